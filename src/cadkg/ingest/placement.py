"""A pose as files state it: a position and roll-pitch-yaw angles, with the line that says so."""

from __future__ import annotations

from dataclasses import dataclass

from cadkg.geometry.frames import Quaternion, quaternion_from_rpy, quaternion_from_xyz_moving

__all__ = ["Placement"]


@dataclass(frozen=True, slots=True)
class Placement:
    """A pose relative to a model's origin: metres and roll-pitch-yaw radians.

    The angles are fixed-axis X, Y, Z (REP 103, ``Rz·Ry·Rx``) unless ``moving_axes``: then
    they turn about the moving X, then Y, then Z axes (``Rx·Ry·Rz``), as the component model
    files of the IEMA cell are read by the software that writes them.
    """

    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    line: int
    moving_axes: bool = False

    def quaternion(self) -> Quaternion:
        """The orientation as a unit quaternion ``(x, y, z, w)``."""
        if self.moving_axes:
            return quaternion_from_xyz_moving(*self.rpy)
        return quaternion_from_rpy(*self.rpy)
