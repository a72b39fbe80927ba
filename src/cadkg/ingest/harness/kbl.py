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

import math
import re
import warnings
from collections import defaultdict
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from decimal import Decimal, InvalidOperation
from pathlib import Path
from typing import Any, NoReturn

from lxml import etree

from cadkg.errors import IngestError, IngestWarning
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

KBL_NAMESPACE = "http://www.prostep.org/Car_electric_container/KBL2.3/KBLSchema"
"""The namespace of every KBL schema from 2.3 on (2.4 kept it)."""

KBL_VERSIONS = ("2.3 SR-1", "2.4", "2.4 SR-1")
"""The ``version_id`` values read, those of the schemas cadkg was written against."""

_EXPECTED = "a KBL file: <kbl:KBL_container version_id=...> holding a <Harness>"
_XSI_TYPE = "{http://www.w3.org/2001/XMLSchema-instance}type"
# Checked on the bytes before parsing: even with entity expansion off, a DOCTYPE can pull
# in external subsets or declare entities whose meaning would silently be dropped.
_PREFIX = {
    None: Decimal(1),
    "kilo": Decimal(1000),
    "centi": Decimal("0.01"),
    "milli": Decimal("0.001"),
    "micro": Decimal("0.000001"),
}
_NAMED_LENGTH = {"m": Decimal(1), "cm": Decimal("0.01"), "mm": Decimal("0.001")}
_NAMED_AREA_MM2 = {"mm2": Decimal(1), "mm²": Decimal(1), "sqmm": Decimal(1), "m2": Decimal(10**6)}
# Which bundle section to take when a segment gives several: what was measured beats what
# was calculated, which beats the section reserved in the design.
_SECTION_PREFERENCE = ("measured", "calculated", "reserved")


def _key(version: str) -> str:
    return re.sub(r"[\s_-]", "", version).upper()


_VERSION_KEYS = {_key(v): v for v in KBL_VERSIONS}


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
    document = xml_document(path, data, expected=_EXPECTED)
    root = parse_untrusted_xml(path, document, what="KBL", expected=_EXPECTED)
    return _Kbl(path, root).records()


def _local(element: Any) -> str:
    return str(etree.QName(element).localname)


def _children(element: Any, name: str) -> list[Any]:
    return [c for c in element if isinstance(c.tag, str) and _local(c) == name]


def _child(element: Any, name: str) -> Any | None:
    found = _children(element, name)
    return found[0] if found else None


def _text(element: Any, name: str) -> str | None:
    child = _child(element, name)
    if child is None or child.text is None:
        return None
    value = child.text.strip()
    # KBL writers put /NULL where a value is unknown.
    return value if value and value != "/NULL" else None


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


@dataclass
class _Placement:
    nodes: list[str] = field(default_factory=list)
    segments: list[str] = field(default_factory=list)


class _Kbl:
    def __init__(self, path: Path, root: Any) -> None:
        self.path = path
        self.root = root
        self.version = self._version()
        self.ids = self._ids()
        self.units = {u.get("id"): u for u in _children(root, "Unit")}

    # -- errors and references ----------------------------------------------------------------
    def error(
        self, reason: str, element: Any, found: object | None = None, expected: str | None = None
    ) -> NoReturn:
        raise IngestError(self.path, reason, line=element.sourceline, found=found, expected=expected)

    def ref(
        self, owner: Any, name: str, table: dict[str, Any], expected: str, *, many: bool = False
    ) -> list[Any]:
        """The entries of ``table`` that the IDREF(S) child ``name`` of ``owner`` names."""
        child = _child(owner, name)
        tokens = (child.text or "").split() if child is not None else []
        if not tokens:
            self.error(f"<{_local(owner)}> has no <{name}>", owner, expected=f"the id of {expected}")
        if len(tokens) > 1 and not many:
            self.error(
                f"<{name}> names more than one element", child, found=" ".join(tokens), expected="one id"
            )
        resolved = []
        for token in tokens:
            if token not in table:
                what = "nothing in the file" if token not in self.ids else f"a <{_local(self.ids[token])}>"
                self.error(
                    f"<{name}> of <{_local(owner)}> names {what}",
                    child,
                    found=token,
                    expected=f"the id of {expected}",
                )
            resolved.append(table[token])
        return resolved

    # -- whole file ------------------------------------------------------------------------------
    def _version(self) -> str:
        root = self.root
        if _local(root) != "KBL_container" or etree.QName(root).namespace != KBL_NAMESPACE:
            self.error("not a KBL container", root, found=f"<{root.tag}>", expected=_EXPECTED)
        raw = (root.get("version_id") or "").strip()
        version = _VERSION_KEYS.get(_key(raw))
        if version is None:
            self.error(
                "unknown KBL version",
                root,
                found=raw or "no version_id",
                expected=f"version_id {' or '.join(KBL_VERSIONS)}",
            )
        return str(version)

    def _ids(self) -> dict[str, Any]:
        ids: dict[str, Any] = {}
        for element in self.root.iter():
            if not isinstance(element.tag, str):
                continue
            ident = element.get("id")
            if ident is None:
                continue
            if ident in ids:
                self.error(
                    "XML id given twice",
                    element,
                    found=ident,
                    expected=f"unique ids (first on line {ids[ident].sourceline})",
                )
            ids[ident] = element
        return ids

    def records(self) -> list[HarnessRecord]:
        harness = _child(self.root, "Harness")
        if harness is None:
            self.error("no <Harness> in the KBL container", self.root, expected=_EXPECTED)
        ident = _text(harness, "Part_number")
        if ident is None:
            self.error("the <Harness> has no <Part_number>", harness, expected="the harness part number")
        self.harness = str(ident)
        head = Harness(self.harness, _text(harness, "Description"), f"KBL {self.version}", harness.sourceline)
        connectors, cavities, contacts = self._connectors(harness)
        nodes, node_connectors, node_fixings = self._nodes(harness, connectors, cavities, contacts)
        wires, cables = self._wires(harness)
        self._connections(harness, wires, contacts)
        fixings = self._occurrences(harness, "Fixing_occurrence")
        protections = self._occurrences(harness, "Wire_protection_occurrence")
        placements: dict[str, _Placement] = defaultdict(_Placement)
        for fixing, node in node_fixings:
            placements[fixing].nodes.append(node)
        segments = self._segments(nodes, fixings, protections, placements)
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
                _text(element, "Description"),
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
                _text(element, "Description"),
                tuple(dict.fromkeys(placements[name].segments)),
                self.length(_child(element, "Protection_length")),
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
            for occurrence in _children(harness, tag):
                name = _text(occurrence, "Id")
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
                    _text(occurrence, "Description"),
                    occurrence.sourceline,
                )
                for contact in _children(occurrence, "Contact_points"):
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
            for box_connector in _children(occurrence, "Component_box_connectors"):
                part = self.ids.get((_text(box_connector, "Part") or "").strip())
                prefix = _text(part, "Id") if part is not None else None
                groups.append((prefix or box_connector.get("id"), box_connector))
        for prefix, holder in groups:
            for slot in _children(holder, "Slots"):
                for cavity in _children(slot, "Cavities"):
                    part = self.ids.get((_text(cavity, "Part") or "").strip())
                    number = _text(part, "Cavity_number") if part is not None else None
                    if number is None:
                        self.error(
                            "cavity occurrence names no cavity with a <Cavity_number>",
                            cavity,
                            found=_text(cavity, "Part") or "no <Part>",
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
            for part in (_text(contact, "Associated_parts") or "").split():
                carried[part].append(connector)
        fixing_ids = {f.get("id"): _text(f, "Id") for f in _children(harness, "Fixing_occurrence")}
        nodes: dict[str, tuple[str, int]] = {}
        on_node: dict[str, list[str]] = defaultdict(list)
        fixings: list[tuple[str, str]] = []
        for node in _children(self.root, "Node"):
            ident = node.get("id")
            if ident is None:
                self.error("<Node> without an id attribute", node, expected='<Node id="...">')
            nodes[ident] = (_text(node, "Id") or ident, node.sourceline)
            for name in ("Referenced_components", "Referenced_cavities"):
                child = _child(node, name)
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

    def _segments(
        self,
        nodes: dict[str, tuple[str, int]],
        fixings: dict[str, Any],
        protections: dict[str, Any],
        placements: dict[str, _Placement],
    ) -> dict[str, HarnessSegment]:
        node_table = {ident: ident for ident in nodes}
        fixing_table = {element.get("id"): name for name, element in fixings.items()}
        protection_table = {element.get("id"): name for name, element in protections.items()}
        segments: dict[str, HarnessSegment] = {}
        for segment in _children(self.root, "Segment"):
            ident = segment.get("id")
            if ident is None:
                self.error("<Segment> without an id attribute", segment, expected='<Segment id="...">')
            start = self.ref(segment, "Start_node", node_table, "a <Node>")[0]
            end = self.ref(segment, "End_node", node_table, "a <Node>")[0]
            length = self.length(_child(segment, "Physical_length")) or self.length(
                _child(segment, "Virtual_length")
            )
            section = self._section(segment)
            circular = (_text(segment, "Form") or "circular") == "circular"
            # The diameter of a circular bundle of that area, to the nanometre: the areas are
            # themselves rounded, so more digits would be noise.
            diameter = (
                round(2 * math.sqrt(float(section) / math.pi) / 1000, 9) if section and circular else None
            )
            for assignment in _children(segment, "Fixing_assignment"):
                name = self.ref(assignment, "Fixing", fixing_table, "a <Fixing_occurrence>")[0]
                placements[name].segments.append(ident)
            for area in _children(segment, "Protection_area"):
                name = self.ref(
                    area, "Associated_protection", protection_table, "a <Wire_protection_occurrence>"
                )[0]
                placements[name].segments.append(ident)
            segments[ident] = HarnessSegment(
                self.harness,
                ident,
                _text(segment, "Id") or ident,
                start,
                end,
                length,
                diameter,
                section,
                segment.sourceline,
            )
        return segments

    def _section(self, segment: Any) -> Decimal | None:
        options: list[tuple[int, int, Any]] = []
        for info in _children(segment, "Cross_section_area_information"):
            how = _text(info, "Value_determination") or ""
            rank = _SECTION_PREFERENCE.index(how) if how in _SECTION_PREFERENCE else len(_SECTION_PREFERENCE)
            options.append((rank, len(options), info))
        if not options:
            return None
        info = min(options)[2]
        return self.area(_child(info, "Area"))

    def _occurrences(self, harness: Any, tag: str) -> dict[str, Any]:
        found: dict[str, Any] = {}
        for element in _children(harness, tag):
            name = _text(element, "Id") or element.get("id")
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

        general_wires = {w.get("id"): w for w in _children(self.root, "General_wire")}
        cores = {c.get("id"): c for w in general_wires.values() for c in _children(w, "Core")}
        for occurrence in _children(harness, "General_wire_occurrence"):
            kind = (occurrence.get(_XSI_TYPE) or "").rpartition(":")[2]
            if not kind:
                kind = (
                    "Special_wire_occurrence"
                    if _child(occurrence, "Special_wire_id") is not None
                    else "Wire_occurrence"
                )
            part = self.ref(occurrence, "Part", general_wires, "a <General_wire>")[0]
            if kind == "Wire_occurrence":
                number = _text(occurrence, "Wire_number")
                if number is None:
                    self.error(
                        "wire occurrence without <Wire_number>", occurrence, expected="the wire number"
                    )
                wires[occurrence.get("id")] = _WireInfo(
                    occurrence, unique(str(number), occurrence), str(number), None, part
                )
            elif kind == "Special_wire_occurrence":
                cable = _text(occurrence, "Special_wire_id")
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
                for core in _children(occurrence, "Core_occurrence"):
                    number = _text(core, "Wire_number")
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
        for connection in _children(harness, "Connection"):
            wire = self.ref(connection, "Wire", wires, "a wire or core occurrence")[0]
            if wire.connection is not None:
                self.error(
                    "wire is in two connections",
                    connection,
                    found=wire.label,
                    expected=f"one <Connection> per wire (first on line {wire.connection.sourceline})",
                )
            ends: list[tuple[float, int, WireEnd]] = []
            for extremity in _children(connection, "Extremities"):
                try:
                    position = float(_text(extremity, "Position_on_wire") or "0")
                except ValueError:
                    self.error(
                        "bad number in <Position_on_wire>",
                        extremity,
                        found=_text(extremity, "Position_on_wire"),
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
            wire.signal = _text(connection, "Signal_name")
            wire.connection = connection
            self.connections[connection.get("id")] = wire

    def _routings(self, wires: dict[str, _WireInfo], segments: dict[str, HarnessSegment]) -> None:
        routed: dict[str, Any] = {}
        for routing in _children(self.root, "Routing"):
            wire = self.ref(routing, "Routed_wire", self.connections, "a <Connection>")[0]
            if wire.ident in routed:
                self.error(
                    "connection routed twice",
                    routing,
                    found=_text(routing, "Routed_wire"),
                    expected=f"one <Routing> per connection (first on line {routed[wire.ident].sourceline})",
                )
            routed[wire.ident] = routing
            if _child(routing, "Segments") is not None and (_text(routing, "Segments") or ""):
                chosen = self.ref(routing, "Segments", segments, "a <Segment>", many=True)
                wire.route = tuple(s.ident for s in chosen)

    def _wire_record(self, wire: _WireInfo) -> HarnessWire:
        part = wire.part
        colours = [
            _text(c, "Colour_value") for c in _children(part, "Cover_colour") + _children(part, "Core_colour")
        ]
        return HarnessWire(
            harness=self.harness,
            ident=wire.ident,
            label=wire.label,
            ends=wire.ends,
            route=wire.route,
            section_mm2=self.area(_child(part, "Cross_section_area")),
            colour="/".join(c for c in colours if c) or None,
            length_m=self._wire_length(wire.element),
            diameter_m=self.diameter(part),
            cable=wire.cable,
            signal=wire.signal,
            line=wire.element.sourceline,
        )

    def _wire_length(self, occurrence: Any) -> Decimal | None:
        # Several lengths (DMU, production ...) may be given; the first one listed is taken.
        for info in _children(occurrence, "Length_information"):
            return self.length(_child(info, "Length_value"))
        return None

    def diameter(self, part: Any) -> float | None:
        value = self.length(_child(part, "Outside_diameter"))
        return float(value) if value is not None else None

    # -- numbers and units ------------------------------------------------------------------------
    def _value(self, element: Any) -> tuple[Decimal, Any]:
        raw = _text(element, "Value_component")
        try:
            value = Decimal(raw or "")
        except InvalidOperation:
            value = Decimal("NaN")
        exponent = value.as_tuple().exponent
        # 1e999999999 would be written out as a gigabyte of digits in the graph.
        if not value.is_finite() or not isinstance(exponent, int) or not -30 <= exponent <= 30:
            self.error(
                f"bad number in <{_local(element)}>",
                _child(element, "Value_component") if raw is not None else element,
                found=raw or "nothing",
                expected="a number such as 625.08",
            )
        unit = self.ref(element, "Unit_component", self.units, "a <Unit>")[0]
        return value, unit

    def length(self, element: Any | None) -> Decimal | None:
        """A length in metres from a numerical value with a length unit."""
        return self._measure(element, None, lambda prefix: prefix, _NAMED_LENGTH, "length", "metres")

    def area(self, element: Any | None) -> Decimal | None:
        """An area in mm² from a numerical value with an area unit."""
        return self._measure(
            element, "square", lambda prefix: (prefix * 1000) ** 2, _NAMED_AREA_MM2, "area", "square metres"
        )

    def _measure(
        self,
        element: Any | None,
        dimension: str | None,
        si_factor: Callable[[Decimal], Decimal],
        named_factors: Mapping[str, Decimal],
        quantity: str,
        si_unit: str,
    ) -> Decimal | None:
        """A value in cadkg's unit: an SI unit (metre with ``dimension`` and a prefix whose factor
        ``si_factor`` turns into cadkg's unit) or one of the ``named_factors``."""
        if element is None:
            return None
        value, unit = self._value(element)
        name, prefix, found_dimension = (
            _text(unit, "Si_unit_name"),
            _text(unit, "Si_prefix"),
            _text(unit, "Si_dimension"),
        )
        if name == "metre" and found_dimension == dimension and prefix in _PREFIX:
            return value * si_factor(_PREFIX[prefix])
        named = (_text(unit, "Unit_name") or "").lower()
        if name is None and named in named_factors:
            return value * named_factors[named]
        self.error(
            f"<{_local(element)}> is not given in a unit of {quantity}",
            element,
            found=_describe(unit),
            expected=f"a <Unit> of {si_unit} (with an optional prefix)",
        )


def _describe(unit: Any) -> str:
    parts: Iterable[str | None] = (
        _text(unit, "Si_prefix"),
        _text(unit, "Si_unit_name"),
        _text(unit, "Si_dimension"),
        _text(unit, "Unit_name"),
    )
    return " ".join(p for p in parts if p) or f"<Unit id={unit.get('id')!r}> without a name"
