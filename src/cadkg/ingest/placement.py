"""A pose as files state it: a position and roll-pitch-yaw angles, with the line that says so."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["Placement"]


@dataclass(frozen=True, slots=True)
class Placement:
    """A pose relative to a model's origin: metres and roll-pitch-yaw radians."""

    xyz: tuple[float, float, float]
    rpy: tuple[float, float, float]
    line: int
