"""Reader of KBL harness files (VDA 4964, ``.kbl``), versions 2.3 SR-1, 2.4 and 2.4 SR-1.

KBL is the XML a harness design tool exports: parts (housings, wires, terminals) at the top
of the container, their occurrences inside ``<Harness>``, and the harness topology (nodes,
segments, routings) beside it. cadkg reads what a robot cell or a detection system needs:
connector occurrences (and component boxes) with their cavities, wires and cores with the
cavities their ends are in, cables, nodes with their positions, segments with length and
bundle section, the segments each wire is routed through, fixings and protections, and the
modules (variants) of a modular harness. Lengths become metres, positions metres in REP 103.

Things are keyed by their XML ``id`` (unique in a file); their ``Id`` (a connector's
designation, which repeats across the modules of a 150 % harness) and wire numbers are labels.
Every reference (an IDREF) is resolved while reading; one that names nothing, or the wrong
kind of thing, is a located error, so a harness is never half read. The file is untrusted
XML: no DTD, no entities, no network. See docs/formats/kbl.md.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from cadkg.ingest.harness.kbl_document import (
    EXPECTED,
    KBL_NAMESPACE,
    KBL_VERSIONS,
    child_elements,
    child_text,
    first_child,
)
from cadkg.ingest.harness.kbl_modules import KblModules
from cadkg.ingest.harness.kbl_parts import KblParts, WireInfo
from cadkg.ingest.harness.kbl_topology import Placement
from cadkg.ingest.harness.records import (
    Harness,
    HarnessCable,
    HarnessConnector,
    HarnessFixing,
    HarnessNode,
    HarnessProtection,
    HarnessRecord,
    HarnessSegment,
    HarnessWire,
    WireRoute,
)
from cadkg.ingest.harness.variants import Modules, as_tuple, topology_modules, union, walk
from cadkg.ingest.xml_input import read_xml_file

__all__ = ["KBL_NAMESPACE", "KBL_VERSIONS", "looks_like_kbl", "read_kbl"]


def looks_like_kbl(head: bytes) -> bool:
    """Whether the first bytes of a file look like KBL (for the registry)."""
    return b"KBL_container" in head


def read_kbl(path: str | Path) -> list[HarnessRecord]:
    """Read one KBL file: the harness, its connectors, topology, wires, fixings, protections
    and modules.

    Raises
    ------
    IngestError
        On an unreadable, empty or binary file, a DOCTYPE or entity declaration, malformed
        XML, a root that is not a KBL container, a ``version_id`` other than 2.3 SR-1, 2.4 or
        2.4 SR-1, a missing ``<Harness>``, a reference (IDREF) naming nothing or the wrong kind
        of element (a wire to a missing cavity ...), a malformed number or point, a unit that
        is not a length or area where one is needed, an XML id given twice, a routing that is
        not a path (or names a segment twice), and a module list naming no module; located at
        file:line.
    """
    path = Path(path)
    return _Kbl(path, read_xml_file(path, what="KBL", expected=EXPECTED)).records()


@dataclass
class _Things:
    """What the harness holds, by XML id, before the variants are known."""

    connectors: dict[str, HarnessConnector]
    nodes: dict[str, HarnessNode]
    segments: dict[str, HarnessSegment]
    wires: dict[str, WireInfo]
    cables: dict[str, HarnessCable]
    fixings: dict[str, Any]
    protections: dict[str, Any]
    placements: dict[str, Placement]


class _Kbl(KblParts):
    """The harness a KBL document describes, as records."""

    def records(self) -> list[HarnessRecord]:
        harness = first_child(self.root, "Harness")
        if harness is None:
            self.error("no <Harness> in the KBL container", self.root, expected=EXPECTED)
        ident = child_text(harness, "Part_number")
        if ident is None:
            self.error("the <Harness> has no <Part_number>", harness, expected="the harness part number")
        self.harness = str(ident)
        head = Harness(
            self.harness, child_text(harness, "Description"), f"KBL {self.version}", harness.sourceline
        )
        modules = KblModules(self, harness, self.harness)
        things = self._things(harness)
        records: list[HarnessRecord] = [head, *modules.records, *modules.configurations]
        records.extend(self._in_variants(things, modules))
        return records

    def _things(self, harness: Any) -> _Things:
        connectors = self.connectors(harness)
        fixings = {f.get("id"): f for f in child_elements(harness, "Fixing_occurrence")}
        protections = {p.get("id"): p for p in child_elements(harness, "Wire_protection_occurrence")}
        node_elements = {n.get("id"): n for n in child_elements(self.root, "Node")}
        placements: dict[str, Placement] = defaultdict(Placement)
        nodes = self._nodes(node_elements, fixings, placements)
        wires, cables = self.wires(harness)
        self.connections(harness, wires)
        segments = self.segments(node_elements, fixings, protections, placements)
        self._routings(wires, segments, nodes)
        return _Things(connectors, nodes, segments, wires, cables, fixings, protections, placements)

    # -- topology ------------------------------------------------------------------------------------
    def _nodes(
        self, elements: dict[str, Any], fixings: dict[str, Any], placements: dict[str, Placement]
    ) -> dict[str, HarnessNode]:
        # A node names what sits on it; a ring terminal (special terminal) stands for the
        # connector whose contact point carries it, a box connector (2.4 SR-1) for its box.
        carried: dict[str, list[str]] = defaultdict(list)
        for connector, contact in self.contacts.values():
            for part in (child_text(contact, "Associated_parts") or "").split():
                carried[part].append(connector)
        nodes: dict[str, HarnessNode] = {}
        for ident, node in elements.items():
            if ident is None:
                self.error("<Node> without an id attribute", node, expected='<Node id="...">')
            on_node: list[str] = []
            for name in ("Referenced_components", "Referenced_cavities"):
                child = first_child(node, name)
                for token in (child.text or "").split() if child is not None else []:
                    if token not in self.ids:
                        self.error(
                            f"<{name}> of <Node> names nothing in the file",
                            child,
                            found=token,
                            expected="the id of a component occurrence",
                        )
                    if token in self.holder:
                        on_node.append(self.holder[token])
                    elif token in self.cavities:
                        on_node.append(self.cavities[token].connector)
                    elif token in fixings:
                        placements[token].nodes.append(ident)
                    else:
                        on_node.extend(carried.get(token, ()))
            nodes[ident] = HarnessNode(
                self.harness,
                ident,
                child_text(node, "Id") or ident,
                tuple(dict.fromkeys(on_node)),
                node.sourceline,
                self.position(node),
            )
        return nodes

    def _routings(
        self, wires: dict[str, WireInfo], segments: dict[str, HarnessSegment], nodes: dict[str, HarnessNode]
    ) -> None:
        ends = {ident: (s.start, s.end) for ident, s in segments.items()}
        at: dict[str, list[str]] = defaultdict(list)
        for node in nodes.values():
            for connector in node.connectors:
                at[connector].append(node.ident)
        routed: dict[str, Any] = {}
        for routing in child_elements(self.root, "Routing"):
            wire = self.ref(routing, "Routed_wire", self.by_connection, "a <Connection>")[0]
            if wire.ident in routed:
                self.error(
                    "connection routed twice",
                    routing,
                    found=child_text(routing, "Routed_wire"),
                    expected=f"one <Routing> per connection (first on line {routed[wire.ident].sourceline})",
                )
            routed[wire.ident] = routing
            chosen: list[str] = []
            if child_text(routing, "Segments"):
                chosen = [s.ident for s in self.ref(routing, "Segments", segments, "a <Segment>", many=True)]
            twice = next((s for n, s in enumerate(chosen) if s in chosen[:n]), None)
            if twice is not None:
                self.error(
                    "a routing names a segment twice",
                    first_child(routing, "Segments"),
                    found=twice,
                    expected="each segment of the wire's path once",
                )
            first = at.get(wire.ends[0].connector, []) if wire.ends else []
            path, broken = walk(chosen, ends, first, reorder=True)
            if broken is not None:
                self.error(
                    f"the routing of wire {wire.label} is not a path",
                    first_child(routing, "Segments"),
                    found=f"{chosen[broken]} after {chosen[broken - 1]}",
                    expected="segments that each share a node with the one before",
                )
            wire.route = path
            wire.routing = routing.get("id") or wire.ident

    # -- variants ------------------------------------------------------------------------------------
    def _in_variants(self, things: _Things, modules: KblModules) -> list[HarnessRecord]:
        """The records, each with the modules of the variants it is in (see records.in_variant)."""
        control = modules.control
        wire_modules: dict[str, Modules] = {}
        for ident, wire in things.wires.items():
            wire_modules[ident] = control(wire.connection if wire.connection is not None else wire.element)
        ending: dict[str, list[Modules]] = defaultdict(list)
        for ident, wire in things.wires.items():
            for end in wire.ends:
                ending[end.connector].append(wire_modules[ident])
        connector_modules: dict[str, Modules] = {}
        for ident in things.connectors:
            own = control(self.ids[ident])
            # A connector no module controls (a ring terminal's dummy, VOBES's base connectors)
            # is where the wires ending in it are; with none, in every variant.
            held = ending.get(ident, [])
            connector_modules[ident] = (
                union([own, *held]) if own is not None else union(held) if held else None
            )
        fixing_modules = {i: control(e) for i, e in things.fixings.items()}
        protection_modules = {i: control(e) for i, e in things.protections.items()}
        carriers: list[tuple[Modules, Iterable[str]]] = [
            (wire_modules[i], w.route) for i, w in things.wires.items()
        ]
        carriers += [(fixing_modules[i], things.placements[i].segments) for i in things.fixings]
        carriers += [(protection_modules[i], things.placements[i].segments) for i in things.protections]
        on_nodes: dict[str, list[Modules]] = defaultdict(list)
        for node in things.nodes.values():
            on_nodes[node.ident].extend(connector_modules[c] for c in node.connectors)
        for ident in things.fixings:
            for node_ident in things.placements[ident].nodes:
                on_nodes[node_ident].append(fixing_modules[ident])
        segment_modules, node_modules = topology_modules(
            {i: (s.start, s.end) for i, s in things.segments.items()}, carriers, on_nodes
        )
        cores: dict[str, list[Modules]] = defaultdict(list)
        for ident, wire in things.wires.items():
            if wire.cable is not None:
                cores[wire.cable].append(wire_modules[ident])
        records: list[HarnessRecord] = []
        records.extend(
            replace(c, modules=as_tuple(connector_modules[i])) for i, c in things.connectors.items()
        )
        records.extend(replace(n, modules=as_tuple(node_modules.get(i))) for i, n in things.nodes.items())
        records.extend(replace(s, modules=as_tuple(segment_modules[i])) for i, s in things.segments.items())
        records.extend(replace(c, modules=as_tuple(union(cores[i]))) for i, c in things.cables.items())
        records.extend(self._wire_record(w, wire_modules[i]) for i, w in things.wires.items())
        for ident, element in things.fixings.items():
            nodes, segments = self._placed(things, ident)
            variants = as_tuple(fixing_modules[ident])
            records.append(
                HarnessFixing(*self._named(ident, element), nodes, segments, element.sourceline, variants)
            )
        for ident, element in things.protections.items():
            _, segments = self._placed(things, ident)
            length = self.length(first_child(element, "Protection_length"))
            variants = as_tuple(protection_modules[ident])
            records.append(
                HarnessProtection(
                    *self._named(ident, element), segments, length, element.sourceline, variants
                )
            )
        return records

    def _named(self, ident: str, element: Any) -> tuple[str, str, str, str | None]:
        """What a fixing and a protection begin with: harness, ident, label (its Id, else its
        ident) and description."""
        return self.harness, ident, child_text(element, "Id") or ident, child_text(element, "Description")

    @staticmethod
    def _placed(things: _Things, ident: str) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """The nodes and the segments a fixing or a protection is placed on, each once."""
        placement = things.placements[ident]
        return tuple(dict.fromkeys(placement.nodes)), tuple(dict.fromkeys(placement.segments))

    def _wire_record(self, wire: WireInfo, modules: Modules) -> HarnessWire:
        part = wire.part
        colours = [
            child_text(c, "Colour_value")
            for c in child_elements(part, "Cover_colour") + child_elements(part, "Core_colour")
        ]
        routes = (WireRoute(wire.routing, wire.route, as_tuple(modules)),) if wire.routing else ()
        return HarnessWire(
            harness=self.harness,
            ident=wire.ident,
            label=wire.label,
            ends=wire.ends,
            routes=routes,
            section_mm2=self.area(first_child(part, "Cross_section_area")),
            colour="/".join(c for c in colours if c) or None,
            length_m=self.wire_length(wire.element),
            diameter_m=self.diameter(part),
            cable=wire.cable,
            signal=wire.signal,
            line=wire.element.sourceline,
            modules=as_tuple(modules),
        )
