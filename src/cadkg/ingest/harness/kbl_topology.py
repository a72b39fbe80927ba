"""The topology of a KBL harness: its segments between nodes, with their lengths, bundle
sections, fixings and protections."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from decimal import Decimal
from typing import Any

from cadkg.ingest.harness.kbl_document import KblDocument, child_elements, child_text, first_child
from cadkg.ingest.harness.records import HarnessSegment

__all__ = ["KblTopology", "Placement"]

# Which bundle section to take when a segment gives several: what was measured beats what
# was calculated, which beats the section reserved in the design.
_SECTION_PREFERENCE = ("measured", "calculated", "reserved")


@dataclass
class Placement:
    """Where a fixing or protection sits: on nodes, along segments."""

    nodes: list[str] = field(default_factory=list)
    segments: list[str] = field(default_factory=list)


class KblTopology(KblDocument):
    """A KBL document read as far as its harness topology."""

    harness: str

    def segments(
        self,
        nodes: dict[str, tuple[str, int]],
        fixings: dict[str, Any],
        protections: dict[str, Any],
        placements: dict[str, Placement],
    ) -> dict[str, HarnessSegment]:
        node_table = {ident: ident for ident in nodes}
        fixing_table = {element.get("id"): name for name, element in fixings.items()}
        protection_table = {element.get("id"): name for name, element in protections.items()}
        segments: dict[str, HarnessSegment] = {}
        for segment in child_elements(self.root, "Segment"):
            ident = segment.get("id")
            if ident is None:
                self.error("<Segment> without an id attribute", segment, expected='<Segment id="...">')
            start = self.ref(segment, "Start_node", node_table, "a <Node>")[0]
            end = self.ref(segment, "End_node", node_table, "a <Node>")[0]
            length = self.length(first_child(segment, "Physical_length")) or self.length(
                first_child(segment, "Virtual_length")
            )
            section = self._section(segment)
            circular = (child_text(segment, "Form") or "circular") == "circular"
            # The diameter of a circular bundle of that area, to the nanometre: the areas are
            # themselves rounded, so more digits would be noise.
            diameter = (
                round(2 * math.sqrt(float(section) / math.pi) / 1000, 9) if section and circular else None
            )
            for assignment in child_elements(segment, "Fixing_assignment"):
                name = self.ref(assignment, "Fixing", fixing_table, "a <Fixing_occurrence>")[0]
                placements[name].segments.append(ident)
            for area in child_elements(segment, "Protection_area"):
                name = self.ref(
                    area, "Associated_protection", protection_table, "a <Wire_protection_occurrence>"
                )[0]
                placements[name].segments.append(ident)
            segments[ident] = HarnessSegment(
                self.harness,
                ident,
                child_text(segment, "Id") or ident,
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
        for info in child_elements(segment, "Cross_section_area_information"):
            how = child_text(info, "Value_determination") or ""
            rank = _SECTION_PREFERENCE.index(how) if how in _SECTION_PREFERENCE else len(_SECTION_PREFERENCE)
            options.append((rank, len(options), info))
        if not options:
            return None
        info = min(options)[2]
        return self.area(first_child(info, "Area"))
