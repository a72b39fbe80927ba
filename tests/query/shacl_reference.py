"""pySHACL as the reference for cadkg's SHACL engine: the same results, found the slow way.

pySHACL checks an rdflib copy of the graphs, with the ontology mixed in as cadkg's store
holds it, and SHACL-AF on (the shapes' SPARQL targets). Its results are turned into the
engine's :class:`ShapeResult` records: a blank property shape is named ``<node shape>/<path>``
as the engine names it, and constraint components by their local name.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path

import pyshacl
import rdflib
from rdflib.namespace import RDF, SH

import cadkg
from cadkg.ontology.terms import ontology_path
from cadkg.query.shacl_sparql import ShapeResult

__all__ = ["Key", "pyshacl_results", "result_keys"]

Key = tuple[str, str | None, str, str, str]  # focus, path, component, shape, severity


def _shape_name(shapes: rdflib.Graph, node: rdflib.term.Node) -> str:
    if isinstance(node, rdflib.URIRef):
        return str(node)
    owner = shapes.value(None, SH.property, node)
    return f"{owner}/{shapes.value(node, SH.path)}"


def _local(iri: rdflib.term.Node) -> str:
    return str(iri).rsplit("#", 1)[-1]


def pyshacl_results(
    kg: cadkg.KnowledgeGraph,
    graphs: Sequence[str],
    shapes_ttl: str | None = None,
) -> list[ShapeResult]:
    """pySHACL's results for ``graphs`` of ``kg`` against cadkg's shapes (or ``shapes_ttl``)."""
    data = rdflib.Graph()
    data.parse(data=kg.serialize("nt", graphs=graphs), format="nt")
    if shapes_ttl is None:
        shapes = rdflib.Graph().parse(ontology_path("shapes.ttl"), format="turtle")
    else:
        shapes = rdflib.Graph().parse(data=shapes_ttl, format="turtle")
    ontology = rdflib.Graph().parse(Path(ontology_path("cadkg.ttl")), format="turtle")
    conforms, report, _ = pyshacl.validate(
        data, shacl_graph=shapes, ont_graph=ontology, inference="none", advanced=True
    )
    results = []
    for result in report.subjects(RDF.type, SH.ValidationResult):
        focus = report.value(result, SH.focusNode)
        path = report.value(result, SH.resultPath)
        message = report.value(result, SH.resultMessage)
        results.append(
            ShapeResult(
                f"_:{focus}" if isinstance(focus, rdflib.BNode) else str(focus),
                None if path is None else str(path),
                _local(report.value(result, SH.sourceConstraintComponent)),
                _shape_name(shapes, report.value(result, SH.sourceShape)),
                str(report.value(result, SH.resultSeverity)),
                "" if message is None else str(message),
            )
        )
    assert bool(conforms) == (not results)
    return sorted(set(results), key=ShapeResult.order)


def result_keys(results: Iterable[ShapeResult]) -> set[Key]:
    """What two engines must agree on; a blank focus node is any blank node (their labels differ)."""
    return {
        ("_:" if r.focus.startswith("_:") else r.focus, r.path, r.component, r.shape, r.severity)
        for r in results
    }
