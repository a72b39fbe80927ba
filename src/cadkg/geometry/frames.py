"""Frames and poses: rotations in the conventions ROS uses (REP 103).

Quaternions are ``(x, y, z, w)``; roll-pitch-yaw are fixed-axis X, Y, Z angles in
radians, so ``R = Rz(yaw) · Ry(pitch) · Rx(roll)`` as in tf2.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

__all__ = [
    "Quaternion",
    "normalize_quaternion",
    "quaternion_from_axes",
    "quaternion_from_rpy",
    "quaternion_from_xyz_moving",
]

Quaternion = tuple[float, float, float, float]
"""A rotation as ``(x, y, z, w)``, unit length."""


def quaternion_from_rpy(roll: float, pitch: float, yaw: float) -> Quaternion:
    """Unit quaternion of fixed-axis roll, pitch, yaw (radians).

    >>> [round(v, 6) for v in quaternion_from_rpy(0.0, 0.0, math.pi / 2)]
    [0.0, 0.0, 0.707107, 0.707107]
    """
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def quaternion_from_xyz_moving(a: float, b: float, c: float) -> Quaternion:
    """Unit quaternion of ``Rx(a) · Ry(b) · Rz(c)``: turns about the moving X, then Y, then Z axes.

    Not REP 103's roll-pitch-yaw (``Rz · Ry · Rx``); the two agree when at most one angle is
    non-zero.

    >>> [round(v, 6) for v in quaternion_from_xyz_moving(math.pi / 2, 0.0, math.pi / 2)]
    [0.5, -0.5, 0.5, 0.5]
    """
    ca, sa = math.cos(a / 2), math.sin(a / 2)
    cb, sb = math.cos(b / 2), math.sin(b / 2)
    cc, sc = math.cos(c / 2), math.sin(c / 2)
    # qx(a) ⊗ qy(b) ⊗ qz(c), each (x, y, z, w).
    x, y, z, w = sa * cb, ca * sb, sa * sb, ca * cb  # qx(a) ⊗ qy(b)
    return (x * cc + y * sc, y * cc - x * sc, z * cc + w * sc, w * cc - z * sc)


def quaternion_from_axes(x: Sequence[float], y: Sequence[float], z: Sequence[float]) -> Quaternion:
    """Unit quaternion of the rotation whose matrix has the orthonormal columns ``x``, ``y``, ``z``.

    >>> [round(v, 6) for v in quaternion_from_axes((0, 1, 0), (-1, 0, 0), (0, 0, 1))]
    [0.0, 0.0, 0.707107, 0.707107]
    """
    m00, m10, m20 = x
    m01, m11, m21 = y
    m02, m12, m22 = z
    trace = m00 + m11 + m22
    # Shepperd's method: divide by the largest of the four candidates, never by a small one.
    if trace > 0:
        s = 2 * math.sqrt(1 + trace)
        q = ((m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, s / 4)
    elif m00 > m11 and m00 > m22:
        s = 2 * math.sqrt(1 + m00 - m11 - m22)
        q = (s / 4, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s)
    elif m11 > m22:
        s = 2 * math.sqrt(1 + m11 - m00 - m22)
        q = ((m01 + m10) / s, s / 4, (m12 + m21) / s, (m02 - m20) / s)
    else:
        s = 2 * math.sqrt(1 + m22 - m00 - m11)
        q = ((m02 + m20) / s, (m12 + m21) / s, s / 4, (m10 - m01) / s)
    return normalize_quaternion(q)


def normalize_quaternion(q: Sequence[float], tolerance: float = 1e-3) -> Quaternion:
    """Scale ``q`` to unit length; raises ValueError when it is far from unit (a typo, not noise)."""
    x, y, z, w = (float(v) for v in q)
    norm = math.sqrt(x * x + y * y + z * z + w * w)
    if abs(norm - 1.0) > tolerance:
        raise ValueError(f"quaternion length {norm:.6g} is not 1")
    return (x / norm, y / norm, z / norm, w / norm)
