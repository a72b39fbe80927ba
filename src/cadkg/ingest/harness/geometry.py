"""Harness geometry: vehicle coordinates to REP 103, and the length of a segment's centre curve.

KBL and VEC give positions in the vehicle frame of the car's design (DIN 70000 as German
makers use it in CAD: x towards the rear, y to the right, z up, millimetres). cadkg keeps
positions in metres in REP 103 axes (x forward, y left, z up): a half turn about z, no mirroring.

Centre curves are B-splines. A KBL ``B_spline_curve`` gives only its degree and control
points: VOBES writes them as unclamped uniform B-splines (knots 0, 1, 2 ...), whose ends lie
on the segment's nodes while the control points lie far away, so the curve is sampled and the
length is that of the sampled polyline. A VEC NURBS curve brings its own knots and weights.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from functools import lru_cache

import numpy as np
import numpy.typing as npt

from cadkg.ingest.harness.records import Position

__all__ = ["SAMPLES", "chord", "curve_points", "polyline_length", "rep103_from_vehicle"]

SAMPLES = 512
"""Points sampled on each curve: a 7-point curve's polyline is then within 1e-5 of its length."""

Array = npt.NDArray[np.float64]


def rep103_from_vehicle(x: float, y: float, z: float, to_metres: float = 0.001) -> Position:
    """A point of the vehicle frame (x rear, y right, z up; in units ``to_metres`` apart) in REP 103."""
    # 0.0 - v, not -v: a coordinate of 0 stays 0.0, not -0.0, in the graph.
    return (0.0 - x * to_metres, 0.0 - y * to_metres, z * to_metres)


def chord(a: Sequence[float], b: Sequence[float]) -> float:
    return math.dist(a, b)


def _basis(knots: Array, degree: int, count: int, u: Array) -> Array:
    """Cox-de Boor: the ``count`` basis functions of ``degree`` at each parameter of ``u``."""
    # The domain's upper end belongs to the span below it, not to the (empty or outer) one above.
    u = np.minimum(u, np.nextafter(knots[count], -np.inf))
    n = ((knots[:-1][None, :] <= u[:, None]) & (u[:, None] < knots[1:][None, :])).astype(np.float64)
    for k in range(1, degree + 1):
        width = n.shape[1] - 1
        left_den = knots[k : k + width] - knots[:width]
        right_den = knots[k + 1 : k + 1 + width] - knots[1 : 1 + width]
        with np.errstate(divide="ignore", invalid="ignore"):
            left = np.where(left_den > 0, (u[:, None] - knots[:width]) / left_den, 0.0)
            right = np.where(right_den > 0, (knots[k + 1 : k + 1 + width] - u[:, None]) / right_den, 0.0)
        n = left * n[:, :width] + right * n[:, 1 : width + 1]
    result: Array = n[:, :count]
    return result


@lru_cache(maxsize=64)
def _uniform(count: int, degree: int, samples: int) -> Array:
    knots = np.arange(count + degree + 1, dtype=np.float64)
    return _basis(knots, degree, count, np.linspace(degree, count, samples))


def curve_points(
    points: Sequence[Sequence[float]],
    degree: int,
    knots: Sequence[float] | None = None,
    weights: Sequence[float] | None = None,
    samples: int = SAMPLES,
) -> Array | None:
    """Points sampled along a B-spline (unclamped uniform without ``knots``; NURBS with
    ``weights``); None when the control points cannot make a curve of that degree."""
    count = len(points)
    if degree < 1 or count <= degree:
        return None
    control = np.asarray(points, dtype=np.float64)
    if knots is None:
        basis = _uniform(count, degree, samples)
    else:
        knot_array = np.asarray(knots, dtype=np.float64)
        if knot_array.size != count + degree + 1 or np.any(np.diff(knot_array) < 0):
            return None
        low, high = knot_array[degree], knot_array[count]
        if not high > low:
            return None
        basis = _basis(knot_array, degree, count, np.linspace(low, high, samples))
    if weights is not None:
        w = np.asarray(weights, dtype=np.float64)
        if w.size != count or np.any(w <= 0):
            return None
        weighted = basis * w[None, :]
        result: Array = (weighted @ control) / weighted.sum(axis=1)[:, None]
        return result
    sampled: Array = basis @ control
    return sampled


def polyline_length(points: Array) -> float:
    return float(np.linalg.norm(np.diff(points, axis=0), axis=1).sum())
