"""The services of D3.1 Table 2 and the route traversal on the example cell, and unknown names.

Expected values are read from the example's files or computed by hand in its README.
"""

from __future__ import annotations

import math

import pytest

from cadkg.geometry.frames import quaternion_from_rpy
from cadkg.geometry.poses import Pose
from cadkg.graph import KnowledgeGraph
from cadkg.services.session import Session
from cadkg.services.table import SERVICES, call, services_for
from cadkg.usecases.elvez.answers import BranchInfo, CableRoute, OperationInfo
from cadkg.usecases.elvez.model import ElvezModel, build_model
from tests.conftest import ROOT

ELVEZ = ROOT / "examples" / "elvez-cell" / "manifest.toml"
TABLE_2 = ("guide_info", "cable_info", "con_info", "wh_info", "all_tools", "tool_info", "all_op", "index_op")
REFERENCE = (
    "connector_info", "cable_info", "tray_info", "jig_info", "guide_info", "taping_spot_info", "all_guides",
    "next_operation", "reset_sequence_list", "reset_sequence_list_to", "index_operation", "all_operations",
    "all_cad_components", "tool_info", "get_tools_service",
)  # fmt: skip
S = math.sqrt(0.5)


@pytest.fixture(scope="module")
def kg(elvez: KnowledgeGraph) -> KnowledgeGraph:
    return elvez  # built once per session (tests/conftest.py)


@pytest.fixture(scope="module")
def session(kg: KnowledgeGraph) -> Session:
    return Session(kg.cell_model(), kg=kg)


@pytest.fixture(scope="module")
def model(kg: KnowledgeGraph) -> ElvezModel:
    return build_model(kg)


def yaw(degrees: float) -> tuple[float, float, float, float]:
    return quaternion_from_rpy(0.0, 0.0, math.radians(degrees))


def test_the_profile_registers_table_2_the_traversal_and_the_reference_node() -> None:
    names = [s.name for s in services_for("elvez")]
    assert names == [*TABLE_2, "wh_routes", *(f"CAD_platform.{n}" for n in REFERENCE)]
    assert SERVICES["guide_info"].optional == frozenset({"frame"})
    reference = SERVICES["CAD_platform.guide_info"]
    assert (reference.ros_namespace, reference.ros_name, reference.ros_type) == (
        "CAD_platform",
        "guide_info",
        "PlatformGuideInfo",
    )
    assert SERVICES["guide_info"].ros_namespace == ""


def test_the_model_is_built_once_per_session(session: Session) -> None:
    first = call(session, "all_tools", {})
    assert call(session, "all_tools", {}) == first
    assert session.profile_model("elvez", lambda kg: None) is session.profile_model("elvez", build_model)


def test_elements_are_scoped_by_platform(model: ElvezModel) -> None:
    assert model.reference == "robot_base"
    by_frame = {e.frame: e.label for e in model.elements}
    # ID0002 is J1 on the platform and C1 on the combs; T1 is a table of the platform and the ATC.
    assert (by_frame["ID0002platform"], by_frame["ID0002combs"]) == ("J1", "C1")
    assert by_frame["ID0001platform"] == by_frame["ID000001ATC"] == "T1"
    assert model.element("T1") is None  # tables are not looked up by label
    element = model.element("J3")
    assert element is not None and element.where == "platform_ids.wri:4"


# -- guides ---------------------------------------------------------------------------------------------


def test_guide_info_of_j1_in_the_robot_base(session: Session) -> None:
    result = call(session, "guide_info", {"name": "J1.1"})
    assert (result.success, result.id, result.frame) == (True, "ID0002", "robot_base")
    assert result.origin_frame.close_to(Pose((0.65, -0.30, 0.21), yaw(-90)), 1e-12)
    assert result.key_frame.close_to(Pose((0.662, -0.305, 0.345), yaw(-90)), 1e-12)
    assert result.key_corner_frame.close_to(Pose((0.658, -0.30, 0.33), yaw(-90)), 1e-12)
    assert result.dimensions == (0.01, 0.024, 0.15)
    assert (result.key_length, result.key_gap, result.key_height) == (0.01, 0.008, 0.03)
    assert call(session, "guide_info", {"name": "J1"}) == result  # J1 has one guide


def test_guide_info_in_another_frame(session: Session) -> None:
    local = call(session, "guide_info", {"name": "J2", "frame": "ID0003platform"})
    assert local.origin_frame.close_to(Pose(), 1e-12)
    assert local.key_frame.close_to(Pose((0.005, 0.012, 0.135)), 1e-12)
    turned = call(session, "guide_info", {"name": "J2"})
    assert turned.key_frame.close_to(Pose((0.655, -0.388, 0.345)), 1e-6)  # 1.570796 for 90°


@pytest.mark.parametrize(
    ("params", "message"),
    [
        (
            {"name": "J99"},
            "no guide 'J99' on the platforms; guides: C1.1, C2.1, J1.1, J2.1, J3.1, J3.2, J4.1",
        ),
        ({"name": "J3"}, "J3 has no guide '(none given)'; guides: 1, 2"),
        ({"name": "J1.7"}, "J1 has no guide '7'; guides: 1"),
        ({"name": "B1"}, "no guide 'B1'"),
        ({"name": "J1", "frame": "nowhere"}, "J1: no frame 'nowhere'"),
    ],
)
def test_guide_info_failures(session: Session, params: dict[str, str], message: str) -> None:
    result = call(session, "guide_info", params)
    assert result.success is False
    assert message in result.message
    assert result.key_frame is None


# -- harnesses ------------------------------------------------------------------------------------------


def test_cable_info(session: Session) -> None:
    result = call(session, "cable_info", {"name": "CA5"})
    assert (result.success, result.message) == (True, "cable CA5")
    assert (result.color, result.length, result.diameter) == ((165, 42, 42), 0.62, 0.0042)
    assert (result.wh, result.connector, result.con_index, result.main_connector) == (
        1,
        "GR12",
        (4, 0, 1, 0),
        "WH1",
    )
    first = call(session, "cable_info", {"name": "CA2"})
    assert (first.connector, first.con_index, first.color) == ("GR11", (2, 0), (0, 128, 0))


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("WH1", "WH1 is not a cable; see con_info"),
        ("K1", "K1 is not a cable"),
        ("CA99", "no cable 'CA99'; cables: CA1, CA2"),
    ],
)
def test_cable_info_unknown(session: Session, name: str, message: str) -> None:
    result = call(session, "cable_info", {"name": name})
    assert result.success is False and message in result.message


def test_con_info(session: Session) -> None:
    first = call(session, "con_info", {"name": "WH1"})
    assert (first.success, first.color, first.wh) == (True, (255, 255, 255), 1)
    assert first.cables == ("CA1", "CA2", "CA3", "CA4", "CA5")
    assert first.dimensions == (0.0329, 0.01464, 0.04655)
    end = call(session, "con_info", {"name": "GR12"})
    assert (end.success, end.cables, end.color, end.wh) == (True, ("CA4", "CA5"), (), 1)
    assert end.message == "connector GR12: not in the components definition (no colour or size)"


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("CA1", "CA1 is a cable, not a connector"),
        ("K1", "K1 is a device, not a connector"),
        ("X1", "no connector 'X1'; connectors: WH1, WH2"),
    ],
)
def test_con_info_unknown(session: Session, name: str, message: str) -> None:
    result = call(session, "con_info", {"name": name})
    assert result.success is False and result.message == message


def test_wh_info(session: Session) -> None:
    first = call(session, "wh_info", {"number": "1"})
    assert (first.success, first.connector) == (True, "WH1")
    assert first.branches == (BranchInfo("GR11", ("CA1", "CA2", "CA3")), BranchInfo("GR12", ("CA4", "CA5")))
    missing = call(session, "wh_info", {"number": "4"})
    assert (missing.success, missing.message) == (False, "no harness 4; harnesses: 1, 2")


# -- tools ----------------------------------------------------------------------------------------------


def test_all_tools(session: Session) -> None:
    assert call(session, "all_tools", {}).names == ("gun", "gripper")


def test_tool_info(session: Session) -> None:
    result = call(session, "tool_info", {"name": "gun"})
    assert (result.success, result.atc_spot, result.dimensions) == (True, "Agun", (0.22, 0.3, 0.1))
    assert result.base_wrist_frame.close_to(Pose((0.06, 0.03, 0.14), yaw(90)), 1e-12)
    assert result.wrist_action_frame.close_to(
        Pose((0.1, -0.05, 0.08), quaternion_from_rpy(0, math.pi / 2, 0)), 1e-12
    )
    # README, "The tools": the station at (-0.15, -0.70, 0.31) turned -90°; the base 90° back.
    assert result.parked_wrist_frame.close_to(Pose((-0.12, -0.76, 0.45)), 1e-6)
    unknown = call(session, "tool_info", {"name": "screwdriver"})
    assert (unknown.success, unknown.message) == (False, "no tool 'screwdriver'; tools: gun, gripper")


# -- sequence -------------------------------------------------------------------------------------------


def test_all_op_in_sequence_order(session: Session) -> None:
    result = call(session, "all_op", {})
    assert (result.success, result.message) == (True, "9 operations")
    assert [(op.index, op.type) for op in result.operations] == list(
        enumerate(["EC", "PC", "RC", "RC", "T", "EC", "PC", "RC", "TJ"], start=1)
    )
    assert result.operations[0] == OperationInfo(1, "EC", ("C1.1.L",), ("WH1",), "")
    assert result.operations[2].spot == ("J1.1", "J2.1", "J3.1")


def test_index_op(session: Session) -> None:
    result = call(session, "index_op", {"index": "4"})
    assert (result.success, result.type, result.spot, result.label, result.tool) == (
        True,
        "RC",
        ("J1.1", "J3.2"),
        ("GR12",),
        "",
    )
    for index in ("0", "10"):
        missing = call(session, "index_op", {"index": index})
        assert (missing.success, missing.message) == (
            False,
            f"no operation {index}; the sequence has operations 1 to 9",
        )


def test_wh_routes(session: Session) -> None:
    result = call(session, "wh_routes", {"number": "1"})
    assert (result.success, result.connector) == (True, "WH1")
    assert [r.cable for r in result.routes] == ["CA1", "CA2", "CA3", "CA4", "CA5"]
    assert result.routes[0] == CableRoute(
        "CA1", "WH1", (0, 0), "GR11", (), ("J1.1", "J2.1", "J3.1"), ("J1.1", "J2.1"), (1, 2, 3, 5)
    )
    assert result.routes[4] == CableRoute(
        "CA5", "WH1", (4, 0), "GR12", (1, 0), ("J1.1", "J3.2"), ("J1.1", "J2.1"), (1, 2, 4, 5)
    )
    whole = call(session, "wh_routes", {"number": "2"}).routes[1]
    assert (whole.guides, whole.tape_spots, whole.operations) == (("J2.1", "J3.1"), ("J3.1",), (6, 7, 8, 9))
    assert call(session, "wh_routes", {"number": "7"}).success is False
