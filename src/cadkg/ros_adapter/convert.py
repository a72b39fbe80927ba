"""Service results as response fields, and request fields as service parameters; no ROS needed.

:func:`response` turns any result of :data:`cadkg.services.table.SERVICES` into plain data
(dicts for messages, lists for arrays) keyed like the fields of the ``.srv`` response in
``ros2/cadkg_interfaces``; :func:`fill` writes that data into a ROS message. Both work on
any object with the right attributes, so they are tested without rclpy.

Conventions: a ``None`` pose becomes the identity pose and, on a successful result, the
message says which field had no pose; a ``None`` text becomes ``""``; results without a
``success`` field (the cursor services) answer ``success=True``.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Mapping
from typing import Any

from cadkg.errors import QueryError
from cadkg.geometry.frames import normalize_quaternion
from cadkg.geometry.poses import Pose
from cadkg.services.service import Paths

__all__ = [
    "FIELDS",
    "IDENTITY",
    "cad_pin",
    "client_of",
    "fill",
    "point",
    "pose",
    "pose_from_msg",
    "request_params",
    "response",
    "ros_service_name",
    "ros_type_of",
    "srv_type_name",
    "typed_response",
    "vector",
]

Data = dict[str, Any]
Converter = Callable[[Any], Any]

IDENTITY: Data = {
    "position": {"x": 0.0, "y": 0.0, "z": 0.0},
    "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
}


def pose(value: Pose | None) -> Data:
    """A cadkg pose as ``geometry_msgs/Pose`` data; ``None`` as the identity."""
    if value is None:
        return {key: dict(part) for key, part in IDENTITY.items()}
    x, y, z = value.position
    qx, qy, qz, qw = value.orientation
    return {
        "position": {"x": float(x), "y": float(y), "z": float(z)},
        "orientation": {"x": float(qx), "y": float(qy), "z": float(qz), "w": float(qw)},
    }


def vector(value: Iterable[float] | None) -> Data:
    """Three numbers as ``geometry_msgs/Vector3`` (or ``Point``) data; ``None`` as zeros."""
    x, y, z = value if value is not None else (0.0, 0.0, 0.0)
    return {"x": float(x), "y": float(y), "z": float(z)}


point = vector


def _text(value: str | None) -> str:
    return "" if value is None else str(value)


def _poses(values: Iterable[Pose]) -> list[Data]:
    return [pose(v) for v in values]


def _texts(values: Iterable[str]) -> list[str]:
    return [str(v) for v in values]


def cad_pin(value: Any) -> Data:
    """A cabinet pin (:class:`~cadkg.usecases.iema.derive.cabinet.CadPin`) as ``cadkg_interfaces/CadPin``;
    ``None`` as an empty pin."""
    if value is None:
        return {
            "label": "",
            "pin": "",
            "screw": pose(None),
            "hole": pose(None),
            "item": "",
            "has_screw": False,
            "has_hole": False,
            "missing": True,
            "component_pose": pose(None),
        }
    return {
        "label": str(value.label),
        "pin": str(value.pin),
        "screw": pose(value.screw),
        "hole": pose(value.hole),
        "item": _text(value.item),
        "has_screw": value.screw is not None,
        "has_hole": value.hole is not None,
        "missing": value.screw is None and value.hole is None,
        "component_pose": pose(getattr(value, "component_pose", None)),
    }


def _fields(converters: dict[str, Converter]) -> Converter:
    """A message's data from the attributes of the same names, each through its converter."""
    return lambda value: {name: convert(getattr(value, name)) for name, convert in converters.items()}


_connection = _fields(
    {
        "wire": str,
        "list_position": int,
        "source": str,
        "origin": str,
        "destination": str,
        "performer": str,
        "missing_pin_data": bool,
        "reason": str,
        "pin": str,
        "target_item": str,
        "target_pin": str,
        "screw_pose": pose,
        "hole_pose": pose,
        "connection_list": str,
    }
)
_pin_data = _fields({"pin": str, "wire": _text, "termination": _text, "exact": bool})


def _cluster(value: Any) -> Data:
    return {"axis": str(value.axis), "pins": _texts(value.pins), "points": [point(p) for p in value.points]}


def _each(convert: Converter) -> Converter:
    return lambda values: [convert(v) for v in values]


_COMPONENT: dict[str, Converter] = {
    "success": bool,
    "message": str,
    "target_pose": pose,
    "corner_pose": pose,
    "original_pose": pose,
    "dimensions": vector,
}

# Result dataclass name -> {field -> converter}; the keys are the response fields of the .srv.
FIELDS: dict[str, dict[str, Converter]] = {
    "CadServiceResult": {**_COMPONENT, "pins": _each(cad_pin)},
    "FullCadServiceResult": {**_COMPONENT, "connections": _each(_connection)},
    "ItemScrewResult": {
        "success": bool,
        "message": str,
        "pins": _texts,
        "screws": _poses,
        "holes": _poses,
        "screw_data": _each(_pin_data),
        "hole_data": _each(_pin_data),
    },
    "TerminalDataResult": {
        "success": bool,
        "message": str,
        "pins": _texts,
        "terminal_start": pose,
        "screws": _poses,
        "holes": _poses,
        "length": float,
        "height": float,
    },
    "ClusterResult": {
        "success": bool,
        "message": str,
        "horizontal": _each(_cluster),
        "vertical": _each(_cluster),
    },
    "CadReferenceResult": {"success": bool, "message": str, "target_pose": pose, "corner_pose": pose},
    "ConnectionEnd": {
        "end": bool,
        "missing_pin_data": bool,
        "list_position": int,
        "source": str,
        "label": str,
        "pin": str,
        "direction": bool,
        "component_pose": pose,
        "wire": str,
        "connection_list": str,
    },
    "GroupConnection": {
        "end": bool,
        "missing_pin_data": str,
        "list_position": int,
        "origin": cad_pin,
        "destination": cad_pin,
        "wire": str,
        "wire_path": str,
        "path_keypoints": _poses,
    },
    "RailScan": {
        "end": bool,
        "rail": str,
        "rail_start": pose,
        "component_poses": _poses,
        "components_dimensions": _each(vector),
        "components_label": _texts,
    },
    "ResetResult": {"success": bool},
    "ResetToResult": {"success": bool, "output": str},
    "DisplayResult": {"success": bool, "message": str, "display": bool},
}

# Single fields that are a pose or a vector: None there is worth a word in the message.
_OPTIONAL_GEOMETRY = {pose, vector}


FieldTypes = Mapping[str, str]

_SCALARS: dict[str, Converter] = {
    "bool": lambda v: bool(v) if v is not None else False,
    "str": _text,
    "int": lambda v: int(v) if v is not None else 0,
    "float": lambda v: float(v) if v is not None else math.nan,
    "geometry_msgs/Pose": pose,
    "geometry_msgs/Vector3": vector,
    "geometry_msgs/Point": vector,
}
# Field types as ``get_fields_and_field_types()`` and as .msg files spell them.
_CANONICAL = {
    "bool": "bool", "boolean": "bool",
    "string": "str", "wstring": "str",
    "float64": "float", "double": "float", "float32": "float", "float": "float",
    "int8": "int", "int16": "int", "int32": "int", "int64": "int",
    "uint8": "int", "uint16": "int", "uint32": "int", "uint64": "int", "octet": "int",
}  # fmt: skip
_ARRAY = re.compile(r"^(?:sequence<(?P<seq>[^,>]+)(?:,\s*\d+)?>|(?P<arr>[\w/]+)\[\d*\])$")


def _typed(value: Any, kind: str, fields_of: Callable[[str], FieldTypes], where: str) -> Any:
    array = _ARRAY.match(kind)
    if array is not None:
        element = array["seq"] or array["arr"]
        return [_typed(v, element, fields_of, where) for v in (value or ())]
    kind = kind.replace("/msg/", "/")
    scalar = _SCALARS.get(_CANONICAL.get(kind, kind))
    if scalar is not None:
        return scalar(value)
    if value is None:
        raise TypeError(f"{where}: no value for a {kind} message")
    return {
        name: _typed(_attribute(value, name, where), sub, fields_of, f"{where}.{name}")
        for name, sub in fields_of(kind).items()
    }


def _attribute(value: Any, name: str, where: str) -> Any:
    if isinstance(value, Mapping):
        if name not in value:
            raise TypeError(f"{where}: no field {name!r}")
        return value[name]
    if not hasattr(value, name):
        raise TypeError(f"{where}: {type(value).__name__} has no field {name!r}")
    return getattr(value, name)


def typed_response(result: Any, fields: FieldTypes, fields_of: Callable[[str], FieldTypes]) -> Data:
    """The response of a service result whose fields mirror the ``.srv`` response by name.

    ``fields`` are the response's field types, ``fields_of("cadkg_interfaces/X")`` those of a
    message; both as ``get_fields_and_field_types()`` gives them (or as .msg files spell them).
    Missing numbers become NaN, missing texts "", missing poses the identity.

    Raises
    ------
    TypeError
        When the result lacks a field of the response.
    """
    name = type(result).__name__
    optional = {"success": True, "message": ""}
    data = {
        field: _typed(
            getattr(result, field, optional[field]) if field in optional else _attribute(result, field, name),
            kind,
            fields_of,
            f"{name}.{field}",
        )
        for field, kind in fields.items()
    }
    if not data.get("message"):
        data["message"] = "ok" if data.get("success", True) else "failed"
    return data


def response(result: Any) -> Data:
    """The response fields (``success``, ``message`` and the result's own) of a cabinet (IEMA)
    service result; the other profiles' results go through :func:`typed_response`.

    Raises
    ------
    TypeError
        When the result's type has no mapping in :data:`FIELDS`.
    """
    name = type(result).__name__
    mapping = FIELDS.get(name)
    if mapping is None:
        raise TypeError(f"no response mapping for {name}")
    data: Data = {}
    absent: list[str] = []
    for field, convert in mapping.items():
        value = getattr(result, field)
        if value is None and convert in _OPTIONAL_GEOMETRY:
            absent.append(field)
        data[field] = convert(value)
    success = bool(data.get("success", True))
    data["success"] = success
    notes = [str(data.get("message", ""))] if data.get("message") else []
    if data.get("end"):
        notes.append("end of the list")
    elif success and absent:
        notes.append(f"no {', '.join(absent)} in the CAD: identity sent")
    data["message"] = "; ".join(notes) if notes else ("ok" if success else "failed")
    return data


def pose_from_msg(msg: Any) -> Pose:
    """A ``geometry_msgs/Pose`` (any object with position.x ... orientation.w) as a cadkg pose.

    Raises
    ------
    QueryError
        When a number is not finite or the quaternion is zero.
    """
    p, q = msg.position, msg.orientation
    values = [float(v) for v in (p.x, p.y, p.z, q.x, q.y, q.z, q.w)]
    if not all(math.isfinite(v) for v in values):
        raise QueryError("detected_pose: not finite")
    try:
        return Pose((values[0], values[1], values[2]), normalize_quaternion(values[3:]))
    except ValueError as err:
        raise QueryError(f"detected_pose: {err}") from None


def request_params(params: Mapping[str, type], request: Any) -> dict[str, Any]:
    """The parameters of a service (``Service.params``) read from a request's fields.

    A field ``has_NAME`` that is false leaves the parameter ``NAME`` out: a ROS field always has
    a value, so an optional parameter whose absence means something says so beside it.
    """
    values: dict[str, Any] = {}
    for name, kind in params.items():
        if getattr(request, f"has_{name}", True) is False:
            continue
        value = getattr(request, name)
        if kind is Pose:
            values[name] = pose_from_msg(value)
        elif kind is bool:
            values[name] = bool(value)
        elif kind is float:
            values[name] = float(value)
        elif kind is int:
            values[name] = int(value)
        elif kind is Paths:  # a list over ROS: never joined into one string and split again
            values[name] = Paths(str(item) for item in value)
        else:
            values[name] = str(value)
    return values


def client_of(request: Any, default: str = "default") -> str:
    """The cursor owner a request names in its ``client`` field; ``default`` when empty or absent."""
    client = getattr(request, "client", "")
    return str(client) if client else default


_SEQUENCE = re.compile(r"^sequence<([^,>]+)(?:,\s*\d+)?>$")


_KINDS: dict[type, dict[str, tuple[str, str | None]]] = {}


def _field_kinds(msg: Any) -> dict[str, tuple[str, str | None]]:
    # Per message class: each field's type and, for a sequence, its element type. A response
    # fills one message per pin and pose, so this is looked up thousands of times a second.
    kinds = _KINDS.get(type(msg))
    if kinds is None:
        kinds = {}
        for name, kind in msg.get_fields_and_field_types().items():
            match = _SEQUENCE.match(kind)
            kinds[name] = (kind, match.group(1) if match else None)
        _KINDS[type(msg)] = kinds
    return kinds


def fill(msg: Any, data: Mapping[str, Any], resolve: Callable[[str], Callable[[], Any]]) -> Any:
    """Write plain ``data`` into a ROS message; nested messages are built with ``resolve(type)``.

    ``resolve("geometry_msgs/Pose")`` returns the message class. The field types come from
    the message's ``get_fields_and_field_types()``; fields absent from ``data`` keep their default.

    Raises
    ------
    KeyError
        When ``data`` names a field the message does not have.
    """
    types = _field_kinds(msg)
    for name, value in data.items():
        kind, element = types[name]
        if element is not None and "/" in element:
            setattr(msg, name, [fill(resolve(element)(), v, resolve) for v in value])
        elif element is None and "/" in kind:
            setattr(msg, name, fill(resolve(kind)(), value, resolve))
        else:
            setattr(msg, name, value)
    return msg


def srv_type_name(name: str) -> str:
    """The ``cadkg_interfaces`` type of a service: ``get_item_screw_service`` → ``GetItemScrewService``."""
    return "".join(part.capitalize() for part in name.split("_"))


def ros_type_of(service: Any) -> str:
    """The ``cadkg_interfaces`` type of a :class:`~cadkg.services.service.Service`: its own, or
    its name's (:func:`srv_type_name`)."""
    return str(service.ros_type or srv_type_name(service.name))


def ros_service_name(service: Any, namespace: str) -> str:
    """Where a node in the root namespace serves a service: its own namespace or ``namespace``,
    then its ROS name (``/CAD_platform/guide_info``, ``/elvez/guide_info``)."""
    prefix = (service.ros_namespace or namespace).strip("/")
    return f"/{prefix}/{service.ros_name or service.name}"
