"""Ontology terms as Python constants, read from ``cadkg.ttl``.

The Turtle file is the source of truth: ``CK.Wire`` exists because the file
declares ``ck:Wire``; ``CK.Wier`` raises :class:`~cadkg.errors.UnknownTermError`.
"""

from __future__ import annotations

from functools import cache
from importlib import resources

import pyoxigraph as ox

from cadkg.errors import UnknownTermError

__all__ = ["CK", "CK_NS", "ONTOLOGY_IRI", "RDF_TYPE", "XSD", "Namespace", "ontology_path"]

CK_NS = "https://w3id.org/cadkg#"
ONTOLOGY_IRI = "https://w3id.org/cadkg"
RDF_TYPE = ox.NamedNode("http://www.w3.org/1999/02/22-rdf-syntax-ns#type")
_DECLARING_TYPES = {
    "http://www.w3.org/2002/07/owl#Class",
    "http://www.w3.org/2002/07/owl#ObjectProperty",
    "http://www.w3.org/2002/07/owl#DatatypeProperty",
    "http://www.w3.org/2002/07/owl#NamedIndividual",
    "http://www.w3.org/2002/07/owl#TransitiveProperty",
    "http://www.w3.org/2002/07/owl#FunctionalProperty",
    "http://www.w3.org/2000/01/rdf-schema#Class",
    "http://www.w3.org/1999/02/22-rdf-syntax-ns#Property",
}


def ontology_path(name: str = "cadkg.ttl") -> str:
    """Path of a file shipped in ``cadkg/ontology`` (``cadkg.ttl``, ``shapes.ttl`` ...)."""
    return str(resources.files("cadkg.ontology").joinpath(name))


@cache
def declared_terms() -> frozenset[str]:
    """Local names of every term ``cadkg.ttl`` declares in the ``ck:`` namespace."""
    names = set()
    for quad in ox.parse(path=ontology_path(), format=ox.RdfFormat.TURTLE):
        subject = quad.subject
        if (
            isinstance(subject, ox.NamedNode)
            and subject.value.startswith(CK_NS)
            and quad.predicate == RDF_TYPE
            and isinstance(quad.object, ox.NamedNode)
            and quad.object.value in _DECLARING_TYPES
        ):
            names.add(subject.value[len(CK_NS) :])
    return frozenset(names)


class Namespace:
    """Attribute access to the IRIs of a vocabulary, checked against its declared terms."""

    def __init__(self, base: str, terms: frozenset[str] | None = None) -> None:
        self._base = base
        self._terms = terms
        self._cache: dict[str, ox.NamedNode] = {}

    def __getattr__(self, name: str) -> ox.NamedNode:
        if name.startswith("_"):
            raise AttributeError(name)
        return self[name]

    def __getitem__(self, name: str) -> ox.NamedNode:
        node = self._cache.get(name)
        if node is None:
            terms = self._terms if self._terms is not None else declared_terms()
            if name not in terms:
                raise UnknownTermError(f"ck:{name} is not declared in the cadkg ontology")
            node = self._cache[name] = ox.NamedNode(self._base + name)
        return node

    def __contains__(self, name: object) -> bool:
        terms = self._terms if self._terms is not None else declared_terms()
        return name in terms


CK = Namespace(CK_NS)


class _Xsd:
    string = ox.NamedNode("http://www.w3.org/2001/XMLSchema#string")
    integer = ox.NamedNode("http://www.w3.org/2001/XMLSchema#integer")
    decimal = ox.NamedNode("http://www.w3.org/2001/XMLSchema#decimal")
    double = ox.NamedNode("http://www.w3.org/2001/XMLSchema#double")
    boolean = ox.NamedNode("http://www.w3.org/2001/XMLSchema#boolean")
    dateTime = ox.NamedNode("http://www.w3.org/2001/XMLSchema#dateTime")  # noqa: N815
    anyURI = ox.NamedNode("http://www.w3.org/2001/XMLSchema#anyURI")  # noqa: N815


XSD = _Xsd()
