"""Graph views for traversal (networkx) and the GraphML export built on them."""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import TYPE_CHECKING

import networkx as nx

from cadkg.ontology.terms import CK, CK_NS

if TYPE_CHECKING:
    from cadkg.store import GraphStore

__all__ = ["DEFAULT_RELATIONS", "graph_view", "write_graphml"]

DEFAULT_RELATIONS: tuple[str, ...] = (
    "pinOf",
    "fromPin",
    "toPin",
    "hasItem",
    "instanceOf",
    "passesThrough",
    "inPlan",
    "hasBranch",
    "containsCable",
    "hasCavity",
    "partOf",
    "onRail",
    "hasTerminalItem",
    "parentFrame",
    "hasPose",
    "segmentFrom",
    "segmentTo",
    "routedThrough",
)
"""Relations in the default view: structure and connectivity, not literals."""


def graph_view(kg: GraphStore, relations: Iterable[str] | None = None) -> nx.MultiDiGraph:
    """A directed multigraph of the chosen ``ck:`` relations between resources.

    Nodes are IRIs with attributes ``type`` (local name of the most specific ck class
    stated) and ``label``; edges carry ``relation`` (a ck local name) and are keyed by it.

    Raises
    ------
    UnknownTermError
        When a relation is not a term of the ontology.
    """
    names = tuple(relations) if relations is not None else DEFAULT_RELATIONS
    # VALUES holds ontology IRIs checked by CK[...], never user text.
    values = " ".join(f"<{CK[name].value}>" for name in names)
    graph = nx.MultiDiGraph()
    edges = kg.query(
        f"SELECT DISTINCT ?s ?p ?o WHERE {{ VALUES ?p {{ {values} }} ?s ?p ?o . FILTER(isIRI(?o)) }}"
    )
    for row in edges:
        relation = row["p"][len(CK_NS) :]
        graph.add_edge(row["s"], row["o"], key=relation, relation=relation)
    attributes = kg.query(
        """SELECT ?n (SAMPLE(?t) AS ?type) (SAMPLE(?l) AS ?label) WHERE {
             ?n a ?t . FILTER(STRSTARTS(STR(?t), STR(ck:)))
             FILTER NOT EXISTS { ?n a ?sub . ?sub rdfs:subClassOf+ ?t . FILTER(?sub != ?t) }
             OPTIONAL { ?n ck:label ?l }
           } GROUP BY ?n"""
    )
    for row in attributes:
        node = row["n"]
        if node in graph:
            graph.nodes[node]["type"] = row["type"][len(CK_NS) :]
            graph.nodes[node]["label"] = row["label"] or ""
    for _node, data in graph.nodes(data=True):
        data.setdefault("type", "")
        data.setdefault("label", "")
    return graph


def write_graphml(kg: GraphStore, path: str | Path, relations: Iterable[str] | None = None) -> None:
    """Write :func:`graph_view` as GraphML (string attributes, stable IRIs as node ids)."""
    nx.write_graphml(graph_view(kg, relations), str(path), named_key_ids=True)
