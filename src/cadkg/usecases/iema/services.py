"""The services of Table 1 of D3.1 (profile ``iema``): the cabinet's components, terminal blocks
and clusters, and the cursors that hand the robot its next wire and rail."""

from __future__ import annotations

from typing import Any

import cadkg.usecases.iema.answers as answers
import cadkg.usecases.iema.cursors as cursors
from cadkg.geometry.poses import Pose
from cadkg.services.display import Frame
from cadkg.services.service import Effect, Service, model_services
from cadkg.services.session import Session

__all__ = ["SERVICES", "cabinet_frames"]


def _cabinet(session: Session) -> Any:
    return session.model


# The services answered from the cabinet model alone: they only read.
_service = model_services("iema", _cabinet)


SERVICES: tuple[Service, ...] = (
    _service(
        "cad_service",
        "pose, corner, target, dimensions and pins of a component",
        {"label": str},
        answers.cad_service,
    ),
    _service(
        "full_cad_service",
        "as cad_service, with the component's connections; by label or by CAD item (cad_item)",
        {"label": str, "cad_item": str},
        answers.full_cad_service,
        optional={"label", "cad_item"},
    ),
    _service(
        "get_item_screw_service",
        "screws and holes re-expressed from a detected component pose",
        {"label": str, "detected_pose": Pose},
        answers.get_item_screw_service,
    ),
    _service(
        "get_item_screw_targets",
        "the reference node's get_item_screw_service: pins moved with the detected target pose",
        {"label": str, "cad_pose": Pose},
        answers.get_item_screw_targets,
    ),
    _service(
        "get_terminal_data",
        "pins, start, length and height of a terminal block",
        {"label": str},
        answers.get_terminal_data,
    ),
    _service(
        "cluster_service",
        "horizontal and vertical clusters of a component's connector points",
        {"label": str},
        answers.cluster_service,
    ),
    _service(
        "cad_reference",
        "target and corner pose of a component",
        {"label": str},
        answers.cad_reference,
    ),
    Service(
        "full_connection_provider",
        "next wire end: origin, then destination (occupancy: the gripper holds the wire's first end)",
        {"occupancy": bool},
        cursors.full_connection_provider,
        effect=Effect.CURSOR,
        optional=frozenset({"occupancy"}),
    ),
    Service(
        "group_connection_provider",
        "next wire with both ends, path and keypoints",
        {},
        cursors.group_connection_provider,
        effect=Effect.CURSOR,
    ),
    Service(
        "reset_connection_list",
        "rewind the connection cursor",
        {},
        cursors.reset_connection_list,
        effect=Effect.CURSOR,
    ),
    Service(
        "reset_to_connection_list",
        "move the connection cursor to a list position (from 0) or wire number; source: orig or dest next",
        {"data": float, "source": str, "connection_list": str},
        cursors.reset_to_connection_list,
        effect=Effect.CURSOR,
        optional=frozenset({"source", "connection_list"}),
    ),
    Service(
        "connection_provider_service",
        "the reference node's older provider: the next wire end, origin then destination",
        {"occupancy": bool},
        cursors.connection_provider_service,
        optional=frozenset({"occupancy"}),
        ros_type="FullConnectionProvider",
        effect=Effect.CURSOR,
    ),
    Service(
        "gearbox_display",
        "publish or withdraw the cabinet's frames (LABEL/original, corner, target), in turn",
        {},
        cursors.gearbox_display,
        effect=Effect.CURSOR,
        changes_frames=True,
    ),
    Service(
        "rail_scanner",
        "the components along the next rail",
        {},
        cursors.rail_scanner,
        effect=Effect.CURSOR,
    ),
    Service(
        "reset_rail_scanner",
        "rewind the rail cursor",
        {},
        cursors.reset_rail_scanner,
        effect=Effect.CURSOR,
    ),
)


def cabinet_frames(session: Session) -> list[Frame]:
    """Per component ``LABEL/original``, ``LABEL/corner``, ``LABEL/target`` (and
    ``LABEL/terminal_start`` on a terminal block) in its frame; per rail ``LABEL/start``;
    none while ``gearbox_display`` has withdrawn them."""
    model = session.model
    if not cursors.displayed(session):
        return []
    frames = []
    for label, geometry in sorted(model.components.items()):
        named = [("original", geometry.original), ("corner", geometry.corner), ("target", geometry.target)]
        if geometry.terminal_block:
            named.append(("terminal_start", geometry.terminal_start))
        frames += [Frame(geometry.frame, f"{label}/{name}", pose) for name, pose in named if pose is not None]
    frames += [Frame(model.frame, f"{rail.label}/start", rail.start) for rail in model.rails]
    return frames
