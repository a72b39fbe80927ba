"""The topology of a VEC harness description: nodes and segments (with their stated lengths and
sections), positions and centre curves of its 3D geometry, and what placements put on them."""

from __future__ import annotations

import math
from collections import defaultdict
from dataclasses import replace
from decimal import Decimal
from typing import Any

from cadkg.ingest.harness.geometry import curve_points, polyline_length, rep103_from_vehicle
from cadkg.ingest.harness.records import HarnessNode, HarnessSegment, Position
from cadkg.ingest.harness.vec_parts import VecParts
from cadkg.ingest.harness.xml_tree import child_elements, child_text, element_name, first_child, kind_of
from cadkg.ingest.text import small_integer

__all__ = ["VecTopology"]

_UNITS = ("SIUnit", "OtherUnit", "ImperialUnit", "USUnit")
_POINTS = ("CartesianPoint3D", "CartesianPoint")


def _knot(text: str | None) -> float:
    """A knot's value; NaN (which makes no curve, refused at the curve) where it is not a number."""
    try:
        return float(text or "nan")
    except ValueError:
        return math.nan


class VecTopology(VecParts):
    """A harness description read as far as its topology and geometry."""

    def topology(self) -> tuple[dict[str, HarnessNode], dict[str, HarnessSegment]]:
        doc = self.document
        nodes: dict[str, HarnessNode] = {}
        segments: dict[str, HarnessSegment] = {}
        for specification in self.of_kind("TopologySpecification"):
            for node in child_elements(specification, "TopologyNode"):
                nodes[node.get("id")] = HarnessNode(
                    self.harness, node.get("id"), self.label(node), (), node.sourceline
                )
            for segment in child_elements(specification, "TopologySegment"):
                ends = [
                    doc.ref(segment, name, ("TopologyNode",)).get("id") for name in ("StartNode", "EndNode")
                ]
                length, source = None, None
                for info in child_elements(segment, "LengthInformation"):
                    length = doc.measure(first_child(info, "Length"))
                    source = (child_text(info, "Classification") or "stated").lower()
                    break
                section = next(
                    (
                        doc.measure(first_child(a, "Area"), 2)
                        for a in child_elements(segment, "CrossSectionAreaInformation")
                    ),
                    None,
                )
                round_form = (child_text(segment, "Form") or "round").lower() in ("round", "circular")
                diameter = (
                    round(2 * math.sqrt(float(section) / math.pi) / 1000, 9)
                    if section and round_form
                    else None
                )
                segments[segment.get("id")] = HarnessSegment(
                    self.harness,
                    segment.get("id"),
                    self.label(segment),
                    ends[0],
                    ends[1],
                    length,
                    diameter,
                    section,
                    segment.sourceline,
                    source,
                )
        for segment in segments.values():
            for node in (segment.start, segment.end):
                if node not in nodes:
                    self.document.error(
                        "a segment leads to a node of another harness description",
                        self.document.ids[segment.ident],
                        found=node,
                        expected=f"a TopologyNode of {self.harness}",
                    )
        return nodes, segments

    def geometry(
        self, nodes: dict[str, HarnessNode], segments: dict[str, HarnessSegment]
    ) -> tuple[dict[str, Position], dict[str, float]]:
        """Node positions (metres, REP 103) and centre curve lengths (metres) of the 3D geometry."""
        doc = self.document
        positions: dict[str, Position] = {}
        curves: dict[str, float] = {}
        for specification in self.of_kind("BuildingBlockSpecification3D"):
            unit = doc.ref(specification, "BaseUnit", _UNITS)
            factor = float(doc.unit_factor(unit, 1, "length", first_child(specification, "BaseUnit")))
            for geometry in child_elements(specification, "GeometryNode"):
                node = doc.ref(geometry, "ReferenceNode", ("TopologyNode",), required=False)
                if node is not None:
                    point = self._xyz(doc.ref(geometry, "CartesianPoint", _POINTS))
                    positions[node.get("id")] = rep103_from_vehicle(*point, to_metres=factor)
            for geometry in child_elements(specification, "GeometrySegment"):
                segment = doc.ref(geometry, "ReferenceSegment", ("TopologySegment",), required=False)
                lengths = [
                    self._curve(c)
                    for c in child_elements(geometry, "Curve") + child_elements(geometry, "BSplineCurve")
                ]
                if segment is not None and lengths:
                    curves[segment.get("id")] = sum(lengths) * factor
        return positions, curves

    def _xyz(self, point: Any) -> tuple[float, float, float]:
        values = [self.document.number(point, name) for name in ("X", "Y", "Z")]
        if any(v is None for v in values):
            self.document.error("a CartesianPoint3D without X, Y and Z", point, expected="<X>, <Y> and <Z>")
        x, y, z = (float(v or 0.0) for v in values)
        return (x, y, z)

    def _curve(self, curve: Any) -> float:
        doc = self.document
        degree = child_text(curve, "Degree") or ""
        knots: list[float] | None = None
        weights: list[float] | None = None
        if kind_of(curve) == "NURBSCurve":
            controls = child_elements(curve, "ControlPoint")
            points = [
                self._xyz(
                    doc.ref(
                        c,
                        "CartesianPoint3D"
                        if first_child(c, "CartesianPoint3D") is not None
                        else "CartesianPoint",
                        _POINTS,
                    )
                )
                for c in controls
            ]
            weights = [doc.number(c, "Weight") or 1.0 for c in controls]
            knots = [_knot(k.text) for k in child_elements(curve, "Knots")] or None
        else:
            points = [self._xyz(p) for p in doc.refs(curve, "ControlPoint", _POINTS)]
        order = small_integer(degree)
        sampled = curve_points(points, order, knots, weights) if order is not None else None
        if sampled is None:
            doc.error(
                f"<{curve.tag.rpartition('}')[2]}> is not a B-spline",
                curve,
                found=f"degree {degree or 'none'}, {len(points)} control points",
                expected="a degree from 1, more control points than the degree (and their sum + 1 knots)",
            )
        return polyline_length(sampled)

    @staticmethod
    def with_length(
        segment: HarnessSegment, curve: float | None, positions: dict[str, Position]
    ) -> HarnessSegment:
        if segment.length_m is not None:
            return segment
        if curve is not None:
            return replace(segment, length_m=Decimal(str(round(curve, 9))), length_source="curve")
        if segment.start in positions and segment.end in positions:
            chord = math.dist(positions[segment.start], positions[segment.end])
            return replace(segment, length_m=Decimal(str(round(chord, 9))), length_source="chord")
        return segment

    def placements(
        self, nodes: dict[str, HarnessNode], segments: dict[str, HarnessSegment], connectors: dict[str, Any]
    ) -> tuple[dict[str, list[str]], dict[str, tuple[list[str], list[str]]], dict[str, list[str]]]:
        """Connectors at nodes, fixings on nodes and segments, protections along segments."""
        doc = self.document
        at_node: dict[str, list[str]] = defaultdict(list)
        fixings: dict[str, tuple[list[str], list[str]]] = {
            o.get("id"): ([], []) for o in self.occurrences if self.roles(o, "FixingRole")
        }
        protections: dict[str, list[str]] = {
            o.get("id"): [] for o in self.occurrences if self.roles(o, "WireProtectionRole")
        }
        for specification in self.of_kind("PlacementSpecification"):
            for placement in child_elements(specification, "Placement"):
                placed = []
                for role in doc.refs(placement, "PlacedElement", None):
                    owner = role.getparent()
                    if owner is None or element_name(role) != "Role" or element_name(owner) != "Component":
                        doc.error(
                            "<PlacedElement> of <Placement> names no role of a part occurrence",
                            first_child(placement, "PlacedElement"),
                            found=role.get("id"),
                            expected="the id of a PlaceableElementRole",
                        )
                    placed.append(owner.get("id"))
                on_nodes: list[str] = []
                on_segments: list[str] = []
                for path in child_elements(placement, "Path"):
                    on_segments.extend(
                        s.get("id") for s in doc.refs(path, "Segment", ("TopologySegment",), required=False)
                    )
                for name in ("Location", "StartLocation", "EndLocation"):
                    for location in child_elements(placement, name):
                        if kind_of(location) == "NodeLocation":
                            on_nodes.append(doc.ref(location, "ReferencedNode", ("TopologyNode",)).get("id"))
                        elif kind_of(location) == "SegmentLocation":
                            on_segments.append(
                                doc.ref(location, "ReferencedSegment", ("TopologySegment",)).get("id")
                            )
                for occurrence in placed:
                    if occurrence in connectors:
                        for node in on_nodes:
                            at_node[node].append(occurrence)
                    if occurrence in fixings:
                        fixings[occurrence][0].extend(on_nodes)
                        fixings[occurrence][1].extend(on_segments)
                    if occurrence in protections:
                        protections[occurrence].extend(on_segments)
        return at_node, fixings, protections
