"""Distances between straight segments, and a grid that finds the segments near another.

A wire leaving a pin and the corridor a tool takes to reach a screw are both segments; a wire
is in the tool's way when the two pass closer than the tool's clearance. The distances of many
pairs are computed at once (numpy), the pairs worth computing found through a grid of cubes.
"""

from __future__ import annotations

from itertools import product

import numpy as np

__all__ = ["close_pairs", "segment_distances"]

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


def close_pairs(
    queries: np.ndarray, filed: np.ndarray, distance: float, chunk: int = 4096
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(query, filed, gap)`` arrays: every filed segment passing closer than ``distance`` to a
    query segment (arrays of shape (n, 2, 3): start and end of each), by query, then filed number.

    Each filed segment is binned by the lowest corner of its box grown by ``distance``, in cubes
    as large as the longest filed segment and twice the distance (or a third of the longest
    query, when that is more), so the grown box lies in that
    cube and the next along each axis. A query can only come near the filed segments binned from
    the cube before its box's lowest corner to the cube of its highest: those are found by
    sorting, not by looking at every pair.
    """
    none = np.zeros(0, dtype=np.int64)
    if not len(queries) or not len(filed):
        return none, none, np.zeros(0)
    # A query spans at most a few cubes along each axis, however long it is.
    longest = float(np.abs(queries[:, 1] - queries[:, 0]).max())
    cube = max(float(np.abs(filed[:, 1] - filed[:, 0]).max()) + 2 * distance, longest / 3) + 1e-9
    keys = np.floor((filed.min(axis=1) - distance) / cube).astype(np.int64)
    low = keys.min(axis=0)
    span = keys.max(axis=0) - low + 1
    code = _codes(keys - low, span)
    order = np.argsort(code, kind="stable")
    sorted_codes = code[order]
    found: list[tuple[np.ndarray, np.ndarray, np.ndarray]] = []
    for first in range(0, len(queries), chunk):
        block = queries[first : first + chunk]
        lowest = np.floor(block.min(axis=1) / cube).astype(np.int64) - 1 - low
        highest = np.minimum(np.floor(block.max(axis=1) / cube).astype(np.int64) - low, span - 1)
        lowest = np.maximum(lowest, 0)
        found_q: list[np.ndarray] = []
        found_f: list[np.ndarray] = []
        widths = np.maximum(highest - lowest, -1).max(axis=0) + 1
        for offset in product(*(range(int(w)) for w in widths)):
            cell = lowest + np.array(offset)
            inside = np.all(cell <= highest, axis=1)
            wanted = np.where(inside, _codes(np.minimum(cell, span - 1), span), -1)
            lo = np.searchsorted(sorted_codes, wanted, side="left")
            hi = np.searchsorted(sorted_codes, wanted, side="right")
            counts = np.where(inside, hi - lo, 0)
            if not counts.any():
                continue
            rows = np.repeat(np.arange(len(block)), counts)
            starts = np.repeat(lo, counts)
            steps = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
            found_q.append(rows)
            found_f.append(order[starts + steps])
        if not found_q:
            continue
        q, f = np.concatenate(found_q), np.concatenate(found_f)
        gaps = segment_distances(block[q, 0], block[q, 1], filed[f, 0], filed[f, 1])
        near = gaps < distance
        q, f, gaps = q[near] + first, f[near], gaps[near]
        by = np.lexsort((f, q))
        found.append((q[by], f[by], gaps[by]))
    if not found:
        return none, none, np.zeros(0)
    q, f, gaps = (np.concatenate(parts) for parts in zip(*found, strict=True))
    return q, f, gaps


def _codes(cells: np.ndarray, span: np.ndarray) -> np.ndarray:
    """One integer per cube (x, y, z) of a grid ``span`` cubes wide."""
    result: np.ndarray = (cells[:, 0] * span[1] + cells[:, 1]) * span[2] + cells[:, 2]
    return result
