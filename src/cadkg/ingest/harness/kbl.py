"""Reader of KBL harness files (VDA 4964, ``.kbl``), versions 2.3 SR-1, 2.4 and 2.4 SR-1.

KBL is the XML a harness design tool exports: parts (housings, wires, terminals) at the top
of the container, their occurrences inside ``<Harness>``, and the harness topology (nodes,
segments, routings) beside it. cadkg reads what a robot cell or a detection system needs:
connector occurrences (and component boxes) with their cavities, wires and cores with the
cavities their ends are in, cables, nodes, segments with length and bundle section, the
segments each wire is routed through, fixings and protections. Lengths become metres.

Every reference (an IDREF) is resolved while reading; one that names nothing, or the wrong
kind of thing, is a located error, so a harness is never half read. The file is untrusted
XML: no DTD, no entities, no network. See docs/formats/kbl.md.
"""

from __future__ import annotations

import warnings
from collections import defaultdict
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import Any

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.harness.kbl_document import (
    EXPECTED,
    KBL_NAMESPACE,
    KBL_VERSIONS,
    child_elements,
    child_text,
    first_child,
)
from cadkg.ingest.harness.kbl_topology import KblTopology, Placement
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
    WireEnd,
)
from cadkg.ingest.text import xml_document
from cadkg.ingest.xml_input import parse_untrusted_xml

__all__ = ["KBL_NAMESPACE", "KBL_VERSIONS", "looks_like_kbl", "read_kbl"]

_XSI_TYPE = "{http://www.w3.org/2001/XMLSchema-instance}type"


def looks_like_kbl(head: bytes) -> bool:
    """Whether the first bytes of a file look like KBL (for the registry)."""
    return b"KBL_container" in head


def read_kbl(path: str | Path) -> list[HarnessRecord]:
    """Read one KBL file: the harness, its connectors, topology, wires, fixings and protections.

    Raises
    ------
    IngestError
        On an unreadable, empty or binary file, a DOCTYPE or entity declaration, malformed
        XML, a root that is not a KBL container, a ``version_id`` other than 2.3 SR-1, 2.4 or
        2.4 SR-1, a missing ``<Harness>``, a reference (IDREF) naming nothing or the wrong kind
        of element (a wire to a missing cavity ...), a malformed number, a unit that is not a
        length or area where one is needed, and a connector Id or XML id given twice; located
        at file:line.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as err:
        raise IngestError(path, f"cannot read the file: {err.strerror}") from err
    document = xml_document(path, data, expected=EXPECTED)
    root = parse_untrusted_xml(path, document, what="KBL", expected=EXPECTED)
    return _Kbl(path, root).records()


@dataclass
class _Cavity:
    connector: str
    name: str


@dataclass
class _WireInfo:
    element: Any
    ident: str
    label: str
    cable: str | None
    part: Any
    ends: tuple[WireEnd, ...] = ()
    route: tuple[str, ...] = ()
    signal: str | None = None
    connection: Any = None


class _Kbl(KblTopology):
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
        connectors, cavities, contacts = self._connectors(harness)
        nodes, node_connectors, node_fixings = self._nodes(harness, connectors, cavities, contacts)
        wires, cables = self._wires(harness)
        self._connections(harness, wires, contacts)
        fixings = self._occurrences(harness, "Fixing_occurrence")
        protections = self._occurrences(harness, "Wire_protection_occurrence")
        placements: dict[str, Placement] = defaultdict(Placement)
        for fixing, node in node_fixings:
            placements[fixing].nodes.append(node)
        segments = self.segments(nodes, fixings, protections, placements)
        self._routings(wires, segments)
        records: list[HarnessRecord] = [head]
        records.extend(connectors.values())
        records.extend(
            HarnessNode(self.harness, ident, label, tuple(dict.fromkeys(node_connectors[ident])), line)
            for ident, (label, line) in nodes.items()
        )
        records.extend(segments.values())
        records.extend(cables)
        records.extend(self._wire_record(w) for w in wires.values())
        records.extend(
            HarnessFixing(
                self.harness,
                name,
                child_text(element, "Description"),
                tuple(dict.fromkeys(placements[name].nodes)),
                tuple(dict.fromkeys(placements[name].segments)),
                element.sourceline,
            )
            for name, element in fixings.items()
        )
        records.extend(
            HarnessProtection(
                self.harness,
                name,
                child_text(element, "Description"),
                tuple(dict.fromkeys(placements[name].segments)),
                self.length(first_child(element, "Protection_length")),
                element.sourceline,
            )
            for name, element in protections.items()
        )
        return records

    # -- connectors and cavities -------------------------------------------------------------------
    def _connectors(
        self, harness: Any
    ) -> tuple[dict[str, HarnessConnector], dict[str, _Cavity], dict[str, tuple[str, Any]]]:
        connectors: dict[str, HarnessConnector] = {}
        cavities: dict[str, _Cavity] = {}
        contacts: dict[str, tuple[str, Any]] = {}
        by_element: dict[str, str] = {}
        for kind, tag in (
            ("connector", "Connector_occurrence"),
            ("component box", "Component_box_occurrence"),
        ):
            for occurrence in child_elements(harness, tag):
                name = child_text(occurrence, "Id")
                if name is None:
                    self.error(f"<{tag}> without <Id>", occurrence, expected="the connector's name")
                if name in connectors:
                    self.error(
                        "connector Id given twice",
                        occurrence,
                        found=name,
                        expected=f"unique connector Ids (first on line {connectors[name].line})",
                    )
                by_element[occurrence.get("id")] = str(name)
                names = self._cavities(occurrence, str(name), kind, cavities)
                connectors[str(name)] = HarnessConnector(
                    self.harness,
                    str(name),
                    kind,
                    names,
                    child_text(occurrence, "Description"),
                    occurrence.sourceline,
                )
                for contact in child_elements(occurrence, "Contact_points"):
                    contacts[contact.get("id")] = (str(name), contact)
        self.connector_ids = by_element
        self.cavities = cavities
        return connectors, cavities, contacts

    def _cavities(
        self, occurrence: Any, connector: str, kind: str, table: dict[str, _Cavity]
    ) -> tuple[str, ...]:
        found: list[tuple[str | None, str, Any]] = []
        groups: list[tuple[str | None, Any]]
        if kind == "connector":
            groups = [(None, occurrence)]
        else:
            # A component box's cavities sit in its box connectors, named by the connector part's Id.
            groups = []
            for box_connector in child_elements(occurrence, "Component_box_connectors"):
                part = self.ids.get((child_text(box_connector, "Part") or "").strip())
                prefix = child_text(part, "Id") if part is not None else None
                groups.append((prefix or box_connector.get("id"), box_connector))
        for prefix, holder in groups:
            for slot in child_elements(holder, "Slots"):
                for cavity in child_elements(slot, "Cavities"):
                    part = self.ids.get((child_text(cavity, "Part") or "").strip())
                    number = child_text(part, "Cavity_number") if part is not None else None
                    if number is None:
                        self.error(
                            "cavity occurrence names no cavity with a <Cavity_number>",
                            cavity,
                            found=child_text(cavity, "Part") or "no <Part>",
                            expected="the id of a <Cavities> element of a connector housing",
                        )
                    found.append((prefix, str(number), cavity))
        counts: dict[str, int] = defaultdict(int)
        for prefix, number, _ in found:
            counts[f"{prefix}/{number}" if prefix else number] += 1
        names = []
        for prefix, number, cavity in found:
            name = f"{prefix}/{number}" if prefix else number
            if counts[name] > 1:
                # Two slots numbering their cavities alike: tell them apart by the slot occurrence.
                name = f"{cavity.getparent().get('id')}/{name}"
            names.append(name)
            table[cavity.get("id")] = _Cavity(connector, name)
        return tuple(names)

    # -- topology ------------------------------------------------------------------------------------
    def _nodes(
        self,
        harness: Any,
        connectors: dict[str, HarnessConnector],
        cavities: dict[str, _Cavity],
        contacts: dict[str, tuple[str, Any]],
    ) -> tuple[dict[str, tuple[str, int]], dict[str, list[str]], list[tuple[str, str]]]:
        # A node names what sits on it; a ring terminal (special terminal) stands for the
        # connector whose contact point carries it.
        carried: dict[str, list[str]] = defaultdict(list)
        for connector, contact in contacts.values():
            for part in (child_text(contact, "Associated_parts") or "").split():
                carried[part].append(connector)
        fixing_ids = {f.get("id"): child_text(f, "Id") for f in child_elements(harness, "Fixing_occurrence")}
        nodes: dict[str, tuple[str, int]] = {}
        on_node: dict[str, list[str]] = defaultdict(list)
        fixings: list[tuple[str, str]] = []
        for node in child_elements(self.root, "Node"):
            ident = node.get("id")
            if ident is None:
                self.error("<Node> without an id attribute", node, expected='<Node id="...">')
            nodes[ident] = (child_text(node, "Id") or ident, node.sourceline)
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
                    if token in self.connector_ids:
                        on_node[ident].append(self.connector_ids[token])
                    elif token in cavities:
                        on_node[ident].append(cavities[token].connector)
                    elif token in fixing_ids:
                        fixings.append((str(fixing_ids[token]), ident))
                    else:
                        on_node[ident].extend(carried.get(token, ()))
        return nodes, on_node, fixings

    def _occurrences(self, harness: Any, tag: str) -> dict[str, Any]:
        found: dict[str, Any] = {}
        for element in child_elements(harness, tag):
            name = child_text(element, "Id") or element.get("id")
            found[str(name)] = element
        return found

    # -- wires and connections --------------------------------------------------------------------
    def _wires(self, harness: Any) -> tuple[dict[str, _WireInfo], list[HarnessCable]]:
        wires: dict[str, _WireInfo] = {}
        cables: list[HarnessCable] = []
        used: dict[str, int] = defaultdict(int)

        def unique(number: str, element: Any) -> str:
            used[number] += 1
            if used[number] == 1:
                return number
            warnings.warn(
                IngestWarning(
                    self.path,
                    "wire number given twice; this wire is told apart with a suffix",
                    line=element.sourceline,
                    found=number,
                    expected=f"{number}~{used[number]}",
                ),
                stacklevel=4,
            )
            return f"{number}~{used[number]}"

        general_wires = {w.get("id"): w for w in child_elements(self.root, "General_wire")}
        cores = {c.get("id"): c for w in general_wires.values() for c in child_elements(w, "Core")}
        for occurrence in child_elements(harness, "General_wire_occurrence"):
            kind = (occurrence.get(_XSI_TYPE) or "").rpartition(":")[2]
            if not kind:
                kind = (
                    "Special_wire_occurrence"
                    if first_child(occurrence, "Special_wire_id") is not None
                    else "Wire_occurrence"
                )
            part = self.ref(occurrence, "Part", general_wires, "a <General_wire>")[0]
            if kind == "Wire_occurrence":
                number = child_text(occurrence, "Wire_number")
                if number is None:
                    self.error(
                        "wire occurrence without <Wire_number>", occurrence, expected="the wire number"
                    )
                wires[occurrence.get("id")] = _WireInfo(
                    occurrence, unique(str(number), occurrence), str(number), None, part
                )
            elif kind == "Special_wire_occurrence":
                cable = child_text(occurrence, "Special_wire_id")
                if cable is None:
                    self.error(
                        "special wire occurrence without <Special_wire_id>",
                        occurrence,
                        expected="the cable id",
                    )
                cables.append(
                    HarnessCable(
                        self.harness,
                        str(cable),
                        self._wire_length(occurrence),
                        self.diameter(part),
                        occurrence.sourceline,
                    )
                )
                for core in child_elements(occurrence, "Core_occurrence"):
                    number = child_text(core, "Wire_number")
                    if number is None:
                        self.error(
                            "core occurrence without <Wire_number>", core, expected="the core's wire number"
                        )
                    core_part = self.ref(core, "Part", cores, "a <Core> of a <General_wire>")[0]
                    wires[core.get("id")] = _WireInfo(
                        core, unique(str(number), core), str(number), str(cable), core_part
                    )
            else:
                self.error(
                    "unknown kind of wire occurrence",
                    occurrence,
                    found=kind,
                    expected="kbl:Wire_occurrence or kbl:Special_wire_occurrence",
                )
        return wires, cables

    def _connections(
        self, harness: Any, wires: dict[str, _WireInfo], contacts: dict[str, tuple[str, Any]]
    ) -> None:
        self.connections: dict[str, _WireInfo] = {}
        for connection in child_elements(harness, "Connection"):
            wire = self.ref(connection, "Wire", wires, "a wire or core occurrence")[0]
            if wire.connection is not None:
                self.error(
                    "wire is in two connections",
                    connection,
                    found=wire.label,
                    expected=f"one <Connection> per wire (first on line {wire.connection.sourceline})",
                )
            ends: list[tuple[float, int, WireEnd]] = []
            for extremity in child_elements(connection, "Extremities"):
                try:
                    position = float(child_text(extremity, "Position_on_wire") or "0")
                except ValueError:
                    self.error(
                        "bad number in <Position_on_wire>",
                        extremity,
                        found=child_text(extremity, "Position_on_wire"),
                        expected="a number from 0 to 1",
                    )
                _, contact = self.ref(
                    extremity, "Contact_point", contacts, "a <Contact_points> of a connector"
                )[0]
                cavity = self.ref(
                    contact,
                    "Contacted_cavity",
                    self.cavities,
                    "a cavity occurrence of a connector",
                    many=True,
                )[0]
                ends.append((position, len(ends), WireEnd(cavity.connector, cavity.name)))
            wire.ends = tuple(end for _, _, end in sorted(ends))
            wire.signal = child_text(connection, "Signal_name")
            wire.connection = connection
            self.connections[connection.get("id")] = wire

    def _routings(self, wires: dict[str, _WireInfo], segments: dict[str, HarnessSegment]) -> None:
        routed: dict[str, Any] = {}
        for routing in child_elements(self.root, "Routing"):
            wire = self.ref(routing, "Routed_wire", self.connections, "a <Connection>")[0]
            if wire.ident in routed:
                self.error(
                    "connection routed twice",
                    routing,
                    found=child_text(routing, "Routed_wire"),
                    expected=f"one <Routing> per connection (first on line {routed[wire.ident].sourceline})",
                )
            routed[wire.ident] = routing
            if first_child(routing, "Segments") is not None and (child_text(routing, "Segments") or ""):
                chosen = self.ref(routing, "Segments", segments, "a <Segment>", many=True)
                wire.route = tuple(s.ident for s in chosen)

    def _wire_record(self, wire: _WireInfo) -> HarnessWire:
        part = wire.part
        colours = [
            child_text(c, "Colour_value")
            for c in child_elements(part, "Cover_colour") + child_elements(part, "Core_colour")
        ]
        return HarnessWire(
            harness=self.harness,
            ident=wire.ident,
            label=wire.label,
            ends=wire.ends,
            route=wire.route,
            section_mm2=self.area(first_child(part, "Cross_section_area")),
            colour="/".join(c for c in colours if c) or None,
            length_m=self._wire_length(wire.element),
            diameter_m=self.diameter(part),
            cable=wire.cable,
            signal=wire.signal,
            line=wire.element.sourceline,
        )

    def _wire_length(self, occurrence: Any) -> Decimal | None:
        # Several lengths (DMU, production ...) may be given; the first one listed is taken.
        for info in child_elements(occurrence, "Length_information"):
            return self.length(first_child(info, "Length_value"))
        return None

    def diameter(self, part: Any) -> float | None:
        value = self.length(first_child(part, "Outside_diameter"))
        return float(value) if value is not None else None
