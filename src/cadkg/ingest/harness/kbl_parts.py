"""The occurrences of a KBL harness: connectors (and component boxes) with their cavities and
contact points, wires, cables and their cores, and the connections that put wire ends in cavities.

Only the ``<Harness>``'s own occurrences are read: an ``Assembly_part`` holds placeholder
occurrences of its parts, whose real occurrences are the harness's ``Specified_*`` ones.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass
from decimal import Decimal
from typing import Any

from cadkg.ingest.harness.kbl_document import child_elements, child_text, first_child
from cadkg.ingest.harness.kbl_topology import KblTopology
from cadkg.ingest.harness.records import HarnessCable, HarnessConnector, WireEnd

__all__ = ["KblParts", "WireInfo"]

_XSI_TYPE = "{http://www.w3.org/2001/XMLSchema-instance}type"
_WIRE = {"Wire_occurrence", "Specified_wire_occurrence"}
_CABLE = {"Special_wire_occurrence", "Specified_special_wire_occurrence"}


@dataclass
class _Cavity:
    connector: str
    name: str


@dataclass
class WireInfo:
    """A wire or core while its connection and routing are read."""

    element: Any
    ident: str
    label: str
    cable: str | None
    part: Any
    ends: tuple[WireEnd, ...] = ()
    route: tuple[str, ...] = ()
    routing: str = ""
    signal: str | None = None
    connection: Any = None


class KblParts(KblTopology):
    """A KBL document read as far as its harness's connectors, wires and connections."""

    # -- connectors and cavities -------------------------------------------------------------------
    def connectors(self, harness: Any) -> dict[str, HarnessConnector]:
        """Connector occurrences and component boxes by XML id; also fills ``holder`` (the
        connector a connector, box or box connector id stands for), ``cavities`` and ``contacts``."""
        connectors: dict[str, HarnessConnector] = {}
        self.holder: dict[str, str] = {}
        self.cavities: dict[str, _Cavity] = {}
        self.contacts: dict[str, tuple[str, Any]] = {}
        for kind, tag in (
            ("connector", "Connector_occurrence"),
            ("component box", "Component_box_occurrence"),
        ):
            for occurrence in child_elements(harness, tag):
                ident = occurrence.get("id")
                if ident is None:
                    self.error(f"<{tag}> without an id attribute", occurrence, expected=f'<{tag} id="...">')
                self.holder[ident] = ident
                for box_connector in child_elements(occurrence, "Component_box_connectors"):
                    if box_connector.get("id") is not None:
                        self.holder[box_connector.get("id")] = ident
                connectors[ident] = HarnessConnector(
                    self.harness,
                    ident,
                    child_text(occurrence, "Id") or ident,
                    kind,
                    self._cavities(occurrence, ident, kind),
                    child_text(occurrence, "Description"),
                    occurrence.sourceline,
                )
                for contact in child_elements(occurrence, "Contact_points"):
                    self.contacts[contact.get("id")] = (ident, contact)
        return connectors

    def _cavities(self, occurrence: Any, connector: str, kind: str) -> tuple[str, ...]:
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
            self.cavities[cavity.get("id")] = _Cavity(connector, name)
        return tuple(names)

    # -- wires and connections --------------------------------------------------------------------
    def wires(self, harness: Any) -> tuple[dict[str, WireInfo], dict[str, HarnessCable]]:
        """Wire and core occurrences by XML id, and cables (special wires) by XML id."""
        wires: dict[str, WireInfo] = {}
        cables: dict[str, HarnessCable] = {}
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
            ident = occurrence.get("id")
            if kind in _WIRE:
                number = child_text(occurrence, "Wire_number")
                if number is None:
                    self.error(
                        "wire occurrence without <Wire_number>", occurrence, expected="the wire number"
                    )
                wires[ident] = WireInfo(occurrence, ident, str(number), None, part)
            elif kind in _CABLE:
                label = child_text(occurrence, "Special_wire_id")
                if label is None:
                    self.error(
                        "special wire occurrence without <Special_wire_id>",
                        occurrence,
                        expected="the cable id",
                    )
                cables[ident] = HarnessCable(
                    self.harness,
                    ident,
                    str(label),
                    self.wire_length(occurrence),
                    self.diameter(part),
                    occurrence.sourceline,
                )
                for core in child_elements(occurrence, "Core_occurrence"):
                    number = child_text(core, "Wire_number")
                    if number is None:
                        self.error(
                            "core occurrence without <Wire_number>", core, expected="the core's wire number"
                        )
                    core_part = self.ref(core, "Part", cores, "a <Core> of a <General_wire>")[0]
                    wires[core.get("id")] = WireInfo(core, core.get("id"), str(number), ident, core_part)
            else:
                self.error(
                    "unknown kind of wire occurrence",
                    occurrence,
                    found=kind,
                    expected="kbl:Wire_occurrence or kbl:Special_wire_occurrence (or their Specified_ forms)",
                )
        return wires, cables

    def connections(self, harness: Any, wires: dict[str, WireInfo]) -> None:
        """Each wire's ends (by ``Position_on_wire``), signal and connection; fills ``by_connection``."""
        self.by_connection: dict[str, WireInfo] = {}
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
                    extremity, "Contact_point", self.contacts, "a <Contact_points> of a connector"
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
            self.by_connection[connection.get("id")] = wire

    def wire_length(self, occurrence: Any) -> Decimal | None:
        # Several lengths (DMU, production ...) may be given; the first one listed is taken.
        for info in child_elements(occurrence, "Length_information"):
            return self.length(first_child(info, "Length_value"))
        return None

    def diameter(self, part: Any) -> float | None:
        value = self.length(first_child(part, "Outside_diameter"))
        return float(value) if value is not None else None
