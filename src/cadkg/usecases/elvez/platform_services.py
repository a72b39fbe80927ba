"""The services of the reference's CAD platform node (``CAD_platform/...``), transport-free.

Each answers with the reference's response fields, computed as the reference computes them
(see docs/elvez-services.md): poses in the model's reference frame (``robot_base`` when the
manifest places it, else the cell), element sizes in metres, component lengths, diameters and
sizes in millimetres and colours by name, as the components file gives them. Where the
reference node fails (an unknown label, a definition without a centre, a box asked for as a
jig) the answer is ``success=False`` with a message; ``message`` is cadkg's addition.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace

from cadkg.errors import CadkgError
from cadkg.geometry.poses import Pose
from cadkg.usecase import Answer
from cadkg.usecases.elvez.files.definitions import ElementDefinition, Guide
from cadkg.usecases.elvez.files.harnesses import split_tray
from cadkg.usecases.elvez.model import Element, ElvezModel, known
from cadkg.usecases.elvez.platform import box_centre, key_centre, tape_spot_centre

__all__ = [
    "AllCadComponentsResult",
    "GetListResult",
    "GuideAllInfoResult",
    "JigGuideData",
    "JigInfoResult",
    "JigTapeData",
    "NameList",
    "PlatformGuideInfoResult",
    "PlatformToolInfoResult",
    "TapingSpotInfoResult",
    "TrayInfoResult",
    "all_cad_components",
    "all_guides",
    "get_tools",
    "guide_info",
    "jig_info",
    "taping_spot_info",
    "tool_info",
    "tray_info",
]


@dataclass(frozen=True)
class JigGuideData:
    """A guide of a jig or comb (the reference's ``jig_guide_data``); unset poses are None."""

    id: str = ""
    key_length: float = 0.0
    key_gap: float = 0.0
    key_height: float = 0.0
    key_height_corner: float = 0.0
    key_corner_frame: Pose | None = None
    key_center_frame: Pose | None = None
    jig_corner_frame: Pose | None = None
    jig_center_frame: Pose | None = None
    jig_dimensions: tuple[float, ...] = ()
    collision_dimensions: tuple[float, ...] = ()
    dimensions: tuple[float, ...] = ()
    collision_corner_frame: Pose | None = None
    collisions: tuple[float, ...] = ()


@dataclass(frozen=True)
class JigTapeData:
    id: str = ""
    dimensions: tuple[float, ...] = ()
    corner_frame: Pose | None = None
    center_frame: Pose | None = None


@dataclass(frozen=True)
class TrayInfoResult(Answer):
    key_corner_frame: Pose | None = None
    key_center_frame: Pose | None = None
    wh: str = ""
    dimensions: tuple[float, ...] = ()


@dataclass(frozen=True)
class JigInfoResult(Answer):
    commercial: str = ""
    dimensions: tuple[float, ...] = ()
    corner_frame: Pose | None = None
    guides: tuple[JigGuideData, ...] = ()
    taping_spots: tuple[JigTapeData, ...] = ()


@dataclass(frozen=True)
class PlatformGuideInfoResult(Answer):
    data: JigGuideData = field(default_factory=JigGuideData)


@dataclass(frozen=True)
class TapingSpotInfoResult(Answer):
    data: JigTapeData = field(default_factory=JigTapeData)


@dataclass(frozen=True)
class GuideAllInfoResult(Answer):
    data: tuple[JigGuideData, ...] = ()


@dataclass(frozen=True)
class NameList(Answer):
    """A list of names, the reference's ``string[] data`` response."""

    data: tuple[str, ...] = ()


@dataclass(frozen=True)
class AllCadComponentsResult(NameList):
    """``all_cad_components``: a jig's guides and taping spots, a box's trays."""


@dataclass(frozen=True)
class GetListResult(NameList):
    """``get_tools_service``: the tools' names."""


@dataclass(frozen=True)
class PlatformToolInfoResult(Answer):
    type: str = ""
    dim: tuple[float, ...] = ()
    dim_tool: tuple[float, ...] = ()
    dim_fingers: tuple[float, ...] = ()
    pose_nail: Pose | None = None
    pose_base: Pose | None = None
    pose_end: Pose | None = None


_NAMES = {
    "table": "a table",
    "jig": "a jig",
    "box": "a box",
    "comb": "a comb",
    "atc_station": "an ATC station",
}


def _defined(
    model: ElvezModel, label: str, types: tuple[str, ...], what: str
) -> tuple[Element, ElementDefinition] | str:
    element = model.element(label)
    if element is None or element.type not in types:
        labels = [e.label for e in model.elements if e.type in types]
        if element is not None:
            return f"{element.label} is {_NAMES.get(element.type, 'an element')}, not {what}"
        return f"no {what.split(' ', 1)[1]} {label!r}; known: {known(labels)}"
    definition = model.definition(element)
    if definition is None:
        code = element.model or "(none)"
        return f"{element.label} ({element.where}) is of model {code}, which no definition gives"
    return element, definition


def _where(element: Element) -> str:
    return f"{element.label} ({element.cad_id} on {element.platform})"


def _guide_data(frame: Pose, guide: Guide, collisions: tuple[float, ...], ident: str) -> JigGuideData:
    key = guide.key
    return JigGuideData(
        id=ident,
        key_length=key.length,
        key_gap=key.gap,
        key_height=key.height,
        key_height_corner=key.height_corner,
        key_corner_frame=frame * key.corner,
        key_center_frame=frame * key_centre(key),
        collision_dimensions=guide.collision.size if guide.collision else (),
        collision_corner_frame=frame * guide.collision.corner if guide.collision else None,
        collisions=collisions,
    )


def guide_info(model: ElvezModel, jig: str, guide: str) -> PlatformGuideInfoResult:
    """A guide of a jig or comb: key sizes, key corner and centre, collision box, and the
    jig's extents (``collisions``) and size (``dimensions``)."""
    found = _defined(model, jig, ("jig", "comb"), "a jig or comb")
    if isinstance(found, str):
        return PlatformGuideInfoResult(False, found)
    element, definition = found
    match = next((g for g in definition.guides if g.couple == guide.strip()), None)
    if match is None:
        return PlatformGuideInfoResult(
            False,
            f"{element.label} has no guide {guide!r}; guides: {known([g.couple for g in definition.guides])}",
        )
    try:
        frame = model.pose(element.frame)
    except CadkgError as err:
        return PlatformGuideInfoResult(False, f"{element.label}: {err}")
    data = _guide_data(frame, match, definition.extents or (), match.couple)
    return PlatformGuideInfoResult(
        True,
        f"guide {match.couple} of {_where(element)} in {model.reference}",
        replace(data, dimensions=definition.size),
    )


def all_guides(model: ElvezModel) -> GuideAllInfoResult:
    """Every guide of every jig (J labels, not combs): id = the jig's label, key sizes and
    centre, the jig's corner, centre, size and footprint (``jig_dimensions``)."""
    data = []
    notes = []
    for element in model.elements:
        definition = model.definition(element)
        if element.type != "jig" or definition is None or element is not model.element(element.label):
            continue
        try:
            frame = model.pose(element.frame)
        except CadkgError as err:
            notes.append(f"{element.label}: {err}")
            continue
        if definition.centre is None:
            notes.append(f"{element.label}: model {definition.model} gives no centre")
        centre = frame * Pose((*definition.centre, 0.0)) if definition.centre is not None else None
        footprint = (*definition.footprint, 0.0) if definition.footprint is not None else ()
        for guide in definition.guides:
            data.append(
                JigGuideData(
                    id=element.label,
                    key_length=guide.key.length,
                    key_gap=guide.key.gap,
                    key_height=guide.key.height,
                    dimensions=definition.size,
                    key_center_frame=frame * key_centre(guide.key),
                    jig_corner_frame=frame,
                    jig_center_frame=centre,
                    jig_dimensions=footprint,
                )
            )
    message = f"{len(data)} guides" + ("; " + "; ".join(notes) if notes else "")
    return GuideAllInfoResult(bool(data), message, tuple(data))


def jig_info(model: ElvezModel, jig: str) -> JigInfoResult:
    """A jig or comb: model, size, corner frame, its guides (with the key's own extents as
    ``collisions``) and taping spots."""
    found = _defined(model, jig, ("jig", "comb"), "a jig or comb")
    if isinstance(found, str):
        return JigInfoResult(False, found)
    element, definition = found
    try:
        frame = model.pose(element.frame)
    except CadkgError as err:
        return JigInfoResult(False, f"{element.label}: {err}")
    guides = tuple(_guide_data(frame, g, g.key.extents, g.couple) for g in definition.guides)
    spots = tuple(_tape_data(frame, definition, s.id) for s in definition.tape_spots)
    return JigInfoResult(
        True,
        f"{_where(element)[:-1]}, model {definition.model}) in {model.reference}",
        definition.model,
        definition.size,
        frame,
        guides,
        spots,
    )


def _tape_data(frame: Pose, definition: ElementDefinition, ident: str) -> JigTapeData:
    spot = next(s for s in definition.tape_spots if s.id == ident)
    guide = next(g for g in definition.guides if g.couple == spot.guide)
    centre = tape_spot_centre(spot, key_centre(guide.key))
    return JigTapeData(spot.id, spot.size, frame * spot.corner, frame * centre)


def taping_spot_info(model: ElvezModel, jig: str, spot: str) -> TapingSpotInfoResult:
    """A taping spot of a jig: size, corner, and centre on the line of its guide's cables."""
    found = _defined(model, jig, ("jig",), "a jig")
    if isinstance(found, str):
        return TapingSpotInfoResult(False, found)
    element, definition = found
    if spot.strip() not in {s.id for s in definition.tape_spots}:
        ids = [s.id for s in definition.tape_spots]
        return TapingSpotInfoResult(
            False, f"{element.label} has no taping spot {spot!r}; taping spots: {known(ids)}"
        )
    try:
        frame = model.pose(element.frame)
    except CadkgError as err:
        return TapingSpotInfoResult(False, f"{element.label}: {err}")
    return TapingSpotInfoResult(
        True, f"taping spot {spot.strip()} of {element.label}", _tape_data(frame, definition, spot.strip())
    )


def tray_info(model: ElvezModel, box: str, tray: str) -> TrayInfoResult:
    """A tray of a box: corner, centre (of its floor), size, and the harness kept in it."""
    found = _defined(model, box, ("box",), "a box")
    if isinstance(found, str):
        users = sorted({h.tray for h in model.harnesses if split_tray(h.tray)[0] == box.strip()})
        note = f" (harness tray {', '.join(users)} names it)" if users else ""
        return TrayInfoResult(False, found + note)
    element, definition = found
    match = next((t for t in definition.trays if t.id == tray.strip()), None)
    if match is None:
        ids = [t.id for t in definition.trays]
        return TrayInfoResult(False, f"{element.label} has no tray {tray!r}; trays: {known(ids)}")
    try:
        frame = model.pose(element.frame)
    except CadkgError as err:
        return TrayInfoResult(False, f"{element.label}: {err}")
    kept = [h.id for h in model.harnesses if split_tray(h.tray) == (element.label, match.id)]
    return TrayInfoResult(
        True,
        f"tray {match.id} of {element.label}" + (f", harness {kept[-1]}" if kept else ", no harness"),
        frame * match.corner,
        frame * box_centre(match),
        kept[-1] if kept else "",
        match.size,
    )


def all_cad_components(model: ElvezModel) -> AllCadComponentsResult:
    """``J1,guides,1`` per guide and ``J1,tape_spots,ID`` per taping spot of every jig,
    ``B1,trays,ID`` per tray of every box."""
    data = []
    for element in model.elements:
        definition = model.definition(element)
        if definition is None or element is not model.element(element.label):
            continue
        if element.type == "jig":
            data += [f"{element.label},guides,{g.couple}" for g in definition.guides]
            data += [f"{element.label},tape_spots,{s.id}" for s in definition.tape_spots]
        elif element.type == "box":
            data += [f"{element.label},trays,{t.id}" for t in definition.trays]
    return AllCadComponentsResult(True, f"{len(data)} components", tuple(data))


def get_tools(model: ElvezModel) -> GetListResult:
    """The tools of the ATC stations: each A label without its ``A``."""
    names = [e.tool for e in model.tools()]
    return GetListResult(True, f"{len(names)} tools", tuple(names))


def tool_info(model: ElvezModel, name: str) -> PlatformToolInfoResult:
    """A tool (ATC station ``A`` + name): type, size, where its base is parked, its end (in the
    base's frame) and, for a gripper, finger size and nail (in the base's frame)."""
    found = _defined(model, "A" + name.strip(), ("atc_station",), "a tool")
    if isinstance(found, str):
        return PlatformToolInfoResult(
            False, f"no tool {name!r}; tools: {known([e.tool for e in model.tools()])}"
        )
    element, definition = found
    tool = definition.tool
    if tool is None:
        return PlatformToolInfoResult(False, f"model {definition.model} of {element.label} defines no tool")
    try:
        base = model.pose(element.frame) * tool.base
    except CadkgError as err:
        return PlatformToolInfoResult(False, f"{element.label}: {err}")
    gripper = tool.kind == "gripper"
    return PlatformToolInfoResult(
        True,
        f"{tool.kind} {name.strip()} parked at {_where(element)} in {model.reference}",
        type=tool.kind,
        dim_tool=tool.size,
        dim_fingers=(tool.fingers or ()) if gripper else (),
        pose_nail=tool.nail if gripper else None,
        pose_base=base,
        pose_end=tool.end,
    )
