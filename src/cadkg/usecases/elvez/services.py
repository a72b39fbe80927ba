"""Registration of the ELVEZ services (profile ``elvez``): Table 2 of D3.1 with the route
traversal (``/elvez/...`` over ROS), and the reference CAD platform node's services, named
``CAD_platform.NAME`` here and over HTTP, ``/CAD_platform/NAME`` over ROS.

Each service answers from the session's ELVEZ model, built from the graph on first use; the
sequence cursor is the client's (see :mod:`cadkg.usecases.elvez.sequence_services`).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import cadkg.usecases.elvez.answers as table2
import cadkg.usecases.elvez.component_services as components
import cadkg.usecases.elvez.platform_services as platform
import cadkg.usecases.elvez.sequence_services as sequence
from cadkg.errors import CadkgError
from cadkg.services.display import Frame, MarkerSpec
from cadkg.services.service import Effect, Service, model_services
from cadkg.services.session import Session
from cadkg.usecases.elvez.model import PROFILE, model_of
from cadkg.usecases.elvez.platform import box_centre, key_centre, tape_spot_centre

__all__ = ["REFERENCE_NAMESPACE", "REFERENCE_PREFIX", "SERVICES", "element_meshes", "platform_frames"]

REFERENCE_NAMESPACE = "CAD_platform"
"""Where the reference node's services are served over ROS."""
REFERENCE_PREFIX = "CAD_platform."
"""The prefix of their names in ``cadkg call`` and over HTTP."""

_service = model_services(PROFILE, model_of)


def _reference(
    name: str,
    ros_type: str,
    description: str,
    params: Mapping[str, type],
    run: Callable[..., Any],
    *,
    cursor: bool = False,
) -> Service:
    # A cursor service runs on the session (the client's cursor); every other one on the model.
    service = (
        Service(REFERENCE_PREFIX + name, description, params, run, effect=Effect.CURSOR, profile=PROFILE)
        if cursor
        else _service(REFERENCE_PREFIX + name, description, params, run)
    )
    return dataclasses.replace(service, ros_namespace=REFERENCE_NAMESPACE, ros_name=name, ros_type=ros_type)


SERVICES: tuple[Service, ...] = (
    _service(
        "guide_info",
        "a guide's element (CAD ID, size, origin), key centre, corner and size, in the robot base or 'frame'",
        {"name": str, "frame": str},
        table2.guide_info,
        optional={"frame"},
    ),
    _service(
        "cable_info",
        "a cable's colour, length, diameter, harness, end connector and cavities",
        {"name": str},
        table2.cable_info,
    ),
    _service("con_info", "a connector's colour, size, harness and cables", {"name": str}, table2.con_info),
    _service(
        "wh_info",
        "a wire harness's first connector and branches (end connector and cables of each)",
        {"number": int},
        table2.wh_info,
    ),
    _service("all_tools", "the names of every tool", {}, table2.all_tools),
    _service(
        "tool_info",
        "a tool's ATC station, base and end frames, size, and parked base frame",
        {"name": str},
        table2.tool_info,
    ),
    _service(
        "all_op", "every operation of the assembly sequence: order, code, spots, labels", {}, table2.all_op
    ),
    _service("index_op", "one operation by its order (from 1)", {"index": int}, table2.index_op),
    _service(
        "wh_routes",
        "each cable of a harness: cavities, guides it is routed through, taping spots, operations",
        {"number": int},
        table2.wh_routes,
    ),
    _reference(
        "connector_info",
        "ConnectorInfo",
        "a connector or device: kind, colour, reference, model, size (mm), harness, tray, cables, cavities",
        {"label": str},
        components.connector_info,
    ),
    _reference(
        "cable_info",
        "PlatformCableInfo",
        "a cable: colour, length, diameter (mm), harness, tray, connectors and cavities",
        {"label": str},
        components.cable_info,
    ),
    _reference(
        "tray_info",
        "TrayInfo",
        "a tray of a box: corner and centre frames, size, harness kept in it",
        {"box": str, "tray": str},
        platform.tray_info,
    ),
    _reference(
        "jig_info",
        "JigInfo",
        "a jig or comb: model, size, corner frame, guides and taping spots",
        {"jig": str},
        platform.jig_info,
    ),
    _reference(
        "guide_info",
        "PlatformGuideInfo",
        "a guide of a jig or comb: key sizes, key corner and centre, collision box, jig extents and size",
        {"jig": str, "guide": str},
        platform.guide_info,
    ),
    _reference(
        "taping_spot_info",
        "TapingSpotInfo",
        "a taping spot of a jig: size, corner and centre frames",
        {"jig": str, "spot": str},
        platform.taping_spot_info,
    ),
    _reference(
        "all_guides",
        "GuideAllInfo",
        "every guide of every jig: key, jig corner, centre and footprint",
        {},
        platform.all_guides,
    ),
    _reference(
        "next_operation",
        "NextOperation",
        "the operation at the client's cursor; the cursor moves on",
        {},
        sequence.next_operation,
        cursor=True,
    ),
    _reference(
        "reset_sequence_list",
        "ResetSequenceList",
        "rewind the client's sequence cursor",
        {},
        sequence.reset_sequence_list,
        cursor=True,
    ),
    _reference(
        "reset_sequence_list_to",
        "ResetTo",
        "move the client's sequence cursor to an operation (from 0)",
        {"index": int},
        sequence.reset_sequence_list_to,
        cursor=True,
    ),
    _reference(
        "index_operation",
        "IndexOperation",
        "the operation at an index (from 0); the client's cursor moves past it",
        {"index": int},
        sequence.index_operation,
        cursor=True,
    ),
    _reference(
        "all_operations",
        "AllOperations",
        "every operation with its spots (element, guide, side); rewinds the client's cursor",
        {},
        sequence.all_operations,
        cursor=True,
    ),
    _reference(
        "all_cad_components",
        "AllCadComponents",
        "every guide and taping spot of the jigs and tray of the boxes, as LABEL,KIND,ID",
        {},
        platform.all_cad_components,
    ),
    _reference(
        "tool_info",
        "PlatformToolInfo",
        "a tool: type, sizes, parked base frame, end and nail frames",
        {"name": str},
        platform.tool_info,
    ),
    _reference("get_tools_service", "GetList", "the names of every tool", {}, platform.get_tools),
)


def platform_frames(session: Session) -> list[Frame]:
    """The frames the reference node broadcasts besides the scenes': per guide the key's
    centre (``ID0002platformguide1``), per taping spot and tray its centre
    (``…tape_spot1``, ``…tray1``), per ATC station the parked tool's base
    (``ID000002ATC_ATC_base_gun``), each in its element's frame."""
    model = model_of(session)
    frames = []
    for element in model.elements:
        definition = model.definition(element)
        if definition is None or element.frame not in model.tree:
            continue
        frame = element.frame
        frames += [Frame(frame, f"{frame}guide{g.couple}", key_centre(g.key)) for g in definition.guides]
        keys = {g.couple: key_centre(g.key) for g in definition.guides}
        frames += [
            Frame(frame, f"{frame}tape_spot{s.id}", tape_spot_centre(s, keys[s.guide]))
            for s in definition.tape_spots
            if s.guide in keys
        ]
        frames += [Frame(frame, f"{frame}tray{t.id}", box_centre(t)) for t in definition.trays]
        if definition.tool is not None and element.type == "atc_station":
            frames.append(Frame(frame, f"{frame}_ATC_base_{element.tool}", definition.tool.base))
    return frames


def element_meshes(session: Session, files_dir: Path) -> list[MarkerSpec]:
    """One mesh per platform element in its own frame: the STL of its platform's folder named
    by its CAD ID or its model's code, else its shape in the scene."""
    try:
        model = model_of(session)
    except CadkgError:
        return []
    specs: list[MarkerSpec] = []
    for element in model.elements:
        rel = (
            model.meshes.get((element.platform, element.cad_id))
            or model.meshes.get((element.platform, element.model or ""))
            or model.frame_meshes.get(element.frame)
        )
        if rel is not None and element.frame in model.tree:
            uri = "file://" + str((Path(files_dir) / rel).resolve())
            specs.append(
                MarkerSpec("mesh", "elements", len(specs), element.frame, mesh_uri=uri, text=element.label)
            )
    return specs
