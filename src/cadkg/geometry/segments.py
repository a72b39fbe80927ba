"""Distances between straight segments, and a grid that finds the segments near another.

A wire leaving a pin and the corridor a tool takes to reach a screw are both segments; a wire
is in the tool's way when the two pass closer than the tool's clearance.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterator
from itertools import product

from cadkg.geometry.poses import Vec3

__all__ = ["SegmentGrid", "segment_distance"]

_EPS = 1e-12


def _sub(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _dot(a: Vec3, b: Vec3) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _clamp(value: float) -> float:
    return 0.0 if value < 0.0 else 1.0 if value > 1.0 else value


def segment_distance(p1: Vec3, q1: Vec3, p2: Vec3, q2: Vec3) -> float:
    """The shortest distance between the segments ``p1 q1`` and ``p2 q2`` (either may be a point).

    >>> segment_distance((0, 0, 0), (1, 0, 0), (0.5, 1, -1), (0.5, 1, 1))
    1.0
    """
    d1, d2, r = _sub(q1, p1), _sub(q2, p2), _sub(p1, p2)
    a, e, f = _dot(d1, d1), _dot(d2, d2), _dot(d2, r)
    if a <= _EPS and e <= _EPS:
        s = t = 0.0
    elif a <= _EPS:
        s, t = 0.0, _clamp(f / e)
    else:
        c = _dot(d1, r)
        if e <= _EPS:
            s, t = _clamp(-c / a), 0.0
        else:
            b = _dot(d1, d2)
            denominator = a * e - b * b
            s = _clamp((b * f - c * e) / denominator) if denominator > _EPS else 0.0
            t = (b * s + f) / e
            if t < 0.0:
                s, t = _clamp(-c / a), 0.0
            elif t > 1.0:
                s, t = _clamp((b - c) / a), 1.0
    c1 = (p1[0] + d1[0] * s, p1[1] + d1[1] * s, p1[2] + d1[2] * s)
    c2 = (p2[0] + d2[0] * t, p2[1] + d2[1] * t, p2[2] + d2[2] * t)
    return math.dist(c1, c2)


class SegmentGrid:
    """Segments filed by the cells of a uniform grid their bounding boxes (grown by ``margin``)
    touch, so the segments near another are found without looking at all of them."""

    def __init__(self, cell: float, margin: float) -> None:
        self.cell, self.margin = cell, margin
        self.cells: dict[tuple[int, int, int], list[int]] = defaultdict(list)
        self.segments: list[tuple[Vec3, Vec3]] = []

    def _span(self, a: Vec3, b: Vec3) -> Iterator[tuple[int, int, int]]:
        ranges = [
            range(
                math.floor((min(a[k], b[k]) - self.margin) / self.cell),
                math.floor((max(a[k], b[k]) + self.margin) / self.cell) + 1,
            )
            for k in range(3)
        ]
        return product(*ranges)  # type: ignore[return-value]

    def add(self, a: Vec3, b: Vec3) -> int:
        """File the segment ``a b``; returns its number."""
        number = len(self.segments)
        self.segments.append((a, b))
        for key in self._span(a, b):
            self.cells[key].append(number)
        return number

    def near(self, a: Vec3, b: Vec3, distance: float) -> Iterator[tuple[int, float]]:
        """The filed segments passing closer than ``distance`` (at most the margin) to ``a b``,
        with how close, each once, in the order they were filed."""
        seen: set[int] = set()
        for key in self._span(a, b):
            seen.update(self.cells.get(key, ()))
        for number in sorted(seen):
            gap = segment_distance(a, b, *self.segments[number])
            if gap < distance:
                yield number, gap
