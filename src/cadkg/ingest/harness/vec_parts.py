"""The part occurrences of a VEC harness description: connectors (a ``ConnectorHousingRole``)
with their cavities, wires (each ``WireElementReference`` of a ``WireRole`` that has ends; several
make a multi-core cable), and the contact points that put wire ends in cavities."""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from decimal import Decimal
from typing import Any

from cadkg.ingest.harness.records import HarnessCable, HarnessConnector, WireEnd
from cadkg.ingest.harness.vec_document import VecDocument
from cadkg.ingest.harness.xml_tree import child_elements, child_text, first_child, kind_of

__all__ = ["VecParts", "VecWire"]

_SLOTS = ("Slot", "ModularSlot")


@dataclass
class VecWire:
    """A wire (or core) while its routings are read."""

    element: Any
    occurrence: Any
    ident: str
    label: str
    ends: tuple[WireEnd, ...]
    cable: str | None
    section_mm2: Decimal | None
    colour: str | None
    length_m: Decimal | None
    diameter_m: float | None
    signal: str | None
    routes: list[tuple[Any, tuple[str, ...]]] = field(default_factory=list)


class VecParts:
    """The occurrences of one harness description (a DocumentVersion of the file)."""

    def __init__(self, document: VecDocument, harness: str, specifications: list[Any]) -> None:
        self.document = document
        self.harness = harness
        self.specifications = specifications
        self.occurrences = [
            c for s in self.of_kind("CompositionSpecification") for c in child_elements(s, "Component")
        ]
        self.cavities: dict[str, tuple[str, str]] = {}

    def of_kind(self, kind: str) -> list[Any]:
        return [s for s in self.specifications if kind_of(s) == kind]

    @staticmethod
    def roles(occurrence: Any, kind: str) -> list[Any]:
        return [r for r in child_elements(occurrence, "Role") if kind_of(r) == kind]

    @staticmethod
    def label(element: Any) -> str:
        return child_text(element, "Identification") or str(element.get("id"))

    # -- connectors ---------------------------------------------------------------------------------
    def connectors(self) -> dict[str, HarnessConnector]:
        """Occurrences with a connector housing role, by XML id; fills ``cavities`` (cavity
        reference id → connector id and cavity name)."""
        connectors: dict[str, HarnessConnector] = {}
        for occurrence in self.occurrences:
            housings = self.roles(occurrence, "ConnectorHousingRole")
            if not housings:
                continue
            ident = occurrence.get("id")
            found: list[tuple[str | None, str, Any]] = []
            slots = [s for role in housings for s in child_elements(role, "SlotReference")]
            for slot_reference in slots:
                slot = self.document.ref(slot_reference, "ReferencedSlot", _SLOTS, required=False)
                prefix = None
                if len(slots) > 1:
                    prefix = (child_text(slot, "SlotNumber") if slot is not None else None) or self.label(
                        slot_reference
                    )
                for reference in child_elements(slot_reference, "CavityReference"):
                    cavity = self.document.ref(reference, "ReferencedCavity", ("Cavity",))
                    number = child_text(cavity, "CavityNumber") or self.label(reference)
                    found.append((prefix, number, reference))
            names = [f"{p}/{n}" if p else n for p, n, _ in found]
            counts = Counter(names)
            unique = []
            for name, (_, _, reference) in zip(names, found, strict=True):
                # Two references to one cavity number: told apart by the reference's id.
                name = f"{reference.get('id')}/{name}" if counts[name] > 1 else name
                unique.append(name)
                self.cavities[reference.get("id")] = (ident, name)
            connectors[ident] = HarnessConnector(
                self.harness,
                ident,
                self.label(occurrence),
                "connector",
                tuple(unique),
                _description(occurrence),
                occurrence.sourceline,
            )
        return connectors

    # -- wires -----------------------------------------------------------------------------------------
    def wire_ends(self) -> dict[str, tuple[str, str]]:
        """Wire end id → the connector and cavity its contact point puts it in."""
        placed: dict[str, tuple[str, str]] = {}
        for specification in self.of_kind("ContactingSpecification"):
            for contact in child_elements(specification, "ContactPoint"):
                cavities = [
                    self.cavities.get(r.get("id"))
                    for mounting in child_elements(contact, "CavityMounting")
                    for r in self.document.refs(mounting, "EquippedCavityRef", ("CavityReference",))
                ]
                cavity = next((c for c in cavities if c is not None), None)
                for mounting in child_elements(contact, "WireMounting"):
                    for end in self.document.refs(mounting, "ReferencedWireEnd", ("WireEnd",)):
                        if cavity is not None:
                            placed[end.get("id")] = cavity
        return placed

    def wires(self) -> tuple[dict[str, VecWire], dict[str, HarnessCable], dict[str, Any]]:
        """Wires by wire element reference id, cables by occurrence id, and the references with
        no ends (a cable's sheath) by id with the occurrence they belong to."""
        placed = self.wire_ends()
        wires: dict[str, VecWire] = {}
        cables: dict[str, HarnessCable] = {}
        sheaths: dict[str, Any] = {}
        for occurrence in self.occurrences:
            references = [
                reference
                for role in self.roles(occurrence, "WireRole")
                for reference in child_elements(role, "WireElementReference")
            ]
            with_ends = [r for r in references if child_elements(r, "WireEnd")]
            cable = occurrence.get("id") if len(with_ends) > 1 else None
            if cable is not None:
                # A cable's own length and diameter: those of the reference to its outer element.
                sheath = next((r for r in references if r not in with_ends), None)
                length = diameter = None
                if sheath is not None:
                    length, diameter = self._length(sheath), self._diameter(sheath)
                cables[cable] = HarnessCable(
                    self.harness, cable, self.label(occurrence), length, diameter, occurrence.sourceline
                )
            for reference in references:
                if reference not in with_ends:
                    sheaths[reference.get("id")] = occurrence
                    continue
                wires[reference.get("id")] = self._wire(reference, occurrence, cable, placed)
        return wires, cables, sheaths

    def _wire(
        self, reference: Any, occurrence: Any, cable: str | None, placed: dict[str, tuple[str, str]]
    ) -> VecWire:
        doc = self.document
        ends = sorted(
            (doc.number(end, "PositionOnWire") or 0.0, n, WireEnd(*placed[end.get("id")]))
            for n, end in enumerate(child_elements(reference, "WireEnd"))
            if end.get("id") in placed
        )
        specification = self._specification(reference)
        conductor = doc.ref(
            specification,
            "ConductorSpecification",
            ("CoreSpecification", "ConductorSpecification"),
            required=False,
        )
        insulation = doc.ref(
            specification, "InsulationSpecification", ("InsulationSpecification",), required=False
        )
        colours = [
            child_text(colour, "Key")
            for name in ("BaseColor", "FirstIdentificationColor", "SecondIdentificationColor")
            for colour in (child_elements(insulation, name) if insulation is not None else [])
        ]
        diameter = self._diameter(reference)
        length = self._length(reference)
        signal = doc.ref(reference, "Signal", ("Signal",), required=False)
        single = cable is None and child_text(reference, "Identification") is None
        return VecWire(
            element=reference,
            occurrence=occurrence,
            ident=reference.get("id"),
            label=self.label(occurrence if single else reference),
            ends=tuple(end for _, _, end in ends),
            cable=cable,
            section_mm2=doc.measure(first_child(conductor, "CrossSectionArea"), 2)
            if conductor is not None
            else None,
            colour="/".join(c for c in colours if c) or None,
            length_m=length,
            diameter_m=diameter,
            signal=(child_text(signal, "SignalName") or self.label(signal)) if signal is not None else None,
        )

    def _specification(self, reference: Any) -> Any:
        element = self.document.ref(reference, "ReferencedWireElement", ("WireElement", "SubWireElement"))
        return self.document.ref(element, "WireElementSpecification", ("WireElementSpecification",))

    def _diameter(self, reference: Any) -> float | None:
        value = self.document.measure(first_child(self._specification(reference), "OutsideDiameter"))
        return float(value) if value is not None else None

    def _length(self, reference: Any) -> Decimal | None:
        lengths = child_elements(reference, "WireLength")
        return self.document.measure(first_child(lengths[0], "LengthValue")) if lengths else None


def _description(occurrence: Any) -> str | None:
    for description in child_elements(occurrence, "Description"):
        text = child_text(description, "Value") or (description.text or "").strip()
        if text:
            return text
    return None
