"""Reader of VEC harness descriptions (VDA 4968, ``.vec``), versions 1.1, 1.2, 2.0 and 2.1.

VEC (Vehicle Electric Container), KBL's successor, holds part masters and harness
descriptions in ``DocumentVersion``s. Each ``DocumentVersion`` of type ``HarnessDescription``
is read as a harness, into the same records as KBL: connectors (occurrences with a
connector housing role) and their cavities, wires (wire element references with their ends
in cavities, through contact points), multi-core cables, the topology (nodes, segments) with
positions and lengths from the 3D geometry when given, the routings of each wire, fixings
and protections with their placements, and variants (variant configurations, modules).

A wire may have several routings (one per variant), and a routing may run through a segment
twice (a loop out and back): both are kept. A routing whose segments do not follow on from
each other, a reference naming nothing or the wrong kind of element, and a unit that is not a
length where one is needed are located errors. A file without a harness description (a part
master library) gives no records and a warning. The file is untrusted XML. See docs/formats/vec.md.
"""

from __future__ import annotations

import warnings
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import replace
from pathlib import Path
from typing import Any

from cadkg.errors import IngestWarning
from cadkg.ingest.harness.records import (
    Harness,
    HarnessFixing,
    HarnessProtection,
    HarnessRecord,
    HarnessSegment,
    HarnessWire,
    WireRoute,
)
from cadkg.ingest.harness.variants import Modules, as_tuple, topology_modules, union, walk
from cadkg.ingest.harness.vec_document import EXPECTED, VEC_NAMESPACE, VEC_VERSIONS, VecDocument
from cadkg.ingest.harness.vec_parts import VecWire
from cadkg.ingest.harness.vec_topology import VecTopology
from cadkg.ingest.harness.vec_variants import VecVariants
from cadkg.ingest.harness.xml_tree import child_elements, child_text, first_child
from cadkg.ingest.xml_input import read_xml_file

__all__ = ["VEC_NAMESPACE", "VEC_VERSIONS", "looks_like_vec", "read_vec"]


def looks_like_vec(head: bytes) -> bool:
    """Whether the first bytes of a file look like VEC (for the registry)."""
    return b"VecContent" in head and VEC_NAMESPACE.encode() in head


def read_vec(path: str | Path) -> list[HarnessRecord]:
    """Read every harness description of one VEC file.

    Raises
    ------
    IngestError
        On an unreadable, empty or binary file, a DOCTYPE or entity declaration, malformed
        XML, a root that is not ``VecContent``, a ``VecVersion`` not read, an XML id given
        twice, a reference (IDREF) naming nothing or the wrong kind of element, a malformed
        number, a unit that is not a length or area where one is needed, and a routing whose
        segments do not follow on from each other; located at file:line.
    """
    path = Path(path)
    document = VecDocument(path, read_xml_file(path, what="VEC", expected=EXPECTED))
    harnesses = [
        d
        for d in child_elements(document.root, "DocumentVersion")
        if child_text(d, "DocumentType") == "HarnessDescription"
    ]
    if not harnesses:
        warnings.warn(
            IngestWarning(
                path,
                "no harness description (a DocumentVersion of DocumentType HarnessDescription)"
                " in this VEC file: nothing read",
                line=document.root.sourceline,
            ),
            stacklevel=2,
        )
    records: list[HarnessRecord] = []
    for harness in harnesses:
        records.extend(_VecHarness(document, harness).records())
    return records


class _VecHarness(VecTopology):
    """One harness description as records."""

    def __init__(self, document: VecDocument, harness: Any) -> None:
        self.element = harness
        name = child_text(harness, "DocumentNumber") or harness.get("id")
        super().__init__(document, str(name), [s for s in child_elements(harness, "Specification")])

    def records(self) -> list[HarnessRecord]:
        doc = self.document
        head = Harness(
            self.harness,
            child_text(self.element, "DocumentVersion")
            and f"version {child_text(self.element, 'DocumentVersion')}",
            f"VEC {doc.version}",
            self.element.sourceline,
        )
        variants = VecVariants(doc, self.harness, self.element, self.occurrences)
        connectors = self.connectors()
        wires, cables, sheaths = self.wires()
        nodes, segments = self.topology()
        positions, curves = self.geometry(nodes, segments)
        segments = {i: self.with_length(s, curves.get(i), positions) for i, s in segments.items()}
        at_node, fixings, protections = self.placements(nodes, segments, connectors)
        self._routings(wires, sheaths, segments, at_node)
        # -- variants
        own = variants.modules
        wire_modules = {i: own(w.occurrence, w.element) for i, w in wires.items()}
        ending: dict[str, list[Modules]] = defaultdict(list)
        for ident, wire in wires.items():
            for end in wire.ends:
                ending[end.connector].append(wire_modules[ident])
        connector_modules = {}
        for ident in connectors:
            mine = own(self.document.ids[ident])
            connector_modules[ident] = union([mine, *ending[ident]]) if mine is not None else None
        routes = {i: [(r, path, own(r) or wire_modules[i]) for r, path in w.routes] for i, w in wires.items()}
        fixing_modules = {i: own(self.document.ids[i]) for i in fixings}
        protection_modules = {i: own(self.document.ids[i]) for i in protections}
        carriers: list[tuple[Modules, Iterable[str]]] = [(m, p) for rs in routes.values() for _, p, m in rs]
        carriers += [(fixing_modules[i], f[1]) for i, f in fixings.items()]
        carriers += [(protection_modules[i], p) for i, p in protections.items()]
        on_nodes: dict[str, list[Modules]] = defaultdict(list)
        for node, held in at_node.items():
            on_nodes[node].extend(connector_modules[c] for c in held)
        for ident, (on, _) in fixings.items():
            for node in on:
                on_nodes[node].append(fixing_modules[ident])
        segment_derived, node_derived = topology_modules(
            {i: (s.start, s.end) for i, s in segments.items()}, carriers, on_nodes
        )
        records: list[HarnessRecord] = [head, *variants.records]
        records.extend(replace(c, modules=as_tuple(connector_modules[i])) for i, c in connectors.items())
        records.extend(
            replace(
                n,
                connectors=tuple(dict.fromkeys(at_node.get(i, ()))),
                position=positions.get(i),
                modules=as_tuple(own(self.document.ids[i]) or node_derived.get(i)),
            )
            for i, n in nodes.items()
        )
        records.extend(
            replace(s, modules=as_tuple(own(self.document.ids[i]) or segment_derived[i]))
            for i, s in segments.items()
        )
        records.extend(
            replace(
                c, modules=as_tuple(union(wire_modules[i] for i, w in wires.items() if w.cable == c.ident))
            )
            for c in cables.values()
        )
        for ident, wire in wires.items():
            records.append(
                HarnessWire(
                    self.harness,
                    ident,
                    wire.label,
                    wire.ends,
                    tuple(WireRoute(r.get("id"), path, as_tuple(m)) for r, path, m in routes[ident]),
                    wire.section_mm2,
                    wire.colour,
                    wire.length_m,
                    wire.diameter_m,
                    wire.cable,
                    wire.signal,
                    wire.element.sourceline,
                    as_tuple(wire_modules[ident]),
                )
            )
        for ident, (on_nodes_of, on_segments) in fixings.items():
            occurrence = self.document.ids[ident]
            records.append(
                HarnessFixing(
                    self.harness,
                    ident,
                    self.label(occurrence),
                    None,
                    tuple(dict.fromkeys(on_nodes_of)),
                    tuple(dict.fromkeys(on_segments)),
                    occurrence.sourceline,
                    as_tuple(fixing_modules[ident]),
                )
            )
        for ident, on_segments in protections.items():
            occurrence = self.document.ids[ident]
            role = self.roles(occurrence, "WireProtectionRole")[0]
            records.append(
                HarnessProtection(
                    self.harness,
                    ident,
                    self.label(occurrence),
                    None,
                    tuple(dict.fromkeys(on_segments)),
                    doc.measure(first_child(role, "ProtectionLength")),
                    occurrence.sourceline,
                    as_tuple(protection_modules[ident]),
                )
            )
        return records

    def _routings(
        self,
        wires: dict[str, VecWire],
        sheaths: dict[str, Any],
        segments: dict[str, HarnessSegment],
        at_node: dict[str, list[str]],
    ) -> None:
        doc = self.document
        ends = {i: (s.start, s.end) for i, s in segments.items()}
        node_of: dict[str, list[str]] = defaultdict(list)
        for node, held in at_node.items():
            for connector in held:
                node_of[connector].append(node)
        later: list[tuple[Any, list[VecWire], list[str]]] = []
        for specification in self.of_kind("RoutingSpecification"):
            for routing in child_elements(specification, "Routing"):
                target = doc.ref(routing, "RoutedElement", ("WireElementReference", "Connection"))
                path = first_child(routing, "Path")
                chosen = (
                    [s.get("id") for s in doc.refs(path, "Segment", ("TopologySegment",), required=False)]
                    if path is not None
                    else []
                )
                for segment in chosen:
                    if segment not in segments:
                        doc.error(
                            "a routing runs through a segment of another harness description",
                            first_child(path, "Segment"),
                            found=segment,
                            expected=f"a TopologySegment of {self.harness}",
                        )
                ident = target.get("id")
                if ident in wires:
                    self._route(routing, wires[ident], chosen, ends, node_of)
                elif ident in sheaths:
                    later.append(
                        (routing, [w for w in wires.values() if w.occurrence is sheaths[ident]], chosen)
                    )
                else:
                    connected = [
                        w
                        for w in wires.values()
                        if ident in (child_text(w.element, "Connection") or "").split()
                    ]
                    later.append((routing, connected, chosen))
        for routing, targets, chosen in later:
            # A cable's sheath or a schematic connection routed: its cores and wires unless routed themselves.
            for wire in targets:
                if not wire.routes:
                    self._route(routing, wire, chosen, ends, node_of)

    def _route(
        self,
        routing: Any,
        wire: VecWire,
        chosen: list[str],
        ends: dict[str, tuple[str, str]],
        node_of: dict[str, list[str]],
    ) -> None:
        first = node_of.get(wire.ends[0].connector, []) if wire.ends else []
        path, broken = walk(chosen, ends, first)

        def label(ident: str) -> str:
            return self.label(self.document.ids[ident])

        if broken is not None:
            self.document.error(
                f"the routing {self.label(routing)} of wire {wire.label} is not a path",
                first_child(first_child(routing, "Path"), "Segment"),
                found=f"{label(chosen[broken])} after {label(chosen[broken - 1])}",
                expected="segments that each share a node with the one before",
            )
        wire.routes.append((routing, path))
