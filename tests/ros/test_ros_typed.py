"""The ELVEZ, ELIMCO, Volkswagen and ENKI results as .srv responses, field by field; no ROS needed.

Their results carry the response's fields by name; :func:`convert.typed_response` converts
them by the field types of the .srv and .msg files, which these tests read from the files.
"""

from __future__ import annotations

import math
from typing import Any

import pytest

import cadkg
from cadkg.plan.cell import store_plan
from cadkg.ros_adapter import convert
from cadkg.services.session import Session
from cadkg.services.table import SERVICES, call, services_for
from tests.conftest import ROOT
from tests.ros.test_ros_interfaces import INTERFACES, fields, service

# Parameters of one successful and one failing call of each service.
CALLS: dict[str, tuple[str, list[dict[str, str]]]] = {
    "guide_info": ("elvez-cell", [{"name": "J1"}, {"name": "J2.1", "frame": "platform_rf"}, {"name": "J99"}]),
    "cable_info": ("elvez-cell", [{"name": "CA5"}, {"name": "WH1"}]),
    "con_info": ("elvez-cell", [{"name": "WH1"}, {"name": "GR12"}, {"name": "CA1"}]),
    "wh_info": ("elvez-cell", [{"number": "1"}, {"number": "9"}]),
    "all_tools": ("elvez-cell", [{}]),
    "tool_info": ("elvez-cell", [{"name": "gripper"}, {"name": "nothing"}]),
    "all_op": ("elvez-cell", [{}]),
    "index_op": ("elvez-cell", [{"index": "1"}, {"index": "99"}]),
    "wh_routes": ("elvez-cell", [{"number": "1"}, {"number": "0"}]),
    "CAD_platform.connector_info": ("elvez-cell", [{"label": "WH1"}, {"label": "K1"}, {"label": "CA1"}]),
    "CAD_platform.cable_info": ("elvez-cell", [{"label": "CA5"}, {"label": "WH1"}]),
    "CAD_platform.tray_info": ("elvez-cell", [{"box": "B1", "tray": "2"}, {"box": "B3", "tray": "1"}]),
    "CAD_platform.jig_info": ("elvez-cell", [{"jig": "J3"}, {"jig": "C1"}, {"jig": "B1"}]),
    "CAD_platform.guide_info": ("elvez-cell", [{"jig": "J1", "guide": "1"}, {"jig": "J1", "guide": "2"}]),
    "CAD_platform.taping_spot_info": ("elvez-cell", [{"jig": "J3", "spot": "1"}, {"jig": "J1", "spot": "1"}]),
    "CAD_platform.all_guides": ("elvez-cell", [{}]),
    "CAD_platform.next_operation": ("elvez-cell", [{}]),
    "CAD_platform.reset_sequence_list": ("elvez-cell", [{}]),
    "CAD_platform.reset_sequence_list_to": ("elvez-cell", [{"index": "2"}, {"index": "9"}]),
    "CAD_platform.index_operation": ("elvez-cell", [{"index": "8"}, {"index": "9"}]),
    "CAD_platform.all_operations": ("elvez-cell", [{}]),
    "CAD_platform.all_cad_components": ("elvez-cell", [{}]),
    "CAD_platform.tool_info": ("elvez-cell", [{"name": "gripper"}, {"name": "gun"}, {"name": "glue"}]),
    "CAD_platform.get_tools_service": ("elvez-cell", [{}]),
    "harness_topology": ("vw-harness", [{"harness": "DOOR-L"}, {"harness": "DOOR-L", "view": "wires"}, {}]),
    "get_pin_positions": ("elimco-bench", [{"use_centroid": "true"}, {"use_centroid": "false"}]),
    "pin_frames": ("elimco-bench", [{}]),
    "get_cable_list": ("elimco-bench", [{}]),
    "get_path_positions": ("elimco-bench", [{"cable": "A4351-2401"}, {"cable": "nope"}]),
    "load_files": ("elimco-bench", [{"paths": "does-not-exist.xml"}]),
    "hose_info": ("enki-hose", [{"product": "HX-25"}, {"product": "HX-99"}]),
    # The operations every cell offers (the IEMA session holds a plan made in memory).
    "label_frames": ("iema-switchgear", [{"label": "F1500.1"}, {}, {"label": "NO-SUCH"}]),
    "plan": ("iema-switchgear", [{}]),
    "assign": ("iema-switchgear", [{"kind": "wire", "id": "1500.51", "performer": "human"}]),
    "progress": ("iema-switchgear", [{"task": "1500.52", "state": "failed", "reason": "would not seat"}]),
    "replan": ("iema-switchgear", [{"task": "1500.53", "performer": "human"}]),
    "reload": ("iema-switchgear", [{}]),
}
KINDS = {"bool": bool, "str": str, "int": int, "float": float}


def msg_fields(kind: str) -> dict[str, str]:
    package, _, name = kind.replace("/msg/", "/").partition("/")
    return fields((INTERFACES.parent / package / "msg" / f"{name}.msg").read_text(), package)


@pytest.fixture(scope="module")
def sessions() -> dict[str, Session]:
    built: dict[str, Session] = {}
    for example in {example for example, _ in CALLS.values()}:
        kg = cadkg.build(ROOT / "examples" / example / "manifest.toml")
        built[example] = Session(kg.cell_model(), kg=kg)
    store_plan(built["iema-switchgear"].kg, None, 0.0)
    # A reload's answer as a served cell gives it (the live ROS tests reload a real store).
    built["iema-switchgear"].reopen = lambda: ("gen-1", "gen-2")
    return built


def test_every_other_profile_service_is_called_here() -> None:
    others = {s.name for s in SERVICES.values() if s.profile != "iema"}
    assert {"assign", "progress", "plan", "replan", "label_frames", "reload"} <= others
    assert set(CALLS) == others
    assert not set(CALLS) & {s.name for s in services_for("iema")}


def check(data: Any, kind: str) -> None:
    """``data`` has the shape of ROS type ``kind`` (a .msg field type)."""
    if kind.endswith("[]"):
        assert isinstance(data, list), kind
        for item in data:
            check(item, kind[:-2])
        return
    simple = {"bool": "bool", "string": "str", "float64": "float", "int32": "int"}.get(kind)
    if simple is not None:
        assert type(data) is KINDS[simple], (kind, data)
        return
    if kind in ("geometry_msgs/Pose",):
        orientation = data["orientation"]
        norm = math.sqrt(sum(orientation[k] ** 2 for k in "xyzw"))
        assert math.isclose(norm, 1.0, abs_tol=1e-9), data
        return
    own = msg_fields(kind)
    assert set(data) == set(own), kind
    for name, sub in own.items():
        check(data[name], sub)


@pytest.mark.parametrize("name", sorted(CALLS))
def test_results_convert_to_their_response(sessions: dict[str, Session], name: str) -> None:
    example, calls = CALLS[name]
    _, response_fields = service(convert.ros_type_of(SERVICES[name]))
    outcomes = []
    for params in calls:
        result = call(sessions[example], name, params)
        data = convert.typed_response(result, response_fields, msg_fields)
        assert set(data) == set(response_fields), name
        for field, kind in response_fields.items():
            check(data[field], kind)
        assert data["message"], name
        outcomes.append(data["success"])
    # The first call of each service succeeds; the failing ones say so (load_files: a missing file).
    if name != "load_files":
        assert outcomes[0] is True, name
    if len(calls) > 1 and name != "get_pin_positions":
        assert outcomes[-1] is False, name


def test_the_plan_steps_carry_their_times(sessions: dict[str, Session]) -> None:
    _, response_fields = service("Plan")
    result = call(sessions["iema-switchgear"], "plan", {})
    data = convert.typed_response(result, response_fields, msg_fields)
    times = [(s["start_s"], s["end_s"]) for s in data["steps"]]
    assert times == [(s["start_s"], s["end_s"]) for s in result.steps] and times[0] == (0.0, 240.0)
    assert "makespan" in data["message"] and max(end for _, end in times) == result.summary["makespan_s"]


def test_a_missing_result_field_is_an_error_not_a_default() -> None:
    from cadkg.usecases.enki.services import HoseInfoResult

    _, response_fields = service("HoseInfo")
    with pytest.raises(TypeError, match="no field 'product'"):
        convert.typed_response({"success": True}, response_fields, msg_fields)
    data = convert.typed_response(
        HoseInfoResult(True, "", "HX", 0.008, None, "", None), response_fields, msg_fields
    )
    assert data["diameter"] == 0.008 and math.isnan(data["length"]) and data["material"] == ""
