"""convert.py maps every field of every service result, checked field by field on the mini cell."""

from __future__ import annotations

import dataclasses
import enum
import math
from collections.abc import Iterator
from types import SimpleNamespace
from typing import Any, ClassVar

import pytest

from cadkg.errors import QueryError
from cadkg.geometry.poses import Pose
from cadkg.graph import KnowledgeGraph
from cadkg.ros_adapter import convert
from cadkg.services.session import Session
from cadkg.services.table import SERVICES, call, services_for
from cadkg.usecases.iema import answers as iema
from cadkg.usecases.iema import cursors
from tests.conftest import ROOT

MINI = ROOT / "tests" / "data" / "cells" / "mini" / "manifest.toml"
RESULTS = [
    getattr(module, name)
    for module in (iema, cursors)
    for name in module.__all__
    if name.endswith(("Result", "Scan", "Connection", "End")) and name != "CadConnection"
]


@pytest.fixture(scope="module")
def kg() -> Iterator[KnowledgeGraph]:
    graph = KnowledgeGraph.build(MINI)
    yield graph
    graph.close()


def test_every_result_class_is_mapped_field_by_field() -> None:
    assert len(RESULTS) == 12
    for cls in RESULTS:
        assert dataclasses.is_dataclass(cls)
        names = [f.name for f in dataclasses.fields(cls)]
        assert set(convert.FIELDS[cls.__name__]) == set(names), cls.__name__
    assert set(convert.FIELDS) == {cls.__name__ for cls in RESULTS}


def same(value: Any, data: Any) -> bool:
    """Whether response data carries ``value``: checked independently of convert's code."""
    if value is None:
        return data in ("", convert.IDENTITY, {"x": 0.0, "y": 0.0, "z": 0.0}) or (
            isinstance(data, dict) and data.get("missing") is True and data.get("pin") == ""
        )
    if isinstance(value, Pose):
        position = (data["position"]["x"], data["position"]["y"], data["position"]["z"])
        orientation = tuple(data["orientation"][k] for k in "xyzw")
        return position == value.position and orientation == value.orientation
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return all(
            same(getattr(value, f.name), data[f.name]) for f in dataclasses.fields(value) if f.name != "iri"
        )
    if isinstance(value, tuple) and len(value) == 3 and all(isinstance(v, float) for v in value):
        return isinstance(data, dict) and (data["x"], data["y"], data["z"]) == value
    if isinstance(value, enum.Enum):  # a performer: a plain string in the message
        value = value.value
    if isinstance(value, tuple | list):
        return len(value) == len(data) and all(same(v, d) for v, d in zip(value, data, strict=True))
    return bool(value == data and type(data) is type(value))


ARGS = {
    "label": "K1",
    "detected_pose": "0.16,0.52,0.0075,0,0,1,0",
    "cad_pose": "0.16,0.52,0.2175,1,0,0,0",
    "occupancy": "false",
    "data": "1",
}


@pytest.mark.parametrize("name", sorted(s.name for s in services_for("iema")))
@pytest.mark.parametrize("label", ["K1", "X1", "K2", "NOPE"])
def test_results_of_the_mini_cell_convert_field_by_field(kg: KnowledgeGraph, name: str, label: str) -> None:
    session = Session(kg.cell_model())
    params = {k: ({**ARGS, "label": label})[k] for k in SERVICES[name].params if k in ARGS}
    for _ in range(5):  # cursors: walk past the end too
        result = call(session, name, params)
        data = convert.response(result)
        assert isinstance(data["success"], bool) and isinstance(data["message"], str) and data["message"]
        for field in dataclasses.fields(result):
            assert same(getattr(result, field.name), data[field.name]), (name, field.name)


def test_cad_pin_flags_and_values(kg: KnowledgeGraph) -> None:
    result = iema.cad_service(kg.cell_model(), "K1")
    pins = {p["pin"]: p for p in convert.response(result)["pins"]}
    a1 = pins["A1"]
    assert a1["has_screw"] and a1["has_hole"] and not a1["missing"] and a1["item"] == "ID000002"
    assert [a1["screw"]["position"][k] for k in "xyz"] == pytest.approx([0.155, 0.57, 0.0675])
    missing = convert.cad_pin(SimpleNamespace(label="K9", pin="1", screw=None, hole=None, item=None))
    assert missing["missing"] and missing["screw"] == convert.IDENTITY and missing["item"] == ""


def test_none_pose_is_identity_and_said_so() -> None:
    result = iema.CadReferenceResult(True, "ok", None, Pose((1.0, 2.0, 3.0)))
    data = convert.response(result)
    assert data["target_pose"] == convert.IDENTITY
    assert "target_pose" in data["message"] and "identity" in data["message"]
    assert data["corner_pose"]["position"] == {"x": 1.0, "y": 2.0, "z": 3.0}
    failed = convert.response(iema.CadReferenceResult(False, "unknown label 'X'"))
    assert failed["message"] == "unknown label 'X'" and not failed["success"]
    end = convert.response(cursors.ConnectionEnd(end=True))
    assert end["success"] and end["end"] and end["message"] == "end of the list"


def test_unmapped_result_type_is_an_error() -> None:
    with pytest.raises(TypeError, match="no response mapping"):
        convert.response(SimpleNamespace(success=True))


def _pose_msg(*values: float) -> SimpleNamespace:
    x, y, z, qx, qy, qz, qw = values
    return SimpleNamespace(
        position=SimpleNamespace(x=x, y=y, z=z), orientation=SimpleNamespace(x=qx, y=qy, z=qz, w=qw)
    )


def test_request_params() -> None:
    request = SimpleNamespace(label="K1", detected_pose=_pose_msg(1, 2, 3, 0, 0, 0, 2 / 2), client="")
    params = convert.request_params(SERVICES["get_item_screw_service"].params, request)
    assert params == {"label": "K1", "detected_pose": Pose((1.0, 2.0, 3.0))}
    assert convert.client_of(request) == "default"
    assert convert.client_of(SimpleNamespace(client="robot2")) == "robot2"
    assert convert.request_params({"data": float, "source": str}, SimpleNamespace(data=2, source="a")) == {
        "data": 2.0,
        "source": "a",
    }
    with pytest.raises(QueryError, match="quaternion"):
        convert.pose_from_msg(_pose_msg(0, 0, 0, 0, 0, 0, 0))
    with pytest.raises(QueryError, match="finite"):
        convert.pose_from_msg(_pose_msg(math.nan, 0, 0, 0, 0, 0, 1))


class FakeMessage:
    """Stands in for a generated ROS message class: slots with types."""

    TYPES: ClassVar[dict[str, str]] = {}

    def get_fields_and_field_types(self) -> dict[str, str]:
        return self.TYPES


def fake(name: str, types: dict[str, str]) -> type[FakeMessage]:
    return type(name, (FakeMessage,), {"TYPES": types})


def test_fill_builds_nested_messages() -> None:
    point = fake("Point", {"x": "double", "y": "double", "z": "double"})
    quaternion = fake("Quaternion", {"x": "double", "y": "double", "z": "double", "w": "double"})
    pose = fake("Pose", {"position": "geometry_msgs/Point", "orientation": "geometry_msgs/Quaternion"})
    cluster = fake(
        "Cluster", {"axis": "string", "pins": "sequence<string>", "points": "sequence<geometry_msgs/Point>"}
    )
    classes = {
        "geometry_msgs/Point": point,
        "geometry_msgs/Quaternion": quaternion,
        "geometry_msgs/Pose": pose,
        "cadkg_interfaces/Cluster": cluster,
    }
    response = fake(
        "Response",
        {
            "success": "boolean",
            "message": "string",
            "screws": "sequence<geometry_msgs/Pose>",
            "start": "geometry_msgs/Pose",
            "horizontal": "sequence<cadkg_interfaces/Cluster, 4>",
        },
    )()
    data = {
        "success": True,
        "message": "ok",
        "screws": [convert.pose(Pose((1.0, 2.0, 3.0)))],
        "start": convert.pose(None),
        "horizontal": [{"axis": "horizontal", "pins": ["A1"], "points": [convert.point((1.0, 0.0, 0.0))]}],
    }
    filled: Any = convert.fill(response, data, classes.__getitem__)
    assert filled.success and filled.message == "ok"
    assert type(filled.screws[0]).__name__ == "Pose" and filled.screws[0].position.z == 3.0
    assert filled.start.orientation.w == 1.0
    assert filled.horizontal[0].points[0].x == 1.0 and filled.horizontal[0].pins == ["A1"]
    with pytest.raises(KeyError):
        convert.fill(response, {"nope": 1}, classes.__getitem__)


def test_srv_type_names() -> None:
    assert convert.srv_type_name("get_item_screw_service") == "GetItemScrewService"
    assert convert.srv_type_name("sparql") == "Sparql"
