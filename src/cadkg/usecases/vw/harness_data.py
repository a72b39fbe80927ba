"""The data of one harness, read from the store for its views: few narrow SPARQL queries whose
results the store serialises itself (tab-separated), split in Python without a term object per
value. A 100k-wire harness has about two million values to read; building them one Python
object at a time is what made the views slow.

Whatever file a harness came from (KBL, VEC, the harness text format, an ELVEZ harness
structure), the queries ask for the ontology's harness terms only: ``ck:Harness``, things
``ck:partOf`` it, ``ck:Segment ck:segmentFrom/ck:segmentTo ck:HarnessNode``, ``ck:Connector
ck:atNode``, ``ck:Routing ck:routingOf/ck:segmentOrder`` (or a wire's ``ck:routedThrough``),
``ck:placedOn``, ``ck:inModule``, and wire ends ``ck:fromPin/ck:toPin`` → ``ck:Pin ck:inCavity
ck:Cavity`` of the connector it is ``ck:pinOf``.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Callable
from concurrent.futures import Future, ThreadPoolExecutor
from dataclasses import dataclass, field
from itertools import repeat
from typing import TYPE_CHECKING

import pyoxigraph as ox

from cadkg.errors import NotFound, QueryError
from cadkg.usecases.vw.harness_queries import (
    AT_NODES,
    AT_NODES_ONLY,
    BASE,
    CAVITIES,
    CONFIGURATIONS,
    CONNECTORS,
    HARNESSES,
    IN_MODULE,
    LOOSE_PINS,
    MODULES,
    NODES,
    PLACED,
    ROUTED,
    ROUTINGS,
    ROUTINGS_ONLY,
    SEGMENTS,
    wires_query,
)

if TYPE_CHECKING:
    from cadkg.store import GraphStore

__all__ = [
    "HarnessRef",
    "ModuleInfo",
    "SegmentInfo",
    "TopologyData",
    "WireData",
    "choose_harness",
    "find_harness",
    "harnesses",
    "ids",
    "relative",
    "topology_data",
    "wire_data",
]

Row = list[str]


@dataclass(frozen=True)
class HarnessRef:
    """A harness in the graph: its IRI, its id relative to the cell (``harness/DOOR-L``), label."""

    iri: str
    id: str
    label: str
    description: str
    file_format: str


@dataclass(frozen=True)
class SegmentInfo:
    label: str
    start: str
    end: str
    length_m: float | None
    diameter_m: float | None
    section_mm2: float | None
    length_source: str | None


@dataclass(frozen=True)
class ModuleInfo:
    """A module of a modular harness: the name users choose it by, its kind and family."""

    id: str
    label: str
    kind: str
    family: str


@dataclass
class TopologyData:
    """What the topology view of a harness is made of, every thing by its id (its IRI relative
    to the cell)."""

    ref: HarnessRef
    base: str
    nodes: dict[str, str] = field(default_factory=dict)
    positions: dict[str, tuple[float, float, float]] = field(default_factory=dict)
    segments: dict[str, SegmentInfo] = field(default_factory=dict)
    at_node: list[tuple[str, str, str]] = field(default_factory=list)
    placed: list[tuple[str, str, str, str]] = field(default_factory=list)
    # (wire, segments in path order, routing or "" for a wire's routedThrough)
    routings: list[tuple[str, list[str], str]] = field(default_factory=list)
    wire_labels: dict[str, str] = field(default_factory=dict)
    in_module: dict[str, set[str]] = field(default_factory=dict)
    modules: dict[str, ModuleInfo] = field(default_factory=dict)
    configurations: dict[str, list[str]] = field(default_factory=dict)


@dataclass
class WireData:
    """What the wires view of a harness is made of, beside its topology (ids as keys)."""

    topology: TopologyData
    # connector → its label
    connectors: dict[str, str] = field(default_factory=dict)
    # (connector, cavity, cavity name) of every cavity of the connectors, connector by connector
    cavities: list[tuple[str, str, str]] = field(default_factory=list)
    # a pin in no cavity → (connector, pin name)
    pins: dict[str, tuple[str, str]] = field(default_factory=dict)
    # [wire, from, to, label, number, section, colour, length, diameter, cable, signal]: ids of
    # the wire and of the cavities its ends are in (of an end's pin where it is in none), then
    # the terms of the query ("" where unknown; see value())
    wires: list[Row] = field(default_factory=list)


# -- reading tab-separated results ---------------------------------------------------------------------

_ESCAPE = re.compile(r"\\(?:u([0-9A-Fa-f]{4})|U([0-9A-Fa-f]{8})|(.))")
_SIMPLE = {"t": "\t", "b": "\b", "n": "\n", "r": "\r", "f": "\f", '"': '"', "'": "'", "\\": "\\"}


def _unescape(match: re.Match[str]) -> str:
    code = match[1] or match[2]
    return chr(int(code, 16)) if code else _SIMPLE.get(match[3], match[3])


def value(term: str) -> str:
    """The value of one term of a tab-separated result: an IRI without <>, a literal's text, a
    number or boolean as written, "" for an unbound variable."""
    if not term:
        return ""
    first = term[0]
    if first == "<":
        return term[1:-1]
    if first == '"':
        body = term[1 : term.rindex('"')]
        return _ESCAPE.sub(_unescape, body) if "\\" in body else body
    return term


def ids(base: str) -> Callable[[str], str]:
    """The id of an IRI term (``<...>``) of a tab-separated result: relative to ``base``."""
    prefix = "<" + base
    start = len(prefix)

    def ident(term: str) -> str:
        return term[start:-1] if term.startswith(prefix) else term[1:-1]

    return ident


def number(term: str) -> float | None:
    text = value(term)
    return float(text) if text else None


def _serialized(kg: GraphStore, sparql: str, harness: str | None) -> bytes:
    bindings = {"h": ox.NamedNode(harness)} if harness is not None else {}
    data: bytes = kg.raw_query(sparql, bindings).serialize(format=ox.QueryResultsFormat.TSV)
    return data


def _split(data: bytes) -> list[Row]:
    lines = data.decode("utf-8").split("\n")
    del lines[0]  # the variables
    if lines and not lines[-1]:
        lines.pop()
    return list(map(str.split, lines, repeat("\t")))


def _rows(kg: GraphStore, sparql: str, harness: str | None = None) -> list[Row]:
    return _split(_serialized(kg, sparql, harness))


class _Fetch:
    """Queries run by the store in two threads (it lets go of the interpreter while it works),
    so one result is split and read here while the next ones are evaluated: they are asked in
    the order they are read."""

    def __init__(self, kg: GraphStore, pool: ThreadPoolExecutor, harness: str) -> None:
        self.kg, self.pool, self.harness = kg, pool, harness
        self.futures: dict[str, Future[bytes]] = {}

    def ask(self, **queries: str) -> None:
        for name, sparql in queries.items():
            bound = self.harness if "?h" in sparql else None
            self.futures[name] = self.pool.submit(_serialized, self.kg, sparql, bound)

    def rows(self, name: str) -> list[Row]:
        return _split(self.futures.pop(name).result())


# -- harnesses ---------------------------------------------------------------------------------------------


def base_of(kg: GraphStore) -> str:
    rows = kg.query(BASE).rows
    cell = str(rows[0]["cell"]) if rows else ""
    return cell.removesuffix("cell/this") if cell.endswith("cell/this") else ""


def relative(iri: str, base: str) -> str:
    return iri[len(base) :] if base and iri.startswith(base) else iri


def harnesses(kg: GraphStore) -> list[HarnessRef]:
    """Every ``ck:Harness`` of the graph, by label."""
    base = base_of(kg)
    refs = {}
    for row in kg.query(HARNESSES):
        iri = row["h"]
        if iri in refs:
            continue
        number_ = row["number"]
        label = row["label"] or (f"WH{number_}" if number_ is not None else relative(iri, base))
        refs[iri] = HarnessRef(
            iri, relative(iri, base), str(label), row["description"] or "", row["format"] or ""
        )
    return sorted(refs.values(), key=lambda r: (r.label, r.iri))


def find_harness(kg: GraphStore, harness: str | None = None) -> HarnessRef:
    """The harness named ``harness`` (its label, id or IRI); may be left out when the graph holds one.

    Raises
    ------
    NotFound
        When the graph holds no harness, or none of that name.
    QueryError
        When no name is given and the graph holds more than one harness.
    """
    return choose_harness(harnesses(kg), harness)


def choose_harness(known: list[HarnessRef], harness: str | None) -> HarnessRef:
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


# -- the data of the views -------------------------------------------------------------------------------


def topology_data(kg: GraphStore, ref: HarnessRef) -> TopologyData:
    """The harness's nodes, segments, connectors at nodes, fixings, protections, routings and modules."""
    base = base_of(kg)
    with ThreadPoolExecutor(2) as pool:
        fetch = _Fetch(kg, pool, ref.iri)
        _ask_topology(fetch, labels=True)
        return _topology(fetch, ref, base, labels=True)


def _ask_topology(fetch: _Fetch, *, labels: bool) -> None:
    """The queries of the topology; without ``labels`` only what the wires view needs of it."""
    fetch.ask(segments=SEGMENTS, routings=ROUTINGS if labels else ROUTINGS_ONLY)
    if labels:
        fetch.ask(nodes=NODES)
    fetch.ask(at_nodes=AT_NODES if labels else AT_NODES_ONLY)
    if labels:
        fetch.ask(placed=PLACED)
    fetch.ask(in_module=IN_MODULE, modules=MODULES, configurations=CONFIGURATIONS)


def _topology(fetch: _Fetch, ref: HarnessRef, base: str, *, labels: bool) -> TopologyData:
    ident = ids(base)
    data = TopologyData(ref, base)
    for row in fetch.rows("segments"):
        segment = ident(row[0])
        data.segments[segment] = SegmentInfo(
            value(row[3]),
            ident(row[1]),
            ident(row[2]),
            number(row[4]),
            number(row[5]),
            number(row[6]),
            value(row[7]) or None,
        )
    by_part = {s.rpartition("/")[2]: s for s in data.segments}
    routings = data.routings
    labelled = data.wire_labels
    prefix = "<" + base
    start = len(prefix)
    for routing, wire, order, label, number_ in fetch.rows("routings"):
        rid = routing[start:-1] if routing.startswith(prefix) else routing[1:-1]
        wire_id = wire[start:-1] if wire.startswith(prefix) else wire[1:-1]
        # The order is percent-encoded ids and spaces: a plain literal, no escapes.
        routings.append((wire_id, [by_part.get(p, p) for p in order[1:-1].split()], rid))
        if labels:
            text = label[1:-1] if label[-1:] == '"' and "\\" not in label else value(label)
            labelled[wire_id] = text or value(number_)
    ends = {info.start for info in data.segments.values()} | {info.end for info in data.segments.values()}
    for node, label, x, y, z, inside in fetch.rows("nodes") if labels else ():
        rid = ident(node)
        if inside == "true" or rid in ends:
            data.nodes[rid] = value(label)
            if x and y and z:
                data.positions[rid] = (float(value(x)), float(value(y)), float(value(z)))
    data.at_node = [
        (ident(c), ident(n), value(label))
        for c, n, label, inside in fetch.rows("at_nodes")
        if inside == "true" or ident(n) in ends
    ]
    data.placed = [
        (ident(x), ident(on), value(t), value(label))
        for x, on, t, label in (fetch.rows("placed") if labels else ())
    ]
    if not routings:
        # A harness of another source: its wires' routedThrough, a set of segments without order.
        routed: dict[str, list[str]] = defaultdict(list)
        for wire, segment, label, number_ in _rows(fetch.kg, ROUTED, fetch.harness):
            rid = ident(wire)
            routed[rid].append(ident(segment))
            labelled[rid] = value(label) or value(number_)
        routings.extend((wire, segments, "") for wire, segments in routed.items())
    for thing, module in fetch.rows("in_module"):
        data.in_module.setdefault(ident(thing), set()).add(ident(module))
    for module, label, kind, family, family_label in fetch.rows("modules"):
        rid = ident(module)
        data.modules[rid] = ModuleInfo(
            rid, value(label) or rid, value(kind), value(family_label) or value(family)
        )
    for configuration, label, module in fetch.rows("configurations"):
        data.configurations.setdefault(value(label) or ident(configuration), []).append(ident(module))
    return data


def wire_data(kg: GraphStore, ref: HarnessRef, *, whole: bool = False) -> WireData:
    """The harness's connectors with their cavities, its wires and their ends, and what the wires
    view needs of its topology (``whole``: all of it, for the topology view too)."""
    base = base_of(kg)
    ident = ids(base)
    with ThreadPoolExecutor(2) as pool:
        fetch = _Fetch(kg, pool, ref.iri)
        # The longest query first, in a thread of its own while the other one reads the rest.
        fetch.ask(wires=wires_query(kg))
        _ask_topology(fetch, labels=whole)
        fetch.ask(connectors=CONNECTORS, cavities=CAVITIES)
        data = WireData(_topology(fetch, ref, base, labels=whole))
        connectors = data.connectors
        connectors.update((ident(c), value(label)) for c, label in fetch.rows("connectors"))
        prefix = "<" + base
        start = len(prefix)
        cavities = data.cavities
        for connector, cavity, label, index in fetch.rows("cavities"):
            rid = connector[start:-1] if connector.startswith(prefix) else connector[1:-1]
            if rid in connectors:
                cavity_id = cavity[start:-1] if cavity.startswith(prefix) else cavity[1:-1]
                name = (
                    label[1:-1] if label.endswith('"') and "\\" not in label else value(label) or value(index)
                )
                cavities.append((rid, cavity_id, name))
        wires = data.wires
        # An end in none of these cavities is a pin in no cavity, or a cavity of another
        # connector: the pins are looked for among those in no cavity.
        known = {cavity for _, cavity, _ in cavities}
        loose: set[str] = set()
        for row in fetch.rows("wires"):
            term = row[0]
            row[0] = term[start:-1] if term.startswith(prefix) else term[1:-1]
            term = row[1]
            row[1] = end = term[start:-1] if term.startswith(prefix) else term[1:-1]
            if end not in known:
                loose.add(end)
            term = row[2]
            row[2] = end = term[start:-1] if term.startswith(prefix) else term[1:-1]
            if end not in known:
                loose.add(end)
            wires.append(row)
    if loose:
        for pin, connector, name, index in _rows(kg, LOOSE_PINS):
            if ident(pin) in loose:
                data.pins[ident(pin)] = (ident(connector), value(name) or value(index))
    return data
