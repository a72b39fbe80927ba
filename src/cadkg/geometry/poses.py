"""Rigid poses: composition, inversion, points, in plain Python.

Service calls handle a handful of poses each, where plain floats are several
times faster than building numpy arrays; bulk work (meshes) uses numpy elsewhere.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from cadkg.geometry.frames import Quaternion, quaternion_from_rpy

__all__ = ["IDENTITY", "Pose", "Vec3", "bounds", "box_corners", "closest_point_on_segment"]

Vec3 = tuple[float, float, float]


def _qmul(a: Quaternion, b: Quaternion) -> Quaternion:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def _rotate(q: Quaternion, v: Sequence[float]) -> Vec3:
    x, y, z, w = q
    vx, vy, vz = v
    # v' = v + 2w(q×v) + 2 q×(q×v), the cheap form of q v q*.
    cx, cy, cz = y * vz - z * vy, z * vx - x * vz, x * vy - y * vx
    cx, cy, cz = cx + w * vx, cy + w * vy, cz + w * vz
    return (
        vx + 2 * (y * cz - z * cy),
        vy + 2 * (z * cx - x * cz),
        vz + 2 * (x * cy - y * cx),
    )


@dataclass(frozen=True, slots=True)
class Pose:
    """A rigid transform: ``position`` in metres, ``orientation`` as a unit quaternion (x, y, z, w)."""

    position: Vec3 = (0.0, 0.0, 0.0)
    orientation: Quaternion = (0.0, 0.0, 0.0, 1.0)

    @classmethod
    def from_xyz_rpy(cls, xyz: Sequence[float], rpy: Sequence[float]) -> Pose:
        return cls((float(xyz[0]), float(xyz[1]), float(xyz[2])), quaternion_from_rpy(*rpy))

    def __mul__(self, other: Pose) -> Pose:
        """``self · other``: ``other`` expressed in the frame of ``self``, re-expressed in self's parent."""
        moved = _rotate(self.orientation, other.position)
        px, py, pz = self.position
        qx, qy, qz, qw = _qmul(self.orientation, other.orientation)
        # Summed in the order sum() would, written out: a diff composes one pose per pin.
        norm = math.sqrt(qx * qx + qy * qy + qz * qz + qw * qw)
        return Pose(
            (px + moved[0], py + moved[1], pz + moved[2]),
            (qx / norm, qy / norm, qz / norm, qw / norm),
        )

    def inverse(self) -> Pose:
        x, y, z, w = self.orientation
        conj = (-x, -y, -z, w)
        back = _rotate(conj, self.position)
        return Pose((-back[0], -back[1], -back[2]), conj)

    def apply(self, point: Sequence[float]) -> Vec3:
        """The point given in this pose's frame, expressed in its parent frame."""
        r = _rotate(self.orientation, point)
        return (self.position[0] + r[0], self.position[1] + r[1], self.position[2] + r[2])

    def rotate(self, vector: Sequence[float]) -> Vec3:
        return _rotate(self.orientation, vector)

    def at(self, point: Sequence[float]) -> Pose:
        """A pose with this orientation at ``point`` given in this pose's frame."""
        return Pose(self.apply(point), self.orientation)

    def close_to(self, other: Pose, tol: float = 1e-9) -> bool:
        same_sign = sum(a * b for a, b in zip(self.orientation, other.orientation, strict=True)) >= 0
        q = other.orientation if same_sign else tuple(-c for c in other.orientation)
        return all(abs(a - b) <= tol for a, b in zip(self.position, other.position, strict=True)) and all(
            abs(a - b) <= tol for a, b in zip(self.orientation, q, strict=True)
        )


IDENTITY = Pose()


def box_corners(lo: Vec3, hi: Vec3) -> list[Vec3]:
    return [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]


def bounds(points: Iterable[Vec3]) -> tuple[Vec3, Vec3]:
    xs, ys, zs = zip(*points, strict=True)
    return (min(xs), min(ys), min(zs)), (max(xs), max(ys), max(zs))


def closest_point_on_segment(a: Vec3, b: Vec3, p: Vec3) -> Vec3:
    ab = (b[0] - a[0], b[1] - a[1], b[2] - a[2])
    length2 = ab[0] ** 2 + ab[1] ** 2 + ab[2] ** 2
    if length2 == 0.0:
        return a
    t = ((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1] + (p[2] - a[2]) * ab[2]) / length2
    t = min(1.0, max(0.0, t))
    return (a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2])
