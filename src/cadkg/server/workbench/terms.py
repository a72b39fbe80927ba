"""What the page's SPARQL editor completes: prefixes, the ontology's classes and properties,
the component labels of the served graph, and the cell's own base IRI as a prefix.

Everything is read from the served graph (the ontology is one of its named graphs), so a
remote store completes as the embedded one does.
"""

from __future__ import annotations

from typing import Any

from cadkg.store import PREFIXES

__all__ = ["CELL_PREFIX", "STANDARD_PREFIXES", "cell_base", "completion_terms"]

CELL_PREFIX = "cell"
# Vocabularies an engineer's query meets besides cadkg's own (and VEC, which cadkg aligns to).
STANDARD_PREFIXES = {
    **PREFIXES,
    "skos": "http://www.w3.org/2004/02/skos/core#",
    "dcterms": "http://purl.org/dc/terms/",
    "dc": "http://purl.org/dc/elements/1.1/",
    "foaf": "http://xmlns.com/foaf/0.1/",
    "prov": "http://www.w3.org/ns/prov#",
    "sh": "http://www.w3.org/ns/shacl#",
    "schema": "https://schema.org/",
    "dcat": "http://www.w3.org/ns/dcat#",
    "void": "http://rdfs.org/ns/void#",
    "vann": "http://purl.org/vocab/vann/",
    "time": "http://www.w3.org/2006/time#",
    "geo": "http://www.opengis.net/ont/geosparql#",
    "qudt": "http://qudt.org/schema/qudt/",
    "unit": "http://qudt.org/vocab/unit/",
    "vec": "http://www.prostep.org/ontologies/ecad/2024/03/vec#",
}
_CELL = "SELECT ?cell WHERE { ?cell a ck:Cell } LIMIT 1"
_CLASSES = """
SELECT ?term ?label ?comment WHERE {
  VALUES ?kind { owl:Class rdfs:Class }
  ?term a ?kind . FILTER(isIRI(?term))
  OPTIONAL { ?term rdfs:label ?label } OPTIONAL { ?term rdfs:comment ?comment }
}"""
_PROPERTIES = """
SELECT ?term ?kind ?label ?comment WHERE {
  VALUES ?kind { owl:ObjectProperty owl:DatatypeProperty owl:AnnotationProperty rdf:Property }
  ?term a ?kind . FILTER(isIRI(?term))
  OPTIONAL { ?term rdfs:label ?label } OPTIONAL { ?term rdfs:comment ?comment }
}"""
# Sorted here, not in the query: a remote store may refuse to sort more rows than it returns
# (Virtuoso sorts at most 10,000).
_LABELS = """
SELECT DISTINCT ?label WHERE { ?c a ck:Component ; ck:label ?label } LIMIT {limit}"""
_KINDS = {
    "http://www.w3.org/2002/07/owl#ObjectProperty": "object",
    "http://www.w3.org/2002/07/owl#DatatypeProperty": "datatype",
    "http://www.w3.org/2002/07/owl#AnnotationProperty": "annotation",
}


def cell_base(graph: Any) -> str | None:
    """The base IRI of the served cell (its ``ck:Cell`` is ``{base}cell/this``), or None."""
    rows = graph.query(_CELL).rows
    if not rows:
        return None
    cell = str(rows[0]["cell"])
    return cell.removesuffix("cell/this") if cell.endswith("cell/this") else cell.rsplit("/", 1)[0] + "/"


def _terms(rows: Any, kind_of: dict[str, str] | None = None) -> list[dict[str, str]]:
    """One entry per IRI: its first label and comment, and its kind when asked."""
    found: dict[str, dict[str, str]] = {}
    for row in rows:
        entry = found.setdefault(row["term"], {"iri": row["term"], "label": "", "comment": ""})
        for key in ("label", "comment"):
            if not entry[key] and row.get(key):
                entry[key] = str(row[key])
        if kind_of is not None and "kind" not in entry:
            entry["kind"] = kind_of.get(row["kind"], "property")
    return sorted(found.values(), key=lambda e: e["iri"])


def completion_terms(graph: Any, max_labels: int = 20000) -> dict[str, Any]:
    """The prefixes, classes, properties and component labels the editor completes.

    ``prefixes`` holds the standard ones and ``cell:`` for the cell's base IRI (when the graph
    has a ``ck:Cell``); ``labels_truncated`` says the component labels stopped at ``max_labels``.
    """
    base = cell_base(graph)
    prefixes = dict(STANDARD_PREFIXES)
    if base:
        prefixes[CELL_PREFIX] = base
    rows = graph.query(_LABELS.replace("{limit}", str(max_labels + 1))).rows
    labels = sorted(str(r["label"]) for r in rows)
    return {
        "prefixes": prefixes,
        "base": base,
        "classes": _terms(graph.query(_CLASSES).rows),
        "properties": _terms(graph.query(_PROPERTIES).rows, _KINDS),
        "components": labels[:max_labels],
        "labels_truncated": len(labels) > max_labels,
    }
