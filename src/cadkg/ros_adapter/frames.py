"""What the node publishes on ``/tf_static`` and ``~/markers``, as plain data (no ROS needed).

Frame names (``child`` of each static transform):

* the manifest's ``[[frame]]`` entries, e.g. ``cabinet`` in ``world``;
* every scene item under its CAD id (the scene's ``DEF``), in its parent item or the scene's frame;
* per component ``LABEL/original``, ``LABEL/corner`` and ``LABEL/target`` in the component's
  frame (the scene's frame, e.g. ``cabinet``), ``LABEL/terminal_start`` for a terminal block;
* per rail ``LABEL/start``.

Markers: one ``MESH_RESOURCE`` per scene item with a mesh, in the item's own frame, with a
``file://`` URI under the store's files directory; one ``ARROW`` per pin with a screw pose,
from 2 cm above the screw (along the screw's z) down to the screw, in the component's frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from cadkg.derive.geometry import Pose, Vec3

if TYPE_CHECKING:
    from cadkg.derive.cabinet import CellModel
    from cadkg.derive.extract import CellInputs

__all__ = ["ARROW_LENGTH", "Frame", "MarkerSpec", "marker_specs", "static_frames"]

ARROW_LENGTH = 0.02


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


def static_frames(inputs: CellInputs, model: CellModel) -> list[Frame]:
    """One transform per frame of the cell; a name given twice keeps its first placement."""
    frames: dict[str, Frame] = {}

    def add(parent: str, child: str, pose: Pose | None) -> None:
        if pose is not None and child not in frames and child != parent:
            frames[child] = Frame(parent, child, pose)

    for name, (parent, pose) in inputs.frames.items():
        add(parent, name, pose)
    for label, geometry in sorted(model.components.items()):
        add(geometry.frame, f"{label}/original", geometry.original)
        add(geometry.frame, f"{label}/corner", geometry.corner)
        add(geometry.frame, f"{label}/target", geometry.target)
        if geometry.terminal_block:
            add(geometry.frame, f"{label}/terminal_start", geometry.terminal_start)
    for rail in model.rails:
        add(model.frame, f"{rail.label}/start", rail.start)
    return list(frames.values())


def marker_specs(inputs: CellInputs, model: CellModel, files_dir: Path) -> list[MarkerSpec]:
    """Meshes of the scene items and an arrow onto every screw."""
    specs: list[MarkerSpec] = []
    for index, (item, rel) in enumerate(sorted(inputs.meshes.items())):
        uri = "file://" + str((Path(files_dir) / rel).resolve())
        specs.append(MarkerSpec("mesh", "meshes", index, item, mesh_uri=uri, text=item))
    index = 0
    for label, geometry in sorted(model.components.items()):
        for name, pin in sorted(geometry.pins.items()):
            if pin.screw is None:
                continue
            tip = pin.screw.position
            tail = pin.screw.apply((0.0, 0.0, ARROW_LENGTH))
            specs.append(
                MarkerSpec("arrow", "pins", index, geometry.frame, points=(tail, tip), text=f"{label}:{name}")
            )
            index += 1
    return specs
