"""The topology of a KBL harness: nodes with their positions and what sits on them, segments
with their lengths, bundle sections, centre curves, fixings and protections."""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field
from decimal import Decimal
from functools import cached_property
from typing import Any

from cadkg.errors import IngestWarning
from cadkg.ingest.harness.geometry import curve_points, polyline_length, rep103_from_vehicle
from cadkg.ingest.harness.kbl_document import KblDocument, child_elements, child_text, first_child
from cadkg.ingest.harness.records import HarnessSegment, Position
from cadkg.ingest.text import small_integer

__all__ = ["KblTopology", "Placement"]

# Which bundle section to take when a segment gives several: what was measured beats what
# was calculated, which beats the section reserved in the design.
_SECTION_PREFERENCE = ("measured", "calculated", "reserved")
# A centre curve this much longer or shorter than the segment's Virtual_length, or ending this
# far (mm) from its node, does not describe the segment: the stated length is kept, with a warning.
_CURVE_TOLERANCE = 0.01
_CURVE_END_MM = 5.0


@dataclass
class Placement:
    """Where a fixing or protection sits: on nodes, along segments."""

    nodes: list[str] = field(default_factory=list)
    segments: list[str] = field(default_factory=list)


class KblTopology(KblDocument):
    """A KBL document read as far as its harness topology."""

    harness: str

    # -- points ----------------------------------------------------------------------------------------
    @cached_property
    def points(self) -> dict[str, Any]:
        return {p.get("id"): p for p in child_elements(self.root, "Cartesian_point")}

    def point(self, owner: Any, name: str) -> tuple[float, ...] | None:
        """The coordinates (mm, vehicle frame) of the ``Cartesian_point`` child ``name`` names
        (2.3 SR-1 on: an IDREF) or holds (older writers); None when there is none."""
        child = first_child(owner, name)
        if child is None:
            return None
        if first_child(child, "Coordinates") is not None:
            return self.coordinates(child)
        return self.coordinates(self.ref(owner, name, self.points, "a <Cartesian_point>")[0])

    def coordinates(self, point: Any) -> tuple[float, ...]:
        values = []
        for element in child_elements(point, "Coordinates"):
            values.append(self.double(element, "a coordinate in millimetres such as -434.5"))
        if len(values) not in (2, 3):
            self.error(
                "<Cartesian_point> does not have 2 or 3 coordinates",
                point,
                found=len(values),
                expected="x, y and z (or x and y) in <Coordinates>",
            )
        return tuple(values) if len(values) == 3 else (values[0], values[1], 0.0)

    def position(self, node: Any) -> Position | None:
        """A node's position: metres, REP 103 axes."""
        point = self.point(node, "Cartesian_point")
        return rep103_from_vehicle(*point) if point is not None else None

    # -- segments --------------------------------------------------------------------------------------
    def segments(
        self,
        nodes: dict[str, Any],
        fixings: dict[str, Any],
        protections: dict[str, Any],
        placements: dict[str, Placement],
    ) -> dict[str, HarnessSegment]:
        """The segments by XML id; the fixings and protections on them go into ``placements``."""
        segments: dict[str, HarnessSegment] = {}
        for segment in child_elements(self.root, "Segment"):
            ident = segment.get("id")
            if ident is None:
                self.error("<Segment> without an id attribute", segment, expected='<Segment id="...">')
            start = self.ref(segment, "Start_node", nodes, "a <Node>")[0].get("id")
            end = self.ref(segment, "End_node", nodes, "a <Node>")[0].get("id")
            length, source = self._length(segment, nodes[start], nodes[end])
            section = self._section(segment)
            circular = (child_text(segment, "Form") or "circular") == "circular"
            # The diameter of a circular bundle of that area, to the nanometre: the areas are
            # themselves rounded, so more digits would be noise.
            diameter = (
                round(2 * math.sqrt(float(section) / math.pi) / 1000, 9) if section and circular else None
            )
            for assignment in child_elements(segment, "Fixing_assignment"):
                fixing = self.ref(assignment, "Fixing", fixings, "a <Fixing_occurrence>")[0]
                placements[fixing.get("id")].segments.append(ident)
            for area in child_elements(segment, "Protection_area"):
                protection = self.ref(
                    area, "Associated_protection", protections, "a <Wire_protection_occurrence>"
                )[0]
                placements[protection.get("id")].segments.append(ident)
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
                source,
            )
        return segments

    def _length(self, segment: Any, start: Any, end: Any) -> tuple[Decimal | None, str | None]:
        """Physical_length, else Virtual_length, else the centre curve's, else the chord's."""
        physical = self.length(first_child(segment, "Physical_length"))
        virtual = self.length(first_child(segment, "Virtual_length"))
        ends = (self.point(start, "Cartesian_point"), self.point(end, "Cartesian_point"))
        curve = self._curve_length(segment, ends, virtual)
        if physical is not None:
            return physical, "physical"
        if virtual is not None:
            return virtual, "virtual"
        if curve is not None:
            return Decimal(str(round(curve / 1000, 9))), "curve"
        if ends[0] is not None and ends[1] is not None:
            return Decimal(str(round(math.dist(ends[0], ends[1]) / 1000, 9))), "chord"
        return None, None

    def _curve_length(
        self, segment: Any, ends: tuple[tuple[float, ...] | None, ...], virtual: Decimal | None
    ) -> float | None:
        """The length (mm) of the segment's centre curves, start to end; None without curves."""
        curves = child_elements(segment, "Center_curve")
        if not curves:
            return None
        total = 0.0
        first: Any = None
        last: Any = None
        for curve in curves:
            degree_text = child_text(curve, "Degree") or ""
            points = [
                self.coordinates(p)
                for p in self.ref(curve, "Control_points", self.points, "a <Cartesian_point>", many=True)
            ]
            degree = small_integer(degree_text)
            sampled = curve_points(points, degree) if degree is not None else None
            if sampled is None:
                self.error(
                    "<Center_curve> is not a B-spline",
                    curve,
                    found=f"degree {degree_text or 'none'}, {len(points)} control points",
                    expected="a degree from 1 and more control points than the degree",
                )
            total += polyline_length(sampled)
            first = sampled[0] if first is None else first
            last = sampled[-1]
        problems = []
        if virtual is not None and abs(total / 1000 - float(virtual)) > _CURVE_TOLERANCE * float(virtual):
            problems.append(
                f"its length {total:.1f} mm is not the Virtual_length {float(virtual) * 1000:.1f} mm"
            )
        for end, at in ((ends[0], first), (ends[1], last)):
            if end is not None and math.dist(end, at) > _CURVE_END_MM:
                problems.append(f"it ends {math.dist(end, at):.1f} mm from its node")
        if problems:
            warnings.warn(
                IngestWarning(
                    self.path,
                    f"the centre curve of segment {segment.get('id')} "
                    f"does not fit the segment: {'; '.join(problems)}",
                    line=segment.sourceline,
                ),
                stacklevel=5,
            )
        return total

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
