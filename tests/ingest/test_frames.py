"""Rotations of the manifest's frames: roll-pitch-yaw to quaternion (REP 103), normalisation."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cadkg.geometry.frames import normalize_quaternion, quaternion_from_rpy

HALF = math.sqrt(0.5)


def rx(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rotate(q: tuple[float, float, float, float], v: np.ndarray) -> np.ndarray:
    """v' = q v q* with the Hamilton product, q = (x, y, z, w)."""
    x, y, z, w = q
    u = np.array([x, y, z])
    return 2 * np.dot(u, v) * u + (w * w - np.dot(u, u)) * v + 2 * w * np.cross(u, v)


@pytest.mark.parametrize(
    ("rpy", "expected"),
    [
        ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)),
        ((0.0, 0.0, math.pi / 2), (0.0, 0.0, HALF, HALF)),
        ((math.pi, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0)),
        ((0.0, math.pi, 0.0), (0.0, 1.0, 0.0, 0.0)),
        ((0.0, 0.0, math.pi), (0.0, 0.0, 1.0, 0.0)),
        ((math.pi / 2, 0.0, 0.0), (HALF, 0.0, 0.0, HALF)),
        ((0.0, -math.pi / 2, 0.0), (0.0, -HALF, 0.0, HALF)),
        ((0.0, 0.0, 1.5707963267948966), (0.0, 0.0, 0.7071068, 0.7071068)),
    ],
    ids=["identity", "yaw-90", "roll-180", "pitch-180", "yaw-180", "roll-90", "pitch-minus-90", "manifest"],
)
def test_quaternion_from_rpy_hand_computed(
    rpy: tuple[float, float, float], expected: tuple[float, float, float, float]
) -> None:
    assert quaternion_from_rpy(*rpy) == pytest.approx(expected, abs=1e-7)


@pytest.mark.parametrize(
    "rpy",
    [(0.3, -0.7, 1.9), (math.pi / 2, math.pi / 4, 0.0), (-2.5, 0.1, -0.4), (0.0, math.pi / 2, 1.0)],
)
def test_combined_rpy_rotates_like_rz_ry_rx(rpy: tuple[float, float, float]) -> None:
    roll, pitch, yaw = rpy
    q = quaternion_from_rpy(roll, pitch, yaw)
    assert math.isclose(sum(c * c for c in q), 1.0, abs_tol=1e-12)
    matrix = rz(yaw) @ ry(pitch) @ rx(roll)
    for v in (np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]), np.array([0.3, -2.0, 5.0])):
        np.testing.assert_allclose(rotate(q, v), matrix @ v, atol=1e-12)


def test_rpy_is_not_the_other_order() -> None:
    # Fixed-axis X, Y, Z (R = Rz Ry Rx) differs from R = Rx Ry Rz for these angles.
    roll, pitch, yaw = 0.3, -0.7, 1.9
    q = quaternion_from_rpy(roll, pitch, yaw)
    v = np.array([0.3, -2.0, 5.0])
    assert not np.allclose(rotate(q, v), rx(roll) @ ry(pitch) @ rz(yaw) @ v, atol=1e-3)


def test_yaw_90_turns_x_into_y() -> None:
    np.testing.assert_allclose(
        rotate(quaternion_from_rpy(0, 0, math.pi / 2), np.array([1.0, 0, 0])), [0, 1, 0], atol=1e-12
    )


@pytest.mark.parametrize(
    ("q", "expected"),
    [
        ((0, 0, 0, 1), (0.0, 0.0, 0.0, 1.0)),
        ((0, 0, 0.7071068, 0.7071068), (0.0, 0.0, HALF, HALF)),
        ((0, 0, 0, 1.0009), (0.0, 0.0, 0.0, 1.0)),
        ((0.5, 0.5, 0.5, 0.5), (0.5, 0.5, 0.5, 0.5)),
        ([0, 0, 0, -0.9995], (0.0, 0.0, 0.0, -1.0)),
    ],
)
def test_normalize_quaternion(q: tuple[float, ...], expected: tuple[float, ...]) -> None:
    result = normalize_quaternion(q)
    assert isinstance(result, tuple) and all(isinstance(c, float) for c in result)
    assert result == pytest.approx(expected, abs=1e-12)
    assert math.isclose(math.sqrt(sum(c * c for c in result)), 1.0, abs_tol=1e-12)


@pytest.mark.parametrize("q", [(0, 0, 0, 2), (0, 0, 0, 0), (1, 1, 1, 1), (0, 0, 0, 1.002), (0, 0, 0.5, 0.5)])
def test_normalize_quaternion_rejects_far_from_unit(q: tuple[float, ...]) -> None:
    with pytest.raises(ValueError, match="is not 1"):
        normalize_quaternion(q)


def test_normalize_quaternion_tolerance() -> None:
    assert normalize_quaternion((0, 0, 0, 1.05), tolerance=0.1) == pytest.approx((0, 0, 0, 1))
    with pytest.raises(ValueError, match=r"quaternion length 1\.05 is not 1"):
        normalize_quaternion((0, 0, 0, 1.05))


def test_normalize_quaternion_needs_four_components() -> None:
    with pytest.raises(ValueError):
        normalize_quaternion((0, 0, 1))
