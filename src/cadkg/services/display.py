"""What a cell shows, as plain data: a static frame (parent, child, pose) and a marker.

:mod:`cadkg.services.frames` makes them for a cell; a use case adds its own through
:attr:`cadkg.usecase.UseCase.frames` and :attr:`~cadkg.usecase.UseCase.markers`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from cadkg.geometry.poses import Pose, Vec3

__all__ = ["Frame", "MarkerSpec"]


@dataclass(frozen=True)
class Frame:
    parent: str
    child: str
    pose: Pose


@dataclass(frozen=True)
class MarkerSpec:
    kind: str  # "mesh" | "arrow"
    ns: str
    id: int
    frame_id: str
    pose: Pose = field(default_factory=Pose)
    mesh_uri: str = ""
    points: tuple[Vec3, ...] = ()
    text: str = ""
