"""Distances between straight segments, and a grid that finds the segments near another.

A wire leaving a pin and the corridor a tool takes to reach a screw are both segments; a wire
is in the tool's way when the two pass closer than the tool's clearance. The distances of many
pairs are computed at once (numpy), the pairs worth computing found through the grid.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterator, Sequence
from itertools import product

import numpy as np

from cadkg.geometry.poses import Vec3

__all__ = ["SegmentGrid", "segment_distances"]

_EPS = 1e-12


def segment_distances(p1: np.ndarray, q1: np.ndarray, p2: np.ndarray, q2: np.ndarray) -> np.ndarray:
    """The shortest distance between segments ``p1[i] q1[i]`` and ``p2[i] q2[i]`` for every row
    ``i`` (arrays of shape (n, 3); a segment may be a point).

    >>> a = np.array([[0.0, 0, 0]]); b = np.array([[1.0, 0, 0]])
    >>> segment_distances(a, b, np.array([[0.5, 1, -1]]), np.array([[0.5, 1, 1]])).tolist()
    [1.0]
    """
    d1, d2, r = q1 - p1, q2 - p2, p1 - p2
    a = np.einsum("ij,ij->i", d1, d1)
    e = np.einsum("ij,ij->i", d2, d2)
    b = np.einsum("ij,ij->i", d1, d2)
    c = np.einsum("ij,ij->i", d1, r)
    f = np.einsum("ij,ij->i", d2, r)
    point1, point2 = a <= _EPS, e <= _EPS
    safe_a, safe_e = np.where(point1, 1.0, a), np.where(point2, 1.0, e)
    denominator = a * e - b * b
    # Both segments proper: the closest points of the two lines, clamped to the first segment.
    s = np.where(
        denominator > _EPS,
        np.clip((b * f - c * e) / np.where(denominator > _EPS, denominator, 1.0), 0, 1),
        0.0,
    )
    t = (b * s + f) / safe_e
    low, high = t < 0.0, t > 1.0
    s = np.where(low, np.clip(-c / safe_a, 0, 1), np.where(high, np.clip((b - c) / safe_a, 0, 1), s))
    t = np.clip(t, 0.0, 1.0)
    # A point against a segment, or two points.
    s = np.where(point1, 0.0, np.where(point2, np.clip(-c / safe_a, 0, 1), s))
    t = np.where(point2, 0.0, np.where(point1, np.clip(f / safe_e, 0, 1), t))
    closest1 = p1 + d1 * s[:, None]
    closest2 = p2 + d2 * t[:, None]
    gap = closest1 - closest2
    distances: np.ndarray = np.sqrt(np.einsum("ij,ij->i", gap, gap))
    return distances


class SegmentGrid:
    """Segments filed by the cells of a uniform grid their bounding boxes (grown by ``margin``)
    touch, so the segments near another are found without looking at all of them."""

    def __init__(self, cell: float, margin: float) -> None:
        self.cell, self.margin = cell, margin
        self.cells: dict[tuple[int, int, int], list[int]] = defaultdict(list)
        self.segments: list[tuple[Vec3, Vec3]] = []

    def _span(self, a: Vec3, b: Vec3) -> Iterator[tuple[int, int, int]]:
        cell, margin = self.cell, self.margin
        ranges = [
            range(
                math.floor((min(a[k], b[k]) - margin) / cell),
                math.floor((max(a[k], b[k]) + margin) / cell) + 1,
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

    def near(self, queries: Sequence[tuple[Vec3, Vec3]], distance: float) -> Iterator[tuple[int, int, float]]:
        """``(query, filed segment, how close)`` for every filed segment passing closer than
        ``distance`` (at most the margin) to a query segment; by query, then filed number."""
        pairs: list[tuple[int, int]] = []
        for q, (a, b) in enumerate(queries):
            found: set[int] = set()
            for key in self._span(a, b):
                found.update(self.cells.get(key, ()))
            pairs.extend((q, n) for n in sorted(found))
        if not pairs:
            return
        index = np.array(pairs, dtype=np.int64)
        starts = np.array([s[0] for s in queries], dtype=float)
        ends = np.array([s[1] for s in queries], dtype=float)
        filed = np.array(self.segments, dtype=float).reshape(-1, 2, 3)
        gaps = segment_distances(
            starts[index[:, 0]], ends[index[:, 0]], filed[index[:, 1], 0], filed[index[:, 1], 1]
        )
        for (q, n), gap in zip(pairs, gaps.tolist(), strict=True):
            if gap < distance:
                yield q, n, gap
