"""What the node publishes on ``/tf_static`` and ``~/markers``, as plain data (no ROS needed).

Frame names (``child`` of each static transform):

* the manifest's ``[[frame]]`` entries, e.g. ``cabinet`` in ``world``;
* every scene item under its CAD id (the scene's ``DEF``), in its parent item or the scene's frame;
* per component ``LABEL/original``, ``LABEL/corner`` and ``LABEL/target`` in the component's
  frame (the scene's frame, e.g. ``cabinet``), ``LABEL/terminal_start`` for a terminal block;
* per rail ``LABEL/start``;
* elvez: every platform element under its CAD id and each point of interest (``G4_key``,
  ``G4_key_corner`` ...) in its element, as the reference's Figure 25 orders them;
* elimco: ``pins_centroid`` and a frame per bench pin (``pin_<name>``, and ``_a``/``_b`` for
  the two pins of a double pin), as the ``pin_frames`` service gives them.

The component frames (original, corner, target, rails) are the cabinet's, published for the
iema profile only.

Markers: one ``MESH_RESOURCE`` per scene item with a mesh, in the item's own frame, with a
``file://`` URI under the store's files directory; one ``ARROW`` per pin with a screw pose,
from 2 cm above the screw (along the screw's z) down to the screw, in the component's frame;
for elvez one ``MESH_RESOURCE`` per platform element with its model's STL, in its own frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from cadkg.geometry.poses import Pose, Vec3

if TYPE_CHECKING:
    from cadkg.usecases.iema.cabinet import CellModel
    from cadkg.usecases.iema.extract import Placements
    from cadkg.usecases.iema.cursors import Session

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


def static_frames(
    placed: Placements, model: CellModel, profile: str = "iema", session: Session | None = None
) -> list[Frame]:
    """One transform per frame of the cell; a name given twice keeps its first placement.

    ``session`` (with its graph) gives the profile's own frames (elvez, elimco).
    """
    frames: dict[str, Frame] = {}

    def add(parent: str, child: str, pose: Pose | None) -> None:
        if pose is not None and child not in frames and child != parent:
            frames[child] = Frame(parent, child, pose)

    for name, (parent, pose) in placed.frames.items():
        add(parent, name, pose)
    if session is not None:
        for parent, child, pose in _profile_frames(profile, session):
            add(parent, child, pose)
    if (profile or "iema") != "iema":
        return list(frames.values())
    for label, geometry in sorted(model.components.items()):
        add(geometry.frame, f"{label}/original", geometry.original)
        add(geometry.frame, f"{label}/corner", geometry.corner)
        add(geometry.frame, f"{label}/target", geometry.target)
        if geometry.terminal_block:
            add(geometry.frame, f"{label}/terminal_start", geometry.terminal_start)
    for rail in model.rails:
        add(model.frame, f"{rail.label}/start", rail.start)
    return list(frames.values())


def _profile_frames(profile: str, session: Session) -> list[tuple[str, str, Pose]]:
    if profile == "elvez":
        from cadkg.usecases.elvez.services import model_of as elvez_model

        return list(elvez_model(session).platforms.tree.transforms())
    if profile == "elimco":
        from cadkg.usecases.elimco.services import model_of as elimco_model
        from cadkg.usecases.elimco.services import pin_frames

        result = pin_frames(elimco_model(session))
        return [(f.parent, f.name, f.pose) for f in result.frames]
    return []


def marker_specs(
    placed: Placements,
    model: CellModel,
    files_dir: Path,
    profile: str = "iema",
    session: Session | None = None,
) -> list[MarkerSpec]:
    """Meshes of the scene items (and of the platform elements) and an arrow onto every screw."""
    specs: list[MarkerSpec] = []
    for index, (item, rel) in enumerate(sorted(placed.meshes.items())):
        uri = "file://" + str((Path(files_dir) / rel).resolve())
        specs.append(MarkerSpec("mesh", "meshes", index, item, mesh_uri=uri, text=item))
    if profile == "elvez" and session is not None:
        from cadkg.usecases.elvez.services import model_of as elvez_model

        elements = sorted(elvez_model(session).platforms.elements.values(), key=lambda e: e.label)
        for index, element in enumerate(e for e in elements if e.mesh):
            uri = "file://" + str((Path(files_dir) / str(element.mesh)).resolve())
            specs.append(
                MarkerSpec("mesh", "elements", index, element.frame, mesh_uri=uri, text=element.label)
            )
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
