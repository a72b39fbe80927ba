"""Networkx views of a wire harness, built from SPARQL over the graph: topology and wires.

Whatever file a harness came from (KBL, the harness text format, an ELVEZ harness
structure), the views ask for the ontology's harness terms only: ``ck:Harness``, things
``ck:partOf`` it, ``ck:Segment ck:segmentFrom/ck:segmentTo ck:HarnessNode``,
``ck:Connector ck:atNode``, ``ck:routedThrough``, ``ck:placedOn``, and wire ends
``ck:fromPin/ck:toPin`` → ``ck:Pin ck:inCavity ck:Cavity`` of the connector it is
``ck:pinOf``.

Node and edge ids are the things' IRIs relative to the cell's base IRI
(``segment/DOOR-L/S1``), so they are stable across rebuilds and unique across harnesses.
Lists are ``;``-joined strings, never Python lists, so the graphs write to GraphML as they are.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import networkx as nx
import pyoxigraph as ox

from cadkg.errors import NotFound, QueryError

if TYPE_CHECKING:
    from cadkg.graph import KnowledgeGraph

__all__ = [
    "LIST_SEPARATOR",
    "NODE_KINDS",
    "HarnessRef",
    "find_harness",
    "harnesses",
    "topology_graph",
    "wire_graph",
]

LIST_SEPARATOR = ";"
NODE_KINDS = ("connector", "fixing", "branch", "end", "inline")
"""Kinds of topology nodes: a connector sits there, else a fixing, else by the number of
segments: three or more ``branch``, one (or none) ``end``, two ``inline``."""

_HARNESSES = """
SELECT ?h ?label ?number ?description ?format WHERE {
  ?h a ck:Harness .
  OPTIONAL { ?h ck:label ?label }
  OPTIONAL { ?h ck:harnessNumber ?number }
  OPTIONAL { ?h ck:description ?description }
  OPTIONAL { ?h ck:fileFormat ?format }
}
"""

_BASE = "SELECT ?cell WHERE { ?cell a ck:Cell } LIMIT 1"

_SEGMENTS = """
SELECT ?s ?label ?from ?to ?length ?diameter ?section WHERE {
  ?s a ck:Segment ; ck:partOf ?h ; ck:segmentFrom ?from ; ck:segmentTo ?to .
  OPTIONAL { ?s ck:label ?label }
  OPTIONAL { ?s ck:lengthM ?length }
  OPTIONAL { ?s ck:diameterM ?diameter }
  OPTIONAL { ?s ck:bundleSectionMm2 ?section }
}
"""

_NODES = """
SELECT DISTINCT ?n ?label WHERE {
  { ?n a ck:HarnessNode ; ck:partOf ?h }
  UNION { ?s ck:partOf ?h ; ck:segmentFrom|ck:segmentTo ?n }
  OPTIONAL { ?n ck:label ?label }
}
"""

_AT_NODES = """
SELECT DISTINCT ?c ?n ?label WHERE {
  ?c ck:atNode ?n . ?n ck:partOf ?h .
  OPTIONAL { ?c ck:label ?label }
}
"""

_PLACED = """
SELECT DISTINCT ?x ?on ?type ?label WHERE {
  ?x ck:placedOn ?on ; ck:partOf ?h ; a ?type .
  VALUES ?type { ck:Fixing ck:Protection }
  OPTIONAL { ?x ck:label ?label }
}
"""

_ROUTES = """
SELECT DISTINCT ?w ?s ?label ?number WHERE {
  ?w ck:routedThrough ?s ; ck:partOf ?h .
  OPTIONAL { ?w ck:label ?label }
  OPTIONAL { ?w ck:wireNumber ?number }
}
"""

_CONNECTORS = """
SELECT DISTINCT ?c ?label ?cavity ?cavityLabel ?cavityIndex WHERE {
  { ?h ck:hasConnector ?c } UNION { ?c a ck:Connector ; ck:partOf ?h }
  UNION { ?h ck:hasBranch/ck:hasConnector ?c }
  OPTIONAL { ?c ck:label ?label }
  OPTIONAL {
    ?c ck:hasCavity ?cavity .
    OPTIONAL { ?cavity ck:label ?cavityLabel }
    OPTIONAL { ?cavity ck:pinIndex ?cavityIndex }
  }
}
"""

_WIRES = """
SELECT ?w ?label ?number ?from ?to ?section ?colour ?length ?diameter ?cable ?signal WHERE {
  ?w ck:partOf ?h ; ck:fromPin ?from ; ck:toPin ?to .
  FILTER EXISTS { ?w a ?kind . VALUES ?kind { ck:Wire ck:Cable } }
  OPTIONAL { ?w ck:label ?label }
  OPTIONAL { ?w ck:wireNumber ?number }
  OPTIONAL { ?w ck:crossSectionMm2 ?section }
  OPTIONAL { ?w ck:colour ?colour }
  OPTIONAL { ?w ck:lengthM ?length }
  OPTIONAL { ?w ck:diameterM ?diameter }
  OPTIONAL { ?w ck:cableName ?cable }
  OPTIONAL { ?w ck:potentialName ?signal }
}
"""

_ENDS = """
SELECT DISTINCT ?pin ?connector ?connectorLabel ?cavity ?cavityLabel ?pinName ?pinIndex WHERE {
  ?w ck:partOf ?h ; ck:fromPin|ck:toPin|ck:intermediatePin ?pin .
  ?pin ck:pinOf ?connector .
  OPTIONAL { ?connector ck:label ?connectorLabel }
  OPTIONAL { ?pin ck:inCavity ?cavity . OPTIONAL { ?cavity ck:label ?cavityLabel } }
  OPTIONAL { ?pin ck:pinName ?pinName }
  OPTIONAL { ?pin ck:pinIndex ?pinIndex }
}
"""


@dataclass(frozen=True)
class HarnessRef:
    """A harness in the graph: its IRI, its id relative to the cell (``harness/DOOR-L``), label."""

    iri: str
    id: str
    label: str
    description: str
    file_format: str


def _base(kg: KnowledgeGraph) -> str:
    rows = kg.query(_BASE).rows
    cell = str(rows[0]["cell"]) if rows else ""
    return cell.removesuffix("cell/this") if cell.endswith("cell/this") else ""


def _relative(iri: str, base: str) -> str:
    return iri[len(base) :] if base and iri.startswith(base) else iri


def harnesses(kg: KnowledgeGraph) -> list[HarnessRef]:
    """Every ``ck:Harness`` of the graph, by label."""
    base = _base(kg)
    refs = {}
    for row in kg.query(_HARNESSES):
        iri = row["h"]
        if iri in refs:
            continue
        number = row["number"]
        label = row["label"] or (f"WH{number}" if number is not None else _relative(iri, base))
        refs[iri] = HarnessRef(
            iri, _relative(iri, base), str(label), row["description"] or "", row["format"] or ""
        )
    return sorted(refs.values(), key=lambda r: (r.label, r.iri))


def find_harness(kg: KnowledgeGraph, harness: str | None = None) -> HarnessRef:
    """The harness named ``harness`` (its label, id or IRI); may be left out when the graph holds one.

    Raises
    ------
    NotFound
        When the graph holds no harness, or none of that name.
    QueryError
        When no name is given and the graph holds more than one harness.
    """
    known = harnesses(kg)
    if not known:
        raise NotFound("the graph holds no harness (ck:Harness)")
    if not harness:
        if len(known) > 1:
            raise QueryError(
                f"the graph holds {len(known)} harnesses; name one: {', '.join(r.label for r in known)}"
            )
        return known[0]
    for ref in known:
        if harness in (ref.label, ref.id, ref.iri):
            return ref
    raise NotFound(f"no harness {harness!r}; known: {', '.join(r.label for r in known)}")


def _rows(kg: KnowledgeGraph, sparql: str, ref: HarnessRef) -> Iterable[dict[str, Any]]:
    return kg.query(sparql, h=ox.NamedNode(ref.iri)).rows


def _joined(values: Iterable[str]) -> str:
    return LIST_SEPARATOR.join(values)


def topology_graph(kg: KnowledgeGraph, harness: str | None = None) -> nx.MultiGraph:
    """The harness topology: nodes are harness nodes, edges are segments (keyed by segment id).

    Node attributes: ``label``, ``kind`` (one of :data:`NODE_KINDS`), ``degree``,
    ``connectors`` and ``fixings`` (labels, ``;``-joined). Edge attributes: ``label``,
    ``from_node`` and ``to_node`` (the segment's direction), ``length_m``, ``diameter_m`` and
    ``section_mm2`` when known, ``wires`` (labels) and ``wire_ids``, ``wire_count``,
    ``fixings`` and ``protections`` (labels). Nodes and edges are added in id order.

    Raises
    ------
    NotFound, QueryError
        As :func:`find_harness`.
    """
    ref = find_harness(kg, harness)
    base = _base(kg)

    def rel(iri: str) -> str:
        return _relative(iri, base)

    graph = nx.MultiGraph(harness=ref.label, harness_id=ref.id, view="topology")
    nodes = {row["n"]: row["label"] or rel(row["n"]) for row in _rows(kg, _NODES, ref)}
    connectors: dict[str, list[str]] = defaultdict(list)
    for row in _rows(kg, _AT_NODES, ref):
        connectors[row["n"]].append(row["label"] or rel(row["c"]))
    placed: dict[tuple[str, str], list[str]] = defaultdict(list)
    for row in _rows(kg, _PLACED, ref):
        kind = "fixings" if row["type"].endswith("Fixing") else "protections"
        placed[(row["on"], kind)].append(row["label"] or rel(row["x"]))
    routed: dict[str, list[tuple[str, str]]] = defaultdict(list)
    for row in _rows(kg, _ROUTES, ref):
        routed[row["s"]].append((row["label"] or row["number"] or rel(row["w"]), rel(row["w"])))
    segments = sorted(_rows(kg, _SEGMENTS, ref), key=lambda r: rel(r["s"]))
    degree: dict[str, int] = defaultdict(int)
    for row in segments:
        degree[row["from"]] += 1
        degree[row["to"]] += 1
    for iri in sorted(nodes, key=rel):
        fixings = sorted(placed.get((iri, "fixings"), []))
        count = degree[iri]
        if connectors.get(iri):
            kind = "connector"
        elif fixings:
            kind = "fixing"
        else:
            kind = "branch" if count >= 3 else "inline" if count == 2 else "end"
        graph.add_node(
            rel(iri),
            label=nodes[iri],
            kind=kind,
            degree=count,
            connectors=_joined(sorted(connectors.get(iri, []))),
            fixings=_joined(fixings),
        )
    for row in segments:
        wires = sorted(set(routed.get(row["s"], [])))
        data: dict[str, Any] = {
            "label": row["label"] or rel(row["s"]),
            "from_node": rel(row["from"]),
            "to_node": rel(row["to"]),
        }
        for name, key in (("length_m", "length"), ("diameter_m", "diameter"), ("section_mm2", "section")):
            if row[key] is not None:
                data[name] = float(row[key])
        data.update(
            wires=_joined(label for label, _ in wires),
            wire_ids=_joined(ident for _, ident in wires),
            wire_count=len(wires),
            fixings=_joined(sorted(placed.get((row["s"], "fixings"), []))),
            protections=_joined(sorted(placed.get((row["s"], "protections"), []))),
        )
        for end in (row["from"], row["to"]):
            if rel(end) not in graph:
                graph.add_node(
                    rel(end), label=rel(end), kind="end", degree=degree[end], connectors="", fixings=""
                )
        graph.add_edge(rel(row["from"]), rel(row["to"]), key=rel(row["s"]), **data)
    return graph


def wire_graph(kg: KnowledgeGraph, harness: str | None = None) -> nx.MultiGraph:
    """The wire-level graph: nodes are connector cavities, edges are wires (keyed by wire id).

    Every cavity of the harness's connectors is a node, used or not; a wire end in no cavity
    is a node of its own (the contact). Node attributes: ``label`` (``connector:cavity``),
    ``connector``, ``cavity``, ``harness_node`` (the topology node the connector sits at, or
    empty). Edge attributes: ``label``, ``wire_number``, ``from_cavity`` and ``to_cavity``
    (the wire's direction), and when known ``section_mm2``, ``colour``, ``length_m``,
    ``diameter_m``, ``cable``, ``signal``; ``segments`` (topology edge ids in route order).

    Raises
    ------
    NotFound, QueryError
        As :func:`find_harness`.
    """
    ref = find_harness(kg, harness)
    base = _base(kg)

    def rel(iri: str) -> str:
        return _relative(iri, base)

    graph = nx.MultiGraph(harness=ref.label, harness_id=ref.id, view="wires")
    at_node = {row["c"]: row["n"] for row in _rows(kg, _AT_NODES, ref)}
    cavities: dict[str, dict[str, Any]] = {}

    def add_cavity(node: str, connector: str, connector_label: str | None, cavity: str) -> None:
        name = connector_label or rel(connector)
        cavities.setdefault(
            rel(node),
            {
                "label": f"{name}:{cavity}",
                "connector": name,
                "cavity": cavity,
                "harness_node": rel(at_node[connector]) if connector in at_node else "",
            },
        )

    for row in _rows(kg, _CONNECTORS, ref):
        if row["cavity"] is not None:
            name = row["cavityLabel"] or (str(row["cavityIndex"]) if row["cavityIndex"] is not None else None)
            add_cavity(row["cavity"], row["c"], row["label"], name or rel(row["cavity"]))
    end_of: dict[str, str] = {}
    connector_of: dict[str, str] = {}
    for row in _rows(kg, _ENDS, ref):
        connector_of[row["pin"]] = row["connector"]
        node = row["cavity"] or row["pin"]
        name = (
            row["cavityLabel"]
            or row["pinName"]
            or (str(row["pinIndex"]) if row["pinIndex"] is not None else "")
        )
        add_cavity(node, row["connector"], row["connectorLabel"], name or rel(node))
        end_of[row["pin"]] = rel(node)
    for node in sorted(cavities):
        graph.add_node(node, **cavities[node])
    routes: dict[str, set[str]] = defaultdict(set)
    for row in _rows(kg, _ROUTES, ref):
        routes[row["w"]].add(row["s"])
    topology = _segment_ends(kg, ref)
    wires = sorted(_rows(kg, _WIRES, ref), key=lambda r: rel(r["w"]))
    seen = set()
    for row in wires:
        if row["w"] in seen:
            continue
        seen.add(row["w"])
        data: dict[str, Any] = {
            "label": row["label"] or row["number"] or rel(row["w"]),
            "wire_number": row["number"] or "",
            "from_cavity": end_of[row["from"]],
            "to_cavity": end_of[row["to"]],
        }
        for name, key in (("section_mm2", "section"), ("length_m", "length"), ("diameter_m", "diameter")):
            if row[key] is not None:
                data[name] = float(row[key])
        for name in ("colour", "cable", "signal"):
            if row[name] is not None:
                data[name] = str(row[name])
        start = at_node.get(connector_of[row["from"]])
        ordered = _in_route_order(routes.get(row["w"], set()), topology, start)
        data["segments"] = _joined(rel(s) for s in ordered)
        graph.add_edge(end_of[row["from"]], end_of[row["to"]], key=rel(row["w"]), **data)
    return graph


def _segment_ends(kg: KnowledgeGraph, ref: HarnessRef) -> dict[str, tuple[str, str]]:
    return {row["s"]: (row["from"], row["to"]) for row in _rows(kg, _SEGMENTS, ref)}


def _in_route_order(segments: set[str], ends: dict[str, tuple[str, str]], start: str | None) -> list[str]:
    """The segments of a route walked from the node ``start``; by id where the walk cannot go on."""
    left = set(segments)
    ordered: list[str] = []
    at = start
    while left and at is not None:
        step = sorted(s for s in left if s in ends and at in ends[s])
        if len(step) != 1:
            break
        segment = step[0]
        ordered.append(segment)
        left.discard(segment)
        first, second = ends[segment]
        at = second if at == first else first
    return ordered + sorted(left)
