"""What a cell shows a robot's tools and a viewer, as plain data: the static frames the ROS
node publishes on ``/tf_static`` and the markers it publishes on ``~/markers``, which the web
page's 3D view draws too.

Frame names (``child`` of each static transform):

* the manifest's ``[[frame]]`` entries, e.g. ``cabinet`` in ``world``;
* every scene item under its CAD id (the scene's ``DEF``), in its parent item or the scene's frame;
* per component ``LABEL/original``, ``LABEL/corner`` and ``LABEL/target`` in the component's
  frame (the scene's frame, e.g. ``cabinet``), ``LABEL/terminal_start`` for a terminal block;
* per rail ``LABEL/start``;
* elvez: every platform element as ``<CAD ID><platform>`` (``ID0002platform``) and the
  keypoints the reference CAD platform node broadcasts in its element (``ID0002platformguide1``);
* elimco: ``pins_centroid`` and a frame per bench pin (``pin_<name>``, and ``_a``/``_b`` for
  the two pins of a double pin), as the ``pin_frames`` service gives them.

The component frames (original, corner, target, rails) are the cabinet's, published for the
iema profile only. Each use case gives its own frames and markers through its declaration's
``frames`` and ``markers`` (:class:`cadkg.usecase.UseCase`).

Markers: one ``MESH_RESOURCE`` per scene item with a mesh, in the item's own frame, with a
``file://`` URI under the store's files directory; one ``ARROW`` per pin with a screw pose,
from 2 cm above the screw (along the screw's z) down to the screw, in the component's frame;
for elvez one ``MESH_RESOURCE`` per platform element, in its own frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cadkg.registry as registry
from cadkg.errors import CadkgError, QueryError
from cadkg.services.display import Frame, MarkerSpec
from cadkg.services.session import Session

__all__ = ["ARROW_LENGTH", "Shown", "marker_specs", "published_frames", "shown", "static_frames"]


ARROW_LENGTH = 0.02


def static_frames(placed: Any, model: Any, profile: str, session: Session | None = None) -> list[Frame]:
    """One transform per frame of the cell; a name given twice keeps its first placement.

    ``profile`` is the cell's (``""``: the default profile's); ``session`` (with its graph)
    gives the use case's own frames (its ``frames`` hook).
    """
    frames: dict[str, Frame] = {}

    def add(frame: Frame) -> None:
        if frame.child not in frames and frame.child != frame.parent:
            frames[frame.child] = frame

    for name, (parent, pose) in placed.frames.items():
        if pose is not None:
            add(Frame(parent, name, pose))
    hook = registry.use_case(profile).frames
    if hook is not None:
        try:
            for frame in hook(session if session is not None else Session(model)):
                add(frame)
        except QueryError:
            if session is not None:
                raise
            # Without a graph, a use case whose frames are read from it has none to give.
    return list(frames.values())


def marker_specs(
    placed: Any,
    model: Any,
    files_dir: Path,
    profile: str,
    session: Session | None = None,
) -> list[MarkerSpec]:
    """Meshes of the scene items (and of the platform elements) and an arrow onto every screw."""
    specs: list[MarkerSpec] = []
    for index, (item, rel) in enumerate(sorted(placed.meshes.items())):
        uri = "file://" + str((Path(files_dir) / rel).resolve())
        specs.append(MarkerSpec("mesh", "meshes", index, item, mesh_uri=uri, text=item))
    hook = registry.use_case(profile).markers
    if hook is not None and session is not None:
        specs += hook(session, Path(files_dir))
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


@dataclass(frozen=True)
class Shown:
    """What a served cell shows: its frames, its markers, and why the use case's own are
    missing (``""`` when they are not)."""

    frames: list[Frame]
    markers: list[MarkerSpec]
    error: str = ""


def published_frames(session: Session) -> list[Frame]:
    """The frames of :func:`shown`, without making its markers."""
    from cadkg.query.placements import placements

    placed = placements(session.kg)
    try:
        return static_frames(placed, session.model, session.profile, session)
    except CadkgError:
        return static_frames(placed, session.model, session.profile)


def shown(session: Session) -> Shown:
    """The frames and markers of the session's cell as they are now (a service may switch some
    on or off: ``gearbox_display``). When the use case's own frames cannot be made, the cell's
    frames still are, and ``error`` says why; its services report the same error to every
    caller."""
    from cadkg.query.placements import placements

    placed = placements(session.kg)
    files = session.kg.files_dir
    try:
        frames = static_frames(placed, session.model, session.profile, session)
        return Shown(frames, marker_specs(placed, session.model, files, session.profile, session))
    except CadkgError as err:
        frames = static_frames(placed, session.model, session.profile)
        markers = marker_specs(placed, session.model, files, session.profile)
        return Shown(frames, markers, str(err))
