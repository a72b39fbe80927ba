"""The ELVEZ services of D3.1 Table 2 (``/elvez/...``), transport-free, and the harness route
traversal, answered from the ELVEZ model (:mod:`cadkg.usecases.elvez.model`).

Every result's first fields are ``success`` and ``message``; an unknown name gives
``success=False`` and a message saying what is known, never an exception. Units: metres,
radians, unit quaternions ``(x, y, z, w)``; colours red, green, blue from 0 to 255 (from the
colour names of the components file). Poses are in the model's reference frame (``robot_base``
when the manifest places it, else the cell) unless ``frame`` names another. A guide is named
``J4.1`` (element and guide) or ``J4`` when its element has one guide. See docs/elvez-services.md.
"""

from __future__ import annotations

from dataclasses import dataclass

from cadkg.errors import CadkgError
from cadkg.geometry.poses import Pose
from cadkg.usecase import Answer
from cadkg.usecases.elvez.files.harnesses import EndConnector, WiringHarness
from cadkg.usecases.elvez.files.sequence import SequenceStep
from cadkg.usecases.elvez.model import ElvezModel, known, unresolved
from cadkg.usecases.elvez.platform import key_centre

__all__ = [
    "AllOpResult",
    "AllToolsResult",
    "BranchInfo",
    "CableInfoResult",
    "CableRoute",
    "ConInfoResult",
    "GuideInfoResult",
    "IndexOpResult",
    "OperationInfo",
    "ToolInfoResult",
    "WhInfoResult",
    "WhRoutesResult",
    "all_op",
    "all_tools",
    "cable_info",
    "con_info",
    "guide_info",
    "index_op",
    "tool_info",
    "wh_info",
    "wh_routes",
]


@dataclass(frozen=True)
class GuideInfoResult(Answer):
    """``/elvez/guide_info``: the element's CAD ID, size, origin, key centre and corner, key size."""

    id: str = ""
    dimensions: tuple[float, ...] = ()
    origin_frame: Pose | None = None
    key_frame: Pose | None = None
    key_corner_frame: Pose | None = None
    key_length: float = 0.0
    key_gap: float = 0.0
    key_height: float = 0.0
    frame: str = ""


@dataclass(frozen=True)
class CableInfoResult(Answer):
    """``/elvez/cable_info``; ``con_index`` is the cavity [row, column] in the main connector,
    then in ``connector`` when the harness configuration gives it."""

    color: tuple[int, ...] = ()
    length: float = 0.0
    diameter: float = 0.0
    wh: int = 0
    connector: str = ""
    con_index: tuple[int, ...] = ()
    main_connector: str = ""


@dataclass(frozen=True)
class ConInfoResult(Answer):
    """``/elvez/con_info``: a connector's colour, size, harness and the cables ending in it."""

    color: tuple[int, ...] = ()
    dimensions: tuple[float, ...] = ()
    wh: int = 0
    cables: tuple[str, ...] = ()


@dataclass(frozen=True)
class BranchInfo:
    """A branch of a harness: its end connector and its cables (wh_info)."""

    connector: str
    cables: tuple[str, ...]


@dataclass(frozen=True)
class WhInfoResult(Answer):
    connector: str = ""
    branches: tuple[BranchInfo, ...] = ()


@dataclass(frozen=True)
class AllToolsResult(Answer):
    names: tuple[str, ...] = ()


@dataclass(frozen=True)
class ToolInfoResult(Answer):
    """``/elvez/tool_info``: the tool's ATC station, its base in the station's frame, its end in
    the base's frame, its size, and where its base (the wrist's seat) is when it is parked."""

    atc_spot: str = ""
    base_wrist_frame: Pose | None = None
    wrist_action_frame: Pose | None = None
    dimensions: tuple[float, ...] = ()
    parked_wrist_frame: Pose | None = None


@dataclass(frozen=True)
class OperationInfo:
    """One operation: its order, code, spots (``J4.1``, ``C1.1.L``) and labels; no tool is given."""

    index: int
    type: str
    spot: tuple[str, ...]
    label: tuple[str, ...]
    tool: str


@dataclass(frozen=True)
class AllOpResult(Answer):
    operations: tuple[OperationInfo, ...] = ()


@dataclass(frozen=True)
class IndexOpResult(Answer):
    type: str = ""
    spot: tuple[str, ...] = ()
    label: tuple[str, ...] = ()
    tool: str = ""


@dataclass(frozen=True)
class CableRoute:
    """How one cable runs: from its cavity in the main connector, through guides in route
    order, to its end connector; where it is taped and which operations handle it (orders)."""

    cable: str
    from_connector: str
    from_cavity: tuple[int, ...]
    to_connector: str
    to_cavity: tuple[int, ...]
    guides: tuple[str, ...]
    tape_spots: tuple[str, ...]
    operations: tuple[int, ...]


@dataclass(frozen=True)
class WhRoutesResult(Answer):
    connector: str = ""
    routes: tuple[CableRoute, ...] = ()


def _number(harness: WiringHarness) -> int:
    return int(harness.id) if harness.id.isdigit() else 0


def guide_info(model: ElvezModel, name: str, frame: str = "") -> GuideInfoResult:
    """A guide's element (CAD ID, size, origin) and key (centre, corner, size), in ``frame``."""
    label, _, couple = name.strip().partition(".")
    element = model.element(label)
    if element is None or element.type not in ("jig", "comb"):
        return GuideInfoResult(
            False, f"no guide {name!r} on the platforms; guides: {known(_guide_names(model))}"
        )
    definition = model.definition(element)
    guides = definition.guides if definition is not None else ()
    if not couple and len(guides) == 1:
        couple = guides[0].couple
    guide = next((g for g in guides if g.couple == couple), None)
    if definition is None or guide is None:
        couples = known([g.couple for g in guides])
        return GuideInfoResult(
            False, f"{element.label} has no guide {couple or '(none given)'!r}; guides: {couples}"
        )
    reference = frame.strip() or model.reference
    try:
        origin = model.pose(element.frame, reference)
    except CadkgError as err:
        return GuideInfoResult(False, f"{element.label}: {err}", id=element.cad_id)
    return GuideInfoResult(
        success=True,
        message=f"guide {element.label}.{guide.couple} ({element.cad_id} on {element.platform}, "
        f"model {definition.model}) in frame {reference}",
        id=element.cad_id,
        dimensions=definition.size,
        origin_frame=origin,
        key_frame=origin * key_centre(guide.key),
        key_corner_frame=origin * guide.key.corner,
        key_length=guide.key.length,
        key_gap=guide.key.gap,
        key_height=guide.key.height,
        frame=reference,
    )


def _guide_names(model: ElvezModel) -> list[str]:
    names = []
    for element in model.elements:
        definition = model.definition(element)
        if element.type in ("jig", "comb") and definition is not None:
            names += [f"{element.label}.{g.couple}" for g in definition.guides]
    return names


def cable_info(model: ElvezModel, name: str) -> CableInfoResult:
    """A cable's colour, length, diameter, harness, end connector and cavities."""
    name = name.strip()
    component = model.components.get(name)
    found = model.harness_of(name)
    cable = found[2] if found is not None else None
    if cable is None and (component is None or component.kind != "cable"):
        if component is not None or found is not None:
            return CableInfoResult(False, f"{name} is not a cable; see con_info")
        cables = [c.label for c in model.components.values() if c.kind == "cable"]
        return CableInfoResult(False, f"no cable {name!r}; cables: {known(cables)}")
    notes = []
    if found is None or cable is None or found[1] is None:
        notes.append("in no harness of the harness configuration")
    if component is None:
        notes.append("not in the components definition (no colour, length or diameter)")
    harness, end = (found[0], found[1]) if found is not None else (None, None)
    cavities = (*cable.first_cavity, *(cable.end_cavity or ())) if cable is not None else ()
    return CableInfoResult(
        success=True,
        message=f"cable {name}" + (": " + "; ".join(notes) if notes else ""),
        color=(component.rgb or ()) if component is not None else (),
        length=(component.length or 0.0) if component is not None else 0.0,
        diameter=(component.diameter or 0.0) if component is not None else 0.0,
        wh=_number(harness) if harness is not None else 0,
        connector=end.label if end is not None else "",
        con_index=cavities,
        main_connector=harness.first_connector if harness is not None else "",
    )


def con_info(model: ElvezModel, name: str) -> ConInfoResult:
    """A connector's colour, size, harness and the cables that end in it (file order)."""
    name = name.strip()
    component = model.components.get(name)
    found = model.harness_of(name)
    if (component is None or component.kind != "connector") and (found is None or found[2] is not None):
        if component is not None or found is not None:
            return ConInfoResult(
                False, f"{name} is a {component.kind if component else 'cable'}, not a connector"
            )
        connectors = [c.label for c in model.components.values() if c.kind == "connector"]
        return ConInfoResult(False, f"no connector {name!r}; connectors: {known(connectors)}")
    cables: tuple[str, ...] = ()
    notes = []
    harness = found[0] if found is not None else None
    if found is None:
        notes.append("in no harness of the harness configuration")
    else:
        ends: tuple[EndConnector, ...] = found[0].end_connectors if found[1] is None else (found[1],)
        cables = tuple(c.label for e in ends for c in e.cables)
    if component is None:
        notes.append("not in the components definition (no colour or size)")
    return ConInfoResult(
        success=True,
        message=f"connector {name}" + (": " + "; ".join(notes) if notes else ""),
        color=(component.rgb or ()) if component is not None else (),
        dimensions=(component.size or ()) if component is not None else (),
        wh=_number(harness) if harness is not None else 0,
        cables=cables,
    )


def _harness(model: ElvezModel, number: int) -> WiringHarness | str:
    match = next((h for h in model.harnesses if h.id == str(number) or _number(h) == number), None)
    if match is None:
        return f"no harness {number}; harnesses: {known([h.id for h in model.harnesses])}"
    return match


def wh_info(model: ElvezModel, number: int) -> WhInfoResult:
    """A harness's first connector and, per end connector, its cables (file order)."""
    harness = _harness(model, number)
    if isinstance(harness, str):
        return WhInfoResult(False, harness)
    branches = tuple(BranchInfo(e.label, tuple(c.label for c in e.cables)) for e in harness.end_connectors)
    count = sum(len(b.cables) for b in branches)
    return WhInfoResult(
        True,
        f"harness {harness.id}: {len(branches)} branches, {count} cables",
        harness.first_connector,
        branches,
    )


def all_tools(model: ElvezModel) -> AllToolsResult:
    """The names of every tool (the ATC stations' labels without their ``A``)."""
    names = tuple(e.tool for e in model.tools())
    return AllToolsResult(True, f"{len(names)} tools", names)


def tool_info(model: ElvezModel, name: str) -> ToolInfoResult:
    """A tool's ATC station, base and end frames, size, and where its base is when parked."""
    station = model.element("A" + name.strip())
    if station is None or station.type != "atc_station":
        return ToolInfoResult(False, f"no tool {name!r}; tools: {known([e.tool for e in model.tools()])}")
    definition = model.definition(station)
    tool = definition.tool if definition is not None else None
    if tool is None:
        return ToolInfoResult(False, f"{station.label} is of model {station.model}, which defines no tool")
    message = f"{tool.kind} {station.tool} at {station.label} ({station.cad_id} on {station.platform})"
    parked = None
    try:
        parked = model.pose(station.frame) * tool.base
    except CadkgError as err:
        message += f"; {err}"
    return ToolInfoResult(True, message, station.label, tool.base, tool.end, tool.size, parked)


def _spots(step: SequenceStep) -> tuple[str, ...]:
    return tuple(f"{s.jig}.{s.guide}" + (f".{s.side}" if s.side else "") for s in step.spots)


def _operation(step: SequenceStep) -> OperationInfo:
    return OperationInfo(step.order, step.code, _spots(step), step.labels, "")


def all_op(model: ElvezModel) -> AllOpResult:
    """Every operation in sequence order; the message names what they refer to in vain."""
    notes = [f"operation {s.order}: {n}" for s in model.sequence for n in unresolved(model, s)]
    message = f"{len(model.sequence)} operations" + ("; " + "; ".join(notes) if notes else "")
    return AllOpResult(True, message, tuple(_operation(s) for s in model.sequence))


def index_op(model: ElvezModel, index: int) -> IndexOpResult:
    """The operation whose order (the sequence's first column, from 1) is ``index``."""
    matches = [s for s in model.sequence if s.order == index]
    if not matches:
        orders = [s.order for s in model.sequence]
        span = f"{min(orders)} to {max(orders)}" if orders else "none"
        return IndexOpResult(False, f"no operation {index}; the sequence has operations {span}")
    if len(matches) > 1:
        return IndexOpResult(False, f"{len(matches)} operations have order {index}")
    step = matches[0]
    notes = unresolved(model, step)
    message = f"operation {index}: {step.code}" + ("; " + "; ".join(notes) if notes else "")
    op = _operation(step)
    return IndexOpResult(True, message, op.type, op.spot, op.label, op.tool)


def wh_routes(model: ElvezModel, number: int) -> WhRoutesResult:
    """For each cable of a harness: its cavities, the guides the sequence routes it through (in
    route order), the spots where it is taped and the operations that handle it.

    An operation handles a cable when it names the cable, its end connector or its harness's
    first connector (the whole harness); RC gives guides, T and TJ taping spots.
    """
    harness = _harness(model, number)
    if isinstance(harness, str):
        return WhRoutesResult(False, harness)
    routes = []
    unrouted = []
    for end in harness.end_connectors:
        for cable in end.cables:
            names = {cable.label, end.label, harness.first_connector}
            steps = [s for s in model.sequence if names & set(s.labels)]
            guides = [spot for s in steps if s.code.upper() == "RC" for spot in _spots(s)]
            tapes = [spot for s in steps if s.code.upper() in ("T", "TJ") for spot in _spots(s)]
            if not guides:
                unrouted.append(cable.label)
            routes.append(
                CableRoute(
                    cable.label,
                    harness.first_connector,
                    cable.first_cavity,
                    end.label,
                    cable.end_cavity or (),
                    tuple(dict.fromkeys(guides)),
                    tuple(dict.fromkeys(tapes)),
                    tuple(s.order for s in steps),
                )
            )
    message = f"harness {harness.id}: {len(routes)} cables from {harness.first_connector}"
    if unrouted:
        message += f"; not routed by the sequence: {', '.join(unrouted)}"
    return WhRoutesResult(True, message, harness.first_connector, tuple(routes))
