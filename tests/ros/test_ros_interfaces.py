"""The .msg/.srv files of ros2/: well formed, and in step with the services and convert.py."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from cadkg.ros_adapter import convert
from cadkg.services.table import SERVICES, services_for
from tests.conftest import ROOT

PACKAGES = ROOT / "ros2"
INTERFACES = PACKAGES / "cadkg_interfaces"
PRIMITIVES = {
    "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
    "int32", "uint32", "int64", "uint64", "string", "wstring",
}  # fmt: skip
KNOWN = {
    "geometry_msgs/Pose",
    "geometry_msgs/Point",
    "geometry_msgs/Vector3",
    "geometry_msgs/TransformStamped",
}
FIELD = re.compile(r"^(?P<type>[A-Za-z][\w/]*)(?P<array>\[\d*\])?\s+(?P<name>[a-z][a-z0-9_]*)(?:\s+\S.*)?$")
OWN_MESSAGES = {p.stem for p in (INTERFACES / "msg").glob("*.msg")}


def fields(text: str, package: str = "cadkg_interfaces") -> dict[str, str]:
    """Field name -> type of one message section; fails on a malformed line or a duplicate."""
    found: dict[str, str] = {}
    for raw in text.splitlines():
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        match = FIELD.match(line)
        assert match, f"not a field: {raw!r}"
        kind, name = match["type"], match["name"]
        if "/" not in kind and kind not in PRIMITIVES:
            kind = f"{package}/{kind}"
        base = kind.replace("/msg/", "/")
        assert base in PRIMITIVES or base in KNOWN or base.split("/")[-1] in OWN_MESSAGES, base
        assert name not in found, f"duplicate field {name}"
        found[name] = kind + (match["array"] or "")
    return found


def service(name: str) -> tuple[dict[str, str], dict[str, str]]:
    text = (INTERFACES / "srv" / f"{name}.srv").read_text()
    parts = text.split("\n---\n") if not text.startswith("---") else ["", text.removeprefix("---\n")]
    assert len(parts) == 2, f"{name}.srv: one '---' separates request and response"
    return fields(parts[0]), fields(parts[1])


def all_interface_files() -> list[Path]:
    return sorted(PACKAGES.glob("*/msg/*.msg")) + sorted(PACKAGES.glob("*/srv/*.srv"))


@pytest.mark.parametrize("path", all_interface_files(), ids=lambda p: p.name)
def test_interface_files_parse(path: Path) -> None:
    text = path.read_text()
    if path.suffix == ".srv":
        _, response = service(path.stem)
        assert {"success", "message"} <= set(response), "every response has success and message"
    else:
        assert fields(text, path.parent.parent.name)


def test_every_interface_is_built() -> None:
    cmake = (INTERFACES / "CMakeLists.txt").read_text()
    listed = set(re.findall(r'"((?:msg|srv)/\w+\.(?:msg|srv))"', cmake))
    on_disk = {f"{p.parent.name}/{p.name}" for p in all_interface_files() if p.parent.parent == INTERFACES}
    assert listed == on_disk


@pytest.mark.parametrize("name", sorted(SERVICES))
def test_srv_matches_service_and_converter(name: str) -> None:
    """Request: the service's parameters (+ client for cursors); response: convert's fields."""
    request, _ = service(convert.ros_type_of(SERVICES[name]))
    # has_NAME says whether the optional parameter NAME is given (convert.request_params).
    given = {f"has_{p}" for p in SERVICES[name].optional}
    assert set(request) - {"client"} - given == set(SERVICES[name].params)
    for param, kind in SERVICES[name].params.items():
        expected = {
            "str": "string",
            "bool": "bool",
            "float": "float64",
            "int": "int32",
            "Pose": "geometry_msgs/Pose",
            "Paths": "string[]",
        }
        assert request[param] == expected[kind.__name__], param


def test_response_fields_are_the_converter_fields() -> None:
    """Each .srv response is success, message and the fields convert.FIELDS maps for its result."""
    results = {
        "CadService": "CadServiceResult",
        "FullCadService": "FullCadServiceResult",
        "GetItemScrewService": "ItemScrewResult",
        "GetTerminalData": "TerminalDataResult",
        "ClusterService": "ClusterResult",
        "CadReference": "CadReferenceResult",
        "FullConnectionProvider": "ConnectionEnd",
        "GroupConnectionProvider": "GroupConnection",
        "ResetConnectionList": "ResetResult",
        "ResetRailScanner": "ResetResult",
        "ResetToConnectionList": "ResetToResult",
        "RailScanner": "RailScan",
        "GetItemScrewTargets": "ItemScrewResult",
        "GearboxDisplay": "DisplayResult",
    }
    # The other profiles' results are converted by field name (tests/ros/test_ros_typed.py).
    assert set(results) == {convert.ros_type_of(s) for s in services_for("iema")}
    for srv, result in results.items():
        _, response = service(srv)
        assert set(response) == set(convert.FIELDS[result]) | {"success", "message"}, srv


def test_generic_services() -> None:
    assert service("Sparql") == (
        {"query": "string", "bindings_json": "string", "format": "string"},
        {"success": "bool", "message": "string", "result": "string"},
    )
    assert service("Reload") == ({}, {"success": "bool", "message": "string"})


def test_messages_mirror_the_dataclasses() -> None:
    from cadkg.usecases.iema.answers import CadConnection, PinData
    from cadkg.usecases.iema.derive.cabinet import CadPin, Cluster

    msg = INTERFACES / "msg"
    for cls, extra in ((CadPin, {"has_screw", "has_hole", "missing"}), (CadConnection, set())):
        names = set(fields((msg / f"{cls.__name__}.msg").read_text()))
        assert names == {f for f in cls.__dataclass_fields__ if f != "iri"} | extra, cls.__name__
    for cls in (PinData, Cluster):
        assert set(fields((msg / f"{cls.__name__}.msg").read_text())) == set(cls.__dataclass_fields__)


def test_tf2_msgs_is_upstream_tfmessage() -> None:
    text = (PACKAGES / "tf2_msgs" / "msg" / "TFMessage.msg").read_text()
    assert fields(text, "tf2_msgs") == {"transforms": "geometry_msgs/TransformStamped[]"}
