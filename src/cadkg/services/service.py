"""A service as every transport calls it: name, parameters with their types, and what runs.

Parameters arrive as text from the command line and over HTTP, and are converted here, so
every transport gets the same checks and messages; answers leave as JSON-ready data
(:func:`to_jsonable`) or, in the ROS adapter, as typed response fields.
"""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from cadkg.errors import QueryError
from cadkg.geometry.frames import normalize_quaternion, quaternion_from_rpy
from cadkg.geometry.poses import Pose

if TYPE_CHECKING:
    from cadkg.services.session import Session

__all__ = [
    "CONVERT",
    "DIGITS",
    "Effect",
    "Paths",
    "Service",
    "model_services",
    "on_model",
    "parse_pose",
    "to_jsonable",
]


class Effect(enum.Enum):
    """What calling a service changes: the one declaration every transport derives its checks from.

    HTTP takes a changing service only by POST with the token (a graph change also needs
    ``--allow-update``); the ROS node serves a graph change only when started with
    ``allow_assign``; ``cadkg call`` keeps cursors only for a cursor service. A reading service
    runs where it cannot reach a cursor (:meth:`cadkg.services.session.Session.reading`). A
    reload needs the token over HTTP, and runs outside the served graph's lock, so the services
    go on answering from the old graph while the new one opens.
    """

    READS = "reads"
    """Answers from the graph and the models derived from it; changes nothing."""
    CURSOR = "cursor"
    """Moves or rewinds the calling client's own cursor."""
    LOADS = "loads files"
    """Reads files named by the caller into the served graph."""
    WRITES = "writes"
    """Changes the served graph or the store."""
    RELOADS = "reloads"
    """Serves the store's current generation: what the store holds, not what the caller gives."""

    @property
    def changes(self) -> bool:
        """Whether a call changes anything at all."""
        return self is not Effect.READS

    @property
    def changes_graph(self) -> bool:
        """Whether a call changes the served graph (not only a caller's cursor)."""
        return self in (Effect.LOADS, Effect.WRITES)


@dataclass(frozen=True)
class Service:
    """``run(session, client=..., **params)``; ``optional`` parameters may be left out.

    ``effect`` has no default: a service that forgets to say what it changes is an error where
    it is declared, not a reading service by accident.
    """

    name: str
    description: str
    params: Mapping[str, type]
    run: Callable[..., Any]
    effect: Effect = field(kw_only=True)
    profile: str = ""
    optional: frozenset[str] = frozenset()
    # Over ROS: the service's own namespace (else the use case's), its name there (else
    # ``name``) and its .srv type (else ``name`` in PascalCase), for a service that mirrors
    # another node's (``/CAD_platform/guide_info`` beside ``/elvez/guide_info``).
    ros_namespace: str = ""
    ros_name: str = ""
    ros_type: str = ""
    # Whether a call changes which frames the cell publishes (transports that publish them,
    # such as /tf_static, publish again after it).
    changes_frames: bool = False


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


class Paths(tuple[str, ...]):
    """Files a caller names: comma separated as text (``a.xml,b.xml``), a list from then on, so
    a transport that checks them hands on the checked list and never joins it again."""


def _paths(text: str) -> Paths:
    return Paths(p.strip() for p in text.split(",") if p.strip())


CONVERT: dict[type, Callable[[str], Any]] = {
    Paths: _paths,
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
    ``make(name, description, params, answer, optional=(), **ros)`` (see :func:`on_model`;
    ``ros``: ``ros_namespace``, ``ros_name``, ``ros_type`` of :class:`Service`). They only
    read: ``answer`` is given the model and the parameters, never the session or a cursor."""

    def make(
        name: str,
        description: str,
        params: Mapping[str, type],
        answer: Callable[..., Any],
        optional: Iterable[str] = (),
        ros_namespace: str = "",
        ros_name: str = "",
        ros_type: str = "",
    ) -> Service:
        return Service(
            name,
            description,
            params,
            on_model(answer, model_of),
            effect=Effect.READS,
            profile=profile,
            optional=frozenset(optional),
            ros_namespace=ros_namespace,
            ros_name=ros_name,
            ros_type=ros_type,
        )

    return make


# Answers are in metres and radians: 1e-12 is far below what any file states or any robot
# reaches, and far above the noise of a few float operations, so rounding there keeps 0.206
# from printing as 0.20600000000000002 after a sum of poses.
DIGITS = 12


def _number(value: float) -> float:
    return round(value, DIGITS) if math.isfinite(value) else value


def to_jsonable(value: Any, annotation: str = "") -> Any:
    """A service result as JSON-ready data: poses as position/orientation objects, vectors
    (fields annotated ``Vec3``) as x/y/z objects, other sequences as lists, floats rounded to
    :data:`DIGITS` decimals (printed in their shortest form)."""
    if isinstance(value, float):
        return _number(value)
    if isinstance(value, Pose):
        x, y, z = (_number(v) for v in value.position)
        qx, qy, qz, qw = (_number(v) for v in value.orientation)
        return {"position": {"x": x, "y": y, "z": z}, "orientation": {"x": qx, "y": qy, "z": qz, "w": qw}}
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        data = {f.name: to_jsonable(getattr(value, f.name), str(f.type)) for f in dataclasses.fields(value)}
        if hasattr(value, "missing") and "missing" not in data:
            data["missing"] = value.missing
        return data
    if isinstance(value, tuple | list):
        if annotation.startswith("Vec3") and len(value) == 3:
            return {"x": _number(value[0]), "y": _number(value[1]), "z": _number(value[2])}
        inner = annotation.removeprefix("tuple[").removeprefix("list[") if "[" in annotation else ""
        return [to_jsonable(v, inner) for v in value]
    return value
