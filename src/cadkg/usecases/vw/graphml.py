"""GraphML export of a harness for detection systems: the topology view and the wire view.

The graphs come from :mod:`cadkg.usecases.vw.views`; this module only writes them with networkx's
GraphML writer. Keys are typed (``string``, ``int``, ``double``), every attribute is a
scalar (lists are ``;``-joined strings), node and edge ids are the things' IRIs relative to
the cell, and nodes and edges are written in id order, so the same graph always gives the
same file. No yEd ``y:`` elements are written: yEd, Gephi and networkx read plain GraphML.
See docs/formats/graphml.md for the keys.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any

import networkx as nx

from cadkg.errors import QueryError
from cadkg.usecases.vw.views import topology_graph, wire_graph

if TYPE_CHECKING:
    from cadkg.graph import KnowledgeGraph

__all__ = ["VIEWS", "graphml_text", "harness_graph", "harness_graphml", "write_harness_graphml"]

VIEWS = ("topology", "wires")
"""``topology``: nodes are harness nodes, edges segments; ``wires``: nodes are cavities, edges wires."""

_SCALARS = (str, int, float, bool)


def harness_graph(kg: KnowledgeGraph, view: str = "topology", harness: str | None = None) -> nx.MultiGraph:
    """The networkx graph of one view of a harness.

    Raises
    ------
    QueryError
        On an unknown view; when no harness is named and the graph holds several.
    NotFound
        When the graph holds no harness of that name.
    """
    if view == "topology":
        return topology_graph(kg, harness)
    if view == "wires":
        return wire_graph(kg, harness)
    raise QueryError(f"unknown harness view {view!r}; one of {', '.join(VIEWS)}")


def _ordered(graph: nx.MultiGraph) -> nx.MultiGraph:
    """A copy whose nodes, and the edges of each node pair, are inserted in id order."""
    ordered = nx.MultiGraph(**graph.graph)
    for node in sorted(graph.nodes):
        ordered.add_node(node, **_checked(graph.nodes[node], f"node {node}"))
    for u, v, key, data in sorted(graph.edges(keys=True, data=True), key=lambda e: str(e[2])):
        ordered.add_edge(u, v, key=key, **_checked(data, f"edge {key}"))
    return ordered


def _checked(data: dict[str, Any], where: str) -> dict[str, Any]:
    for name, value in data.items():
        if not isinstance(value, _SCALARS):
            # GraphML has no list type; a list would be written as its Python repr.
            raise TypeError(f"{where}: attribute {name!r} is a {type(value).__name__}, not a scalar")
    return data


def graphml_text(graph: nx.MultiGraph) -> str:
    """The GraphML document of ``graph``, nodes and edges in id order (typed keys ``d0``, ``d1`` ...)."""
    return "\n".join(nx.generate_graphml(_ordered(graph), prettyprint=True)) + "\n"


def harness_graphml(kg: KnowledgeGraph, view: str = "topology", harness: str | None = None) -> str:
    """One view of a harness as GraphML text.

    Raises
    ------
    QueryError, NotFound
        As :func:`harness_graph`.
    """
    return graphml_text(harness_graph(kg, view, harness))


def write_harness_graphml(
    kg: KnowledgeGraph, path: str | Path, view: str = "topology", harness: str | None = None
) -> Path:
    """Write one view of a harness to ``path`` as GraphML (UTF-8).

    Raises
    ------
    QueryError, NotFound
        As :func:`harness_graph`.
    """
    path = Path(path)
    path.write_text(harness_graphml(kg, view, harness), encoding="utf-8")
    return path
