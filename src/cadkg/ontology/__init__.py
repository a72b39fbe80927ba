"""The cadkg ontology (``cadkg.ttl``), its SHACL shapes and the term constants."""

from cadkg.ontology.terms import CK, CK_NS, ONTOLOGY_IRI, RDF_TYPE, XSD, Namespace, ontology_path

__all__ = ["CK", "CK_NS", "ONTOLOGY_IRI", "RDF_TYPE", "XSD", "Namespace", "ontology_path"]
