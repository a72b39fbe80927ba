"""The table of services by name, with their parameters: what the CLI and the ROS adapter call.

``call(session, "cad_service", label="F1500.1")`` runs one service; parameters
arrive as text from the command line and are converted here, so every transport
gets the same checks and messages.

Each service belongs to a profile (the use case of a cell: iema, elvez, elimco, vw,
enki); the IEMA services are listed here, the other profiles' in their own modules,
which :func:`register` them when imported at the end of this one.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass
from importlib import import_module
from typing import Any

from cadkg.geometry.frames import normalize_quaternion, quaternion_from_rpy
from cadkg.geometry.poses import Pose
from cadkg.errors import QueryError
from cadkg.usecases.iema import answers as iema
from cadkg.usecases.iema.cursors import Session

__all__ = [
    "SERVICES",
    "Service",
    "call",
    "on_model",
    "parse_pose",
    "register",
    "services_for",
    "to_jsonable",
]


@dataclass(frozen=True)
class Service:
    """``run(session, client=..., **params)``; ``optional`` parameters may be left out."""

    name: str
    description: str
    params: Mapping[str, type]
    run: Callable[..., Any]
    profile: str = "iema"
    optional: frozenset[str] = frozenset()


def parse_pose(text: str) -> Pose:
    """``x,y,z,qx,qy,qz,qw`` or ``x,y,z,roll,pitch,yaw`` (metres, radians)."""
    try:
        values = [float(v) for v in text.replace(" ", ",").split(",") if v]
    except ValueError:
        raise QueryError(
            f"not a pose: {text!r}; expected x,y,z,qx,qy,qz,qw or x,y,z,roll,pitch,yaw"
        ) from None
    if len(values) not in (6, 7) or not all(math.isfinite(v) for v in values):
        raise QueryError(f"not a pose: {text!r}; expected 6 or 7 finite numbers")
    xyz = (values[0], values[1], values[2])
    if len(values) == 6:
        return Pose(xyz, quaternion_from_rpy(*values[3:]))
    try:
        return Pose(xyz, normalize_quaternion(values[3:]))
    except ValueError as err:
        raise QueryError(f"not a pose: {text!r}: {err}") from None


def _bool(text: str) -> bool:
    lowered = text.strip().lower()
    if lowered in ("true", "1", "yes"):
        return True
    if lowered in ("false", "0", "no"):
        return False
    raise QueryError(f"not a boolean: {text!r}; expected true or false")


def _float(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise QueryError(f"not a number: {text!r}") from None
    if not math.isfinite(value):
        raise QueryError(f"not a finite number: {text!r}")
    return value


def _int(text: str) -> int:
    try:
        return int(text.strip())
    except ValueError:
        raise QueryError(f"not an integer: {text!r}") from None


_CONVERT: dict[type, Callable[[str], Any]] = {
    str: str,
    bool: _bool,
    float: _float,
    int: _int,
    Pose: parse_pose,
}


def on_model(fn: Callable[..., Any], model_of: Callable[[Session], Any]) -> Callable[..., Any]:
    """The ``run`` of a service answered by ``fn(model, **params)`` without cursors: ``model_of``
    picks the model from the session (the cabinet's, or a profile's built on first use)."""

    def run(session: Session, client: str = "default", **params: Any) -> Any:
        return fn(model_of(session), **params)

    return run


def model_services(profile: str, model_of: Callable[[Session], Any]) -> Callable[..., Service]:
    """The maker of ``profile``'s services answered from its model:
    ``make(name, description, params, answer, optional=())`` (see :func:`on_model`)."""

    def make(
        name: str,
        description: str,
        params: Mapping[str, type],
        answer: Callable[..., Any],
        optional: Iterable[str] = (),
    ) -> Service:
        return Service(
            name,
            description,
            params,
            on_model(answer, model_of),
            profile=profile,
            optional=frozenset(optional),
        )

    return make


def _cabinet(session: Session) -> Any:
    return session.model


def _label(fn: Callable[..., Any]) -> Callable[..., Any]:
    return on_model(fn, _cabinet)


SERVICES: dict[str, Service] = {
    s.name: s
    for s in (
        Service(
            "cad_service",
            "pose, corner, target, dimensions and pins of a component",
            {"label": str},
            _label(iema.cad_service),
        ),
        Service(
            "full_cad_service",
            "as cad_service, with the component's connections",
            {"label": str},
            _label(iema.full_cad_service),
        ),
        Service(
            "get_item_screw_service",
            "screws and holes re-expressed from a detected component pose",
            {"label": str, "detected_pose": Pose},
            on_model(iema.get_item_screw_service, _cabinet),
        ),
        Service(
            "get_terminal_data",
            "pins, start, length and height of a terminal block",
            {"label": str},
            _label(iema.get_terminal_data),
        ),
        Service(
            "cluster_service",
            "horizontal and vertical clusters of a component's connector points",
            {"label": str},
            _label(iema.cluster_service),
        ),
        Service(
            "cad_reference",
            "target and corner pose of a component",
            {"label": str},
            _label(iema.cad_reference),
        ),
        Service(
            "full_connection_provider",
            "next wire end to handle (occupancy: the gripper holds the wire's first end)",
            {"occupancy": bool},
            lambda s, occupancy, client="default": s.full_connection_provider(occupancy, client),
        ),
        Service(
            "group_connection_provider",
            "next wire with both ends, path and keypoints",
            {},
            lambda s, client="default": s.group_connection_provider(client),
        ),
        Service(
            "reset_connection_list",
            "rewind the connection cursor",
            {},
            lambda s, client="default": s.reset_connection_list(client),
        ),
        Service(
            "reset_to_connection_list",
            "move the connection cursor to a wire number (or list position) of a source",
            {"data": float, "source": str},
            lambda s, data, source="", client="default": s.reset_to_connection_list(data, source, client),
            optional=frozenset({"source"}),
        ),
        Service(
            "rail_scanner",
            "the components along the next rail",
            {},
            lambda s, client="default": s.rail_scanner(client),
        ),
        Service(
            "reset_rail_scanner",
            "rewind the rail cursor",
            {},
            lambda s, client="default": s.reset_rail_scanner(client),
        ),
    )
}


def register(*services: Service) -> None:
    """Add the services of a profile module; a name may be registered once."""
    for service in services:
        if service.name in SERVICES:
            raise ValueError(f"service {service.name!r} is already registered")
        SERVICES[service.name] = service


def services_for(profile: str) -> list[Service]:
    """The services of one profile (``""`` counts as iema, the first profile)."""
    wanted = profile or "iema"
    return [s for s in SERVICES.values() if s.profile == wanted]


def call(session: Session, name: str, params: Mapping[str, str | Any], client: str = "default") -> Any:
    """Run service ``name``; text parameters are converted to the service's types.

    Raises
    ------
    QueryError
        On an unknown service, a missing, unknown or malformed parameter.
    """
    service = SERVICES.get(name)
    if service is None:
        raise QueryError(f"unknown service {name!r}; known: {', '.join(sorted(SERVICES))}")
    unknown = set(params) - set(service.params)
    if unknown:
        raise QueryError(
            f"{name}: unknown parameter {', '.join(sorted(unknown))}; "
            f"parameters: {', '.join(service.params) or 'none'}"
        )
    missing = [p for p in service.params if p not in params and p not in service.optional]
    if missing:
        raise QueryError(f"{name}: missing parameter {', '.join(missing)}")
    values = {
        key: _CONVERT[service.params[key]](value) if isinstance(value, str) else value
        for key, value in params.items()
    }
    return service.run(session, client=client, **values)


def to_jsonable(value: Any, annotation: str = "") -> Any:
    """A service result as JSON-ready data: poses as position/orientation objects, vectors
    (fields annotated ``Vec3``) as x/y/z objects, other sequences as lists."""
    if isinstance(value, Pose):
        x, y, z = value.position
        qx, qy, qz, qw = value.orientation
        return {"position": {"x": x, "y": y, "z": z}, "orientation": {"x": qx, "y": qy, "z": qz, "w": qw}}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        data = {f.name: to_jsonable(getattr(value, f.name), str(f.type)) for f in dataclasses.fields(value)}
        if hasattr(value, "missing") and "missing" not in data:
            data["missing"] = value.missing
        return data
    if isinstance(value, tuple | list):
        if annotation.startswith("Vec3") and len(value) == 3:
            return {"x": value[0], "y": value[1], "z": value[2]}
        inner = annotation.removeprefix("tuple[").removeprefix("list[") if "[" in annotation else ""
        return [to_jsonable(v, inner) for v in value]
    return value


import_module("cadkg.usecases.elvez.services")
import_module("cadkg.usecases.vw.services")
import_module("cadkg.usecases.elimco.services")
import_module("cadkg.usecases.enki.services")
