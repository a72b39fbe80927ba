"""The ELVEZ services of the reference's Table 2, transport-free, and the harness route traversal.

:func:`build_model` (:mod:`cadkg.usecases.elvez.model`) reads the graph once into an
:class:`ElvezModel`; every service is a plain function of that model
returning a frozen dataclass whose first fields are ``success`` and ``message``. An unknown
name gives ``success=False`` and a message saying what is known, never an exception.

Units: metres, radians, unit quaternions ``(x, y, z, w)``; colours are red, green, blue from 0
to 255. Poses are in the robot base frame (``robot_base``) unless ``frame`` names another frame
of the cell. See docs/elvez-services.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import networkx as nx

from cadkg.errors import CadkgError
from cadkg.geometry.poses import Pose
from cadkg.usecases.elvez.model import BranchInfo, ElvezModel, OperationInfo, build_model
from cadkg.usecases.elvez.platform import PlatformElement

__all__ = [
    "AllOpResult",
    "AllToolsResult",
    "BranchInfo",
    "CableInfoResult",
    "CableRoute",
    "ConInfoResult",
    "ElvezModel",
    "GuideInfoResult",
    "IndexOpResult",
    "OperationInfo",
    "ToolInfoResult",
    "WhInfoResult",
    "WhRoutesResult",
    "all_op",
    "all_tools",
    "build_model",
    "cable_info",
    "con_info",
    "guide_info",
    "index_op",
    "tool_info",
    "wh_info",
    "wh_routes",
]

_SHOWN = 12


# -- results ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class GuideInfoResult:
    """``/elvez/guide_info``: a guide's CAD ID, size, origin and key frames and key size."""

    success: bool
    message: str
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
class CableInfoResult:
    """``/elvez/cable_info``; ``con_index`` is [cavity at the main connector, cavity at ``connector``]."""

    success: bool
    message: str
    color: tuple[int, ...] = ()
    length: float = 0.0
    diameter: float = 0.0
    wh: int = 0
    connector: str = ""
    con_index: tuple[int, ...] = ()
    main_connector: str = ""


@dataclass(frozen=True)
class ConInfoResult:
    """``/elvez/con_info``: a connector's colour, size, harness and the cables ending in it."""

    success: bool
    message: str
    color: tuple[int, ...] = ()
    dimensions: tuple[float, ...] = ()
    wh: int = 0
    cables: tuple[str, ...] = ()


@dataclass(frozen=True)
class WhInfoResult:
    """``/elvez/wh_info``: the main connector and the branches of a harness."""

    success: bool
    message: str
    connector: str = ""
    branches: tuple[BranchInfo, ...] = ()


@dataclass(frozen=True)
class AllToolsResult:
    success: bool
    message: str
    names: tuple[str, ...] = ()


@dataclass(frozen=True)
class ToolInfoResult:
    """``/elvez/tool_info``; ``parked_wrist_frame`` is where the wrist meets the tool in its slot."""

    success: bool
    message: str
    atc_spot: str = ""
    base_wrist_frame: Pose | None = None
    wrist_action_frame: Pose | None = None
    dimensions: tuple[float, ...] = ()
    parked_wrist_frame: Pose | None = None


@dataclass(frozen=True)
class AllOpResult:
    success: bool
    message: str
    operations: tuple[OperationInfo, ...] = ()


@dataclass(frozen=True)
class IndexOpResult:
    success: bool
    message: str
    type: str = ""
    spot: tuple[str, ...] = ()
    label: tuple[str, ...] = ()
    tool: str = ""


@dataclass(frozen=True)
class CableRoute:
    """How one cable runs: from a main-connector cavity, through guides, to a branch-connector cavity."""

    cable: str
    from_connector: str
    from_pin: int
    to_connector: str
    to_pin: int
    guides: tuple[str, ...]
    tape_spots: tuple[str, ...]
    operations: tuple[int, ...]


@dataclass(frozen=True)
class WhRoutesResult:
    success: bool
    message: str
    connector: str = ""
    routes: tuple[CableRoute, ...] = ()


# -- the model ---------------------------------------------------------------------------------------------


def _known(names: Any) -> str:
    listed = sorted(names)
    if not listed:
        return "none"
    shown = ", ".join(listed[:_SHOWN])
    return shown + (f" and {len(listed) - _SHOWN} more" if len(listed) > _SHOWN else "")


# -- Table 2 -------------------------------------------------------------------------------------------------


def _element(model: ElvezModel, name: str, kind: str, what: str) -> PlatformElement | str:
    element = model.platforms.elements.get(name.strip())
    if element is None:
        known = [e.label for e in model.platforms.of_kind(kind)]
        return f"no {what} {name!r} on the platforms; {what}s: {_known(known)}"
    if element.kind != kind:
        return f"{element.label} is of type {element.kind}, not a {what}"
    return element


def guide_info(model: ElvezModel, name: str, frame: str = "") -> GuideInfoResult:
    """A guide's CAD ID, dimensions, origin frame, key frame, key corner frame and key size.

    Poses are in ``frame`` (the robot base when empty); lengths in metres.
    """
    element = _element(model, name, "guide", "guide")
    if isinstance(element, str):
        return GuideInfoResult(False, element)
    reference = frame.strip() or model.platforms.robot_base
    missing = [k for k in ("key", "key_corner") if k not in element.keyframes]
    try:
        origin = model.platforms.pose(element.frame, reference)
        key, corner = (
            model.platforms.pose(element.keyframes[k].frame, reference) if k in element.keyframes else None
            for k in ("key", "key_corner")
        )
    except CadkgError as err:
        return GuideInfoResult(False, f"{element.label}: {err}", id=element.cad_id)
    message = f"guide {element.label} ({element.cad_id}, model {element.model or '?'}) in frame {reference}"
    if missing:
        message += f"; model {element.model or '?'} defines no {' or '.join(missing)} frame"
    if element.key_length is None:
        message += f"; model {element.model or '?'} gives no key size"
    return GuideInfoResult(
        success=True,
        message=message,
        id=element.cad_id,
        dimensions=element.dimensions or (),
        origin_frame=origin,
        key_frame=key,
        key_corner_frame=corner,
        key_length=element.key_length or 0.0,
        key_gap=element.key_gap or 0.0,
        key_height=element.key_height or 0.0,
        frame=reference,
    )


def cable_info(model: ElvezModel, name: str) -> CableInfoResult:
    """A cable's colour, length, diameter, harness, branch connector and cavity indices."""
    name = name.strip()
    cable = model.cables.get(name)
    if cable is None:
        if name in model.connectors:
            return CableInfoResult(
                False, f"{name} is a {model.connectors[name].kind}, not a cable; see con_info"
            )
        return CableInfoResult(False, f"no cable {name!r}; cables: {_known(model.cables)}")
    main, end = model.ends.get(name, (None, None))
    number = model.harness_of.get(name, 0)
    notes = []
    if number == 0:
        notes.append("in no harness of the harness structure")
    if cable.length is None or cable.diameter is None or not cable.color:
        notes.append("not in the components list (no colour, length or diameter)")
    return CableInfoResult(
        success=True,
        message=f"cable {name}" + (": " + "; ".join(notes) if notes else ""),
        color=cable.color,
        length=cable.length or 0.0,
        diameter=cable.diameter or 0.0,
        wh=number,
        connector=end.connector if end else "",
        con_index=tuple(e.pin for e in (main, end) if e is not None),
        main_connector=main.connector if main else "",
    )


def _cables_at(model: ElvezModel, connector: str) -> tuple[str, ...]:
    ends = [
        (end.pin, cable)
        for cable, pair in model.ends.items()
        for end in pair
        if end is not None and end.connector == connector
    ]
    return tuple(cable for _, cable in sorted(ends))


def con_info(model: ElvezModel, name: str) -> ConInfoResult:
    """A connector's colour, dimensions, harness and the cables that end in it (by cavity)."""
    name = name.strip()
    connector = model.connectors.get(name)
    if connector is None or connector.kind != "connector":
        if name in model.cables:
            return ConInfoResult(False, f"{name} is a cable, not a connector; see cable_info")
        if connector is not None:
            return ConInfoResult(False, f"{name} is a {connector.kind}, not a connector")
        known = [c.name for c in model.connectors.values() if c.kind == "connector"]
        return ConInfoResult(False, f"no connector {name!r}; connectors: {_known(known)}")
    number = model.harness_of.get(name, 0)
    return ConInfoResult(
        success=True,
        message=f"connector {name}" + ("" if number else ": in no harness of the harness structure"),
        color=connector.color,
        dimensions=connector.dimensions,
        wh=number,
        cables=_cables_at(model, name),
    )


def wh_info(model: ElvezModel, number: int) -> WhInfoResult:
    """A harness's main connector and, per branch, its connector and cables (structure order)."""
    harness = model.harnesses.get(number)
    if harness is None:
        return WhInfoResult(
            False, f"no harness {number}; harnesses: {_known(str(n) for n in model.harnesses)}"
        )
    count = sum(len(b.cables) for b in harness.branches)
    return WhInfoResult(
        True,
        f"harness {number}: {len(harness.branches)} branches, {count} cables",
        harness.main_connector,
        harness.branches,
    )


def all_tools(model: ElvezModel) -> AllToolsResult:
    """The names of every tool."""
    return AllToolsResult(True, f"{len(model.tools)} tools", tuple(model.tools))


def tool_info(model: ElvezModel, name: str) -> ToolInfoResult:
    """A tool's ATC slot, base-to-wrist and wrist-to-action frames, dimensions, and where the
    wrist meets it in its slot (in the robot base frame)."""
    tool = model.tools.get(name.strip())
    if tool is None:
        return ToolInfoResult(False, f"no tool {name!r}; tools: {_known(model.tools)}")
    message = f"tool {tool.name} ({tool.kind}) in slot {tool.atc_slot}"
    parked = None
    slot = model.platforms.elements.get(tool.atc_slot)
    if slot is None:
        message += f"; slot {tool.atc_slot!r} is not on any platform"
    elif tool.base_wrist is not None:
        seat = slot.keyframes.get("key")
        try:
            parked = model.platforms.pose(seat.frame if seat else slot.frame) * tool.base_wrist
        except CadkgError as err:
            message += f"; {err}"
        if seat is None:
            message += (
                f"; model {slot.model or '?'} of {slot.label} defines no key frame: its origin is the seat"
            )
    return ToolInfoResult(
        success=True,
        message=message,
        atc_spot=tool.atc_slot,
        base_wrist_frame=tool.base_wrist,
        wrist_action_frame=tool.wrist_action,
        dimensions=tool.dimensions,
        parked_wrist_frame=parked,
    )


def _unresolved(model: ElvezModel, op: OperationInfo) -> list[str]:
    """What an operation names that the other files do not define."""
    notes = [f"spot {s} is not on any platform" for s in op.spot if s not in model.platforms.elements]
    if op.type == "insert":
        notes += [
            f"{c} is not a connector of the harness files" for c in op.label if c not in model.connectors
        ]
    else:
        notes += [f"{c} is not a cable of the harness files" for c in op.label if c not in model.cables]
    if op.tool not in model.tools:
        notes.append(f"tool {op.tool or '(none)'} is not in the tools file")
    return notes


def all_op(model: ElvezModel) -> AllOpResult:
    """Every operation of the plan, in plan order; the message names what the plan refers to in vain."""
    notes = [f"operation {op.index}: {note}" for op in model.operations for note in _unresolved(model, op)]
    message = f"{len(model.operations)} operations" + ("; " + "; ".join(notes) if notes else "")
    return AllOpResult(True, message, tuple(model.operations))


def index_op(model: ElvezModel, index: int) -> IndexOpResult:
    """The operation at position ``index`` (1-based) of the plan."""
    matches = [op for op in model.operations if op.index == index]
    if not matches:
        last = model.operations[-1].index if model.operations else 0
        return IndexOpResult(False, f"no operation {index}; the plan has operations 1 to {last}")
    if len(matches) > 1:
        return IndexOpResult(
            False, f"{len(matches)} operations have index {index}; the graph holds several plans"
        )
    op = matches[0]
    notes = _unresolved(model, op)
    message = f"operation {index}: {op.type}" + ("; " + "; ".join(notes) if notes else "")
    return IndexOpResult(True, message, op.type, op.spot, op.label, op.tool)


# -- traversal ---------------------------------------------------------------------------------------------


def _related(view: nx.MultiDiGraph, node: str, relation: str, *, reverse: bool = False) -> list[str]:
    edges = view.in_edges(node, keys=True) if reverse else view.out_edges(node, keys=True)
    return [(u if reverse else v) for u, v, key in edges if key == relation]


def wh_routes(model: ElvezModel, number: int) -> WhRoutesResult:
    """For each cable of a harness: the connectors and cavities it runs between, the guides the
    plan routes it through (in plan order) and the spots where it is taped.

    The walk follows the graph's relations (networkx): harness → branch → cable → pins →
    connectors, and cable ← operations → spots.
    """
    harness = model.harnesses.get(number)
    if harness is None:
        return WhRoutesResult(
            False, f"no harness {number}; harnesses: {_known(str(n) for n in model.harnesses)}"
        )
    view = model.view
    labels = nx.get_node_attributes(view, "label")
    by_index = {op.index: op for op in model.operations}
    index_of = model.operation_index
    routes = []
    problems = []
    for branch in _related(view, harness.iri, "hasBranch"):
        for cable in _related(view, branch, "containsCable"):
            name = labels.get(cable, "")
            ends = [
                next(
                    (
                        labels.get(c, "")
                        for p in _related(view, cable, relation)
                        for c in _related(view, p, "pinOf")
                    ),
                    "",
                )
                for relation in ("fromPin", "toPin")
            ]
            guides: list[str] = []
            tapes: list[str] = []
            indices = sorted(
                index_of[op] for op in _related(view, cable, "involves", reverse=True) if op in index_of
            )
            for index in indices:
                op = by_index.get(index)
                if op is None:
                    continue
                spots = [s for s in op.spot if _is_guide(model, s)] if op.type == "route" else list(op.spot)
                target = guides if op.type == "route" else tapes if op.type == "tape" else None
                if target is not None:
                    target.extend(s for s in spots if s not in target)
            if not any(by_index[i].type == "route" for i in indices if i in by_index):
                problems.append(name)
            pair = model.ends.get(name, (None, None))
            routes.append(
                CableRoute(
                    cable=name,
                    from_connector=ends[0],
                    from_pin=pair[0].pin if pair[0] else 0,
                    to_connector=ends[1],
                    to_pin=pair[1].pin if pair[1] else 0,
                    guides=tuple(guides),
                    tape_spots=tuple(tapes),
                    operations=tuple(indices),
                )
            )
    order = {branch.connector: position for position, branch in enumerate(harness.branches)}
    routes.sort(key=lambda r: (order.get(r.to_connector, len(order)), r.to_pin, r.cable))
    message = f"harness {number}: {len(routes)} cables from {harness.main_connector}"
    if problems:
        message += f"; not routed by the plan: {', '.join(sorted(problems))}"
    return WhRoutesResult(True, message, harness.main_connector, tuple(routes))


def _is_guide(model: ElvezModel, label: str) -> bool:
    element = model.platforms.elements.get(label)
    return element is not None and element.kind == "guide"
