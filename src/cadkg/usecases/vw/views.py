"""The two views of a wire harness, built from its data in the store: topology and wires.

A :class:`View` is the graph's data, its nodes and its edges with their attributes, in id
order: the GraphML writer (:mod:`cadkg.usecases.vw.graphml`) streams it to a file, and
:func:`topology_graph` and :func:`wire_graph` make it a networkx graph for the Python API.

Node and edge ids are the things' IRIs relative to the cell's base IRI
(``segment/DOOR-L/S1``), so they are stable across rebuilds and unique across harnesses.
Lists are ``;``-joined strings, never Python lists, so a view writes to GraphML as it is.
With ``modules``, a view holds one variant of a modular harness (see :func:`choose_modules`).
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from cadkg.errors import QueryError
from cadkg.usecases.vw.harness_data import (
    TopologyData,
    WireData,
    find_harness,
    topology_data,
    value,
    wire_data,
)

if TYPE_CHECKING:
    import networkx as nx

    from cadkg.graph import KnowledgeGraph

__all__ = [
    "FRAME",
    "LIST_SEPARATOR",
    "NODE_KINDS",
    "Variant",
    "View",
    "choose_modules",
    "networkx_graph",
    "topology_graph",
    "topology_view",
    "wire_graph",
    "wire_view",
]

LIST_SEPARATOR = ";"
NODE_KINDS = ("connector", "fixing", "branch", "end", "inline")
"""Kinds of topology nodes: a connector sits there, else a fixing, else by the number of
segments: three or more ``branch``, one (or none) ``end``, two ``inline``."""
FRAME = "REP 103: x forward, y left, z up; metres"
"""The axes of the node positions (``x``, ``y``, ``z``)."""

Attributes = dict[str, Any]


@dataclass
class View:
    """One view of a harness: graph data, nodes and edges (``u``, ``v``, key) in id order."""

    graph: Attributes
    nodes: list[tuple[str, Attributes]]
    edges: list[tuple[str, str, str, Attributes]]
    warnings: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class Variant:
    """The modules chosen (IRIs; None for the whole 150 % harness) and what to tell the user."""

    modules: frozenset[str] | None
    labels: tuple[str, ...]
    warnings: tuple[str, ...]


def _joined(values: Iterable[str]) -> str:
    return LIST_SEPARATOR.join(values)


def choose_modules(data: TopologyData, names: Sequence[str]) -> Variant:
    """The variant of the modules ``names`` (a module's label or id, or a configuration's label).

    Raises
    ------
    QueryError
        When the harness has no modules, or a name is none of its modules or configurations.
    """
    if not names:
        return Variant(None, (), ())
    if not data.modules:
        raise QueryError(f"harness {data.ref.label} has no modules to choose from")
    by_name: dict[str, set[str]] = defaultdict(set)
    for module in data.modules.values():
        for name in (module.label, module.id, module.id.rpartition("/")[2]):
            by_name[name].add(module.id)
    chosen: set[str] = set()
    for name in names:
        if name in by_name:
            chosen.update(by_name[name])
        elif name in data.configurations:
            chosen.update(data.configurations[name])
        else:
            known = sorted({m.label for m in data.modules.values()})
            configurations = sorted(data.configurations)
            raise QueryError(
                f"harness {data.ref.label} has no module or configuration {name!r};"
                f" modules: {', '.join(known)}"
                + (f"; configurations: {', '.join(configurations)}" if configurations else "")
            )
    families: dict[str, list[str]] = defaultdict(list)
    for ident in sorted(chosen):
        module = data.modules[ident]
        if module.family:
            families[module.family].append(module.label)
    warnings = tuple(
        f"modules {', '.join(labels)} are of one family ({family}) and exclude each other"
        for family, labels in sorted(families.items())
        if len(labels) > 1
    )
    return Variant(frozenset(chosen), tuple(sorted(data.modules[m].label for m in chosen)), warnings)


def _in(data: TopologyData, variant: Variant) -> Callable[[str], bool]:
    chosen = variant.modules
    in_module = data.in_module
    if chosen is None or not in_module:
        return lambda ident: True

    def test(ident: str) -> bool:
        modules = in_module.get(ident)
        return not modules or not chosen.isdisjoint(modules)

    return test


def _graph_data(data: TopologyData, view: str, variant: Variant) -> Attributes:
    graph: Attributes = {"harness": data.ref.label, "harness_id": data.ref.id, "view": view}
    if variant.modules is not None:
        graph["modules"] = _joined(variant.labels)
    if data.positions:
        graph["frame"] = FRAME
    return graph


def topology_view(data: TopologyData, variant: Variant | None = None) -> View:
    """Nodes are harness nodes, edges are segments (keyed by segment id); see docs/formats/graphml.md."""
    variant = variant or Variant(None, (), ())
    keep = _in(data, variant)
    segments = {s: info for s, info in data.segments.items() if keep(s)}
    connectors: dict[str, list[str]] = defaultdict(list)
    for connector, node, label in data.at_node:
        if keep(connector):
            connectors[node].append(label or connector)
    placed: dict[tuple[str, str], list[str]] = defaultdict(list)
    for thing, on, kind, label in data.placed:
        if keep(thing):
            placed[(on, "fixings" if kind.endswith("Fixing") else "protections")].append(label or thing)
    routed: dict[str, set[tuple[str, str]]] = defaultdict(set)
    labels = data.wire_labels
    for wire, path, routing in data.routings:
        if keep(wire) and (not routing or keep(routing)):
            entry = (labels.get(wire) or wire, wire)
            for segment in path:
                routed[segment].add(entry)
    degree: dict[str, int] = defaultdict(int)
    for info in segments.values():
        degree[info.start] += 1
        degree[info.end] += 1
    nodes = []
    for ident in sorted({n for n in data.nodes if keep(n)} | set(degree)):
        name = data.nodes.get(ident) or ident
        here = sorted(connectors.get(ident, []))
        fixings = sorted(placed.get((ident, "fixings"), []))
        count = degree.get(ident, 0)
        kind = (
            "connector"
            if here
            else "fixing"
            if fixings
            else "branch"
            if count >= 3
            else "inline"
            if count == 2
            else "end"
        )
        attributes: Attributes = {
            # Readable: the designations of the connectors there, else the node's own name.
            "label": ", ".join(here) or name,
            "node_name": name,
            "kind": kind,
            "degree": count,
            "connectors": _joined(here),
            "fixings": _joined(fixings),
        }
        if ident in data.positions:
            attributes["x"], attributes["y"], attributes["z"] = data.positions[ident]
        nodes.append((ident, attributes))
    edges = []
    for ident in sorted(segments):
        info = segments[ident]
        wires = sorted(routed.get(ident, ()))
        attributes = {"label": info.label or ident, "from_node": info.start, "to_node": info.end}
        for name, number in (
            ("length_m", info.length_m),
            ("diameter_m", info.diameter_m),
            ("section_mm2", info.section_mm2),
        ):
            if number is not None:
                attributes[name] = number
        if info.length_source:
            attributes["length_source"] = info.length_source
        attributes["wires"] = _joined([label for label, _ in wires])
        attributes["wire_ids"] = _joined([wire for _, wire in wires])
        attributes["wire_count"] = len(wires)
        attributes["fixings"] = _joined(sorted(placed.get((ident, "fixings"), [])))
        attributes["protections"] = _joined(sorted(placed.get((ident, "protections"), [])))
        edges.append((info.start, info.end, ident, attributes))
    view = View(_graph_data(data, "topology", variant), nodes, edges, list(variant.warnings))
    view.warnings.extend(_ambiguous(connectors.values()))
    return view


def _ambiguous(labels: Iterable[list[str]]) -> list[str]:
    counts: dict[str, int] = defaultdict(int)
    for here in labels:
        for label in here:
            counts[label] += 1
    twice = sorted(label for label, count in counts.items() if count > 1)
    return [f"connector designation {label} names several connectors" for label in twice]


def wire_view(data: WireData, variant: Variant | None = None) -> View:
    """Nodes are connector cavities, edges are wires (keyed by wire id); see docs/formats/graphml.md."""
    variant = variant or Variant(None, (), ())
    topology = data.topology
    keep = _in(topology, variant)
    at_node = {c: n for c, n, _ in topology.at_node}
    connectors = data.connectors
    # Each connector shown: its label and harness node.
    shown = {c: (label or c, at_node.get(c, "")) for c, label in connectors.items() if keep(c)}
    cavities: dict[str, Attributes] = {}
    # The connector of a cavity not shown, for a wire that ends there (see _end).
    holder: dict[str, str] = {}
    for connector, cavity, name in data.cavities:
        here = shown.get(connector)
        if here is None:
            holder[cavity] = connector
            continue
        label, node = here
        number = name or cavity
        cavities[cavity] = {
            "label": f"{label}:{number}",
            "connector": label,
            "cavity": number,
            "harness_node": node,
        }
    routes: dict[str, list[tuple[str, list[str]]]] = {}
    unordered: set[str] = set()
    for wire, path, routing in topology.routings:
        if not routing:
            unordered.add(wire)
        if not routing or keep(routing):
            routes.setdefault(wire, []).append((routing, path))
    edges = []
    for row in sorted(data.wires):
        wire = row[0]
        if not keep(wire):
            continue
        # Hot loop (a row per wire): plain literals and numbers are read without a call.
        start, end = row[1], row[2]
        if start not in cavities:
            _end(data, cavities, holder, at_node, start)
        if end not in cavities:
            _end(data, cavities, holder, at_node, end)
        term = row[3]
        label = term[1:-1] if term[-1:] == '"' and "\\" not in term else value(term)
        term = row[4]
        number = term[1:-1] if term[-1:] == '"' and "\\" not in term else value(term)
        attributes: Attributes = {
            "label": label or number or wire,
            "wire_number": number,
            "from_cavity": start,
            "to_cavity": end,
        }
        # In the order of the keys, as the attributes are written.
        term = row[5]
        if term:
            attributes["section_mm2"] = float(term) if term[0] != '"' else float(value(term))
        term = row[7]
        if term:
            attributes["length_m"] = float(term) if term[0] != '"' else float(value(term))
        term = row[8]
        if term:
            attributes["diameter_m"] = float(term) if term[0] != '"' else float(value(term))
        term = row[6]
        if term:
            attributes["colour"] = term[1:-1] if term[-1:] == '"' and "\\" not in term else value(term)
        term = row[9]
        if term:
            attributes["cable"] = term[1:-1] if term[-1:] == '"' and "\\" not in term else value(term)
        term = row[10]
        if term:
            attributes["signal"] = term[1:-1] if term[-1:] == '"' and "\\" not in term else value(term)
        routings = routes.get(wire, [])
        if wire in unordered:
            paths = [_ordered(routings[0][1], topology, cavities[start]["harness_node"])]
        else:
            paths = [path for _, path in sorted(routings)] if len(routings) > 1 else [p for _, p in routings]
        # Routings of one wire for different variants, all in the view of the whole harness: "|".
        attributes["segments"] = "|".join([";".join(path) for path in paths])
        edges.append((start, end, wire, attributes))
    view = View(
        _graph_data(topology, "wires", variant), sorted(cavities.items()), edges, list(variant.warnings)
    )
    view.warnings.extend(_ambiguous([[label for c, label in connectors.items() if c in shown and label]]))
    return view


def _end(
    data: WireData,
    cavities: dict[str, Attributes],
    holder: dict[str, str],
    at_node: dict[str, str],
    end: str,
) -> None:
    """The node of a wire end not in a shown cavity: a cavity of a connector not shown, or a pin
    in no cavity (a node of its own)."""
    if end in holder:
        connector, name = holder[end], end
    else:
        connector, name = data.pins.get(end, ("", end))
    label = data.connectors.get(connector) or connector
    cavities[end] = {
        "label": f"{label}:{name}",
        "connector": label,
        "cavity": name,
        "harness_node": at_node.get(connector, ""),
    }


def _ordered(path: list[str], topology: TopologyData, start: str) -> list[str]:
    """A set of routed segments (no routing) walked from ``start``; by id where the walk cannot go on."""
    left = set(path)
    ordered: list[str] = []
    at = start
    segments = topology.segments
    while left and at:
        step = sorted(s for s in left if s in segments and at in (segments[s].start, segments[s].end))
        if len(step) != 1:
            break
        ordered.append(step[0])
        left.discard(step[0])
        at = segments[step[0]].end if at == segments[step[0]].start else segments[step[0]].start
    return ordered + sorted(left)


# -- networkx, for the Python API -------------------------------------------------------------------------


def networkx_graph(view: View) -> nx.MultiGraph:
    """The view as a networkx multigraph (edges keyed by segment or wire id)."""
    import networkx as nx  # a fifth of a second to import: only when a view is exported

    graph = nx.MultiGraph(**view.graph)
    graph.add_nodes_from(view.nodes)
    graph.add_edges_from(view.edges)
    return graph


def topology_graph(
    kg: KnowledgeGraph, harness: str | None = None, modules: Sequence[str] = ()
) -> nx.MultiGraph:
    """The harness topology as networkx: nodes are harness nodes, edges are segments.

    Raises
    ------
    NotFound, QueryError
        When the harness is unknown or not named where several are; on an unknown module.
    """
    data = topology_data(kg, find_harness(kg, harness))
    return networkx_graph(topology_view(data, choose_modules(data, modules)))


def wire_graph(kg: KnowledgeGraph, harness: str | None = None, modules: Sequence[str] = ()) -> nx.MultiGraph:
    """The wire-level graph as networkx: nodes are connector cavities, edges are wires.

    Raises
    ------
    NotFound, QueryError
        As :func:`topology_graph`.
    """
    ref = find_harness(kg, harness)
    data = wire_data(kg, ref)
    return networkx_graph(wire_view(data, choose_modules(data.topology, modules)))
