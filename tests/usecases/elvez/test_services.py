"""Every ELVEZ service (Table 2 and the route traversal) on the example cell, and unknown names.

Expected values are read from the example's files or computed by hand in its README.
"""

from __future__ import annotations

import math
from collections.abc import Iterator

import pytest

from cadkg.geometry.frames import quaternion_from_rpy
from cadkg.geometry.poses import Pose
from cadkg.graph import KnowledgeGraph
from cadkg.services.session import Session
from cadkg.services.table import SERVICES, call, services_for
from cadkg.usecases.elvez import answers as elvez
from cadkg.usecases.elvez.answers import BranchInfo, CableRoute, ElvezModel, OperationInfo
from tests.conftest import ROOT

ELVEZ = ROOT / "examples" / "elvez-cell" / "manifest.toml"
TABLE_2 = ("guide_info", "cable_info", "con_info", "wh_info", "all_tools", "tool_info", "all_op", "index_op")


@pytest.fixture(scope="module")
def kg() -> Iterator[KnowledgeGraph]:
    graph = KnowledgeGraph.build(ELVEZ)
    yield graph
    graph.close()


@pytest.fixture(scope="module")
def session(kg: KnowledgeGraph) -> Session:
    return Session(kg.cell_model(), kg=kg)


@pytest.fixture(scope="module")
def model(kg: KnowledgeGraph) -> ElvezModel:
    return elvez.build_model(kg)


def yaw(degrees: float) -> tuple[float, float, float, float]:
    return quaternion_from_rpy(0.0, 0.0, math.radians(degrees))


def test_the_profile_registers_table_2_and_the_traversal() -> None:
    names = [s.name for s in services_for("elvez")]
    assert names == [*TABLE_2, "wh_routes"]
    assert SERVICES["guide_info"].optional == frozenset({"frame"})


def test_the_model_is_built_once_per_session(session: Session) -> None:
    first = call(session, "all_tools", {})
    assert call(session, "all_tools", {}) == first
    assert session.profile_model("elvez", lambda kg: None) is session.profile_model(
        "elvez", elvez.build_model
    )


# -- guides ---------------------------------------------------------------------------------------------


def test_the_assembly_platform_has_eight_guides(model: ElvezModel) -> None:
    guides = model.platforms.of_kind("guide")
    on_assembly = sorted(g.label for g in guides if g.platform == "assembly_platform")
    assert on_assembly == [f"G{i}" for i in range(1, 9)]
    assert sorted(g.label for g in guides if g.platform == "holder_platform") == [
        f"H{i}" for i in range(1, 7)
    ]
    assert sorted(e.label for e in model.platforms.of_kind("atc_slot")) == ["ATC1", "ATC2", "ATC3"]


def test_every_guide_answers_with_its_key(model: ElvezModel) -> None:
    for guide in model.platforms.of_kind("guide"):
        result = elvez.guide_info(model, guide.label)
        assert result.success, result.message
        assert result.key_frame is not None and result.key_corner_frame is not None
        assert result.key_length > 0 and result.key_gap > 0 and result.key_height > 0


def test_guide_info_in_another_frame(session: Session) -> None:
    # G4's key in its platform: the X3D pose of G4 (30° about z, on FS1 at z = 0.01) times the
    # model's key frame (10 mm along x, 40 mm up, 90° about z); see the example README.
    result = call(session, "guide_info", {"name": "G4", "frame": "assembly_platform"})
    assert result.frame == "assembly_platform"
    expected = Pose((0.3 + 0.01 * math.cos(math.pi / 6), 0.1 + 0.01 * math.sin(math.pi / 6), 0.07), yaw(120))
    assert result.key_frame.close_to(expected, 1e-12)
    local = call(session, "guide_info", {"name": "G4", "frame": "ID000005"})
    assert local.key_frame.close_to(Pose((0.01, 0.0, 0.04), yaw(90)), 1e-12)
    assert local.origin_frame.close_to(Pose(), 1e-12)
    assert local.id == "ID000005"
    assert local.dimensions == pytest.approx((0.04, 0.03, 0.05))
    assert (local.key_length, local.key_gap, local.key_height) == pytest.approx((0.03, 0.006, 0.025))


def test_guide_on_the_holder_platform_turned_half_a_turn(session: Session) -> None:
    result = call(session, "guide_info", {"name": "H5", "frame": "cell_top_corner"})
    assert result.key_frame.close_to(Pose((0.35, 1.15, 0.095), yaw(180)), 1e-12)
    assert result.key_corner_frame.close_to(Pose((0.358, 1.152, 0.08), yaw(180)), 1e-12)


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"name": "G99"}, "no guide 'G99' on the platforms; guides: G1, G2, G3, G4"),
        ({"name": "ATC1"}, "ATC1 is of type atc_slot, not a guide"),
        ({"name": "CH1"}, "CH1 is of type connector_holder, not a guide"),
        ({"name": "G4", "frame": "nowhere"}, "G4: no frame 'nowhere'"),
        ({"name": "G4", "frame": "gripper_left_wrist"}, "are not connected"),
    ],
)
def test_guide_info_failures(session: Session, params: dict[str, str], message: str) -> None:
    result = call(session, "guide_info", params)
    assert result.success is False
    assert message in result.message
    assert result.key_frame is None


# -- harnesses ------------------------------------------------------------------------------------------


def test_cable_info(session: Session) -> None:
    result = call(session, "cable_info", {"name": "W101"})
    assert (result.success, result.message) == (True, "cable W101")
    assert result.color == (255, 0, 0)
    assert (result.length, result.diameter) == pytest.approx((0.42, 0.0016))
    assert (result.wh, result.connector, result.con_index, result.main_connector) == (1, "C11", (1, 1), "C10")
    last = call(session, "cable_info", {"name": "W311"})
    assert (last.wh, last.connector, last.con_index, last.color) == (3, "C33", (12, 3), (255, 105, 180))


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("C10", "C10 is a connector, not a cable; see con_info"),
        ("K33", "K33 is a capacitor, not a cable"),
        ("W999", "no cable 'W999'; cables: W101, W102"),
    ],
)
def test_cable_info_unknown(session: Session, name: str, message: str) -> None:
    result = call(session, "cable_info", {"name": name})
    assert result.success is False and message in result.message


def test_con_info(session: Session) -> None:
    branch = call(session, "con_info", {"name": "C12"})
    assert branch.success
    assert (branch.color, branch.wh, branch.cables) == ((255, 255, 255), 1, ("W104", "W105", "W106"))
    assert branch.dimensions == pytest.approx((0.02, 0.015, 0.012))
    main = call(session, "con_info", {"name": "C30"})
    assert main.cables == tuple(f"W3{i:02d}" for i in range(1, 12))
    assert main.dimensions == pytest.approx((0.055, 0.03, 0.02))


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("W101", "W101 is a cable, not a connector; see cable_info"),
        ("K33", "K33 is a capacitor, not a connector"),
        ("C99", "no connector 'C99'; connectors: C10, C11"),
    ],
)
def test_con_info_unknown(session: Session, name: str, message: str) -> None:
    result = call(session, "con_info", {"name": name})
    assert result.success is False and message in result.message


def test_wh_info(session: Session) -> None:
    counts = []
    for number in ("1", "2", "3"):
        result = call(session, "wh_info", {"number": number})
        assert result.success
        counts.append(sum(len(b.cables) for b in result.branches))
    assert counts == [6, 10, 11]
    first = call(session, "wh_info", {"number": "1"})
    assert first.connector == "C10"
    assert first.branches == (
        BranchInfo("C11", ("W101", "W102", "W103")),
        BranchInfo("C12", ("W104", "W105", "W106")),
    )
    missing = call(session, "wh_info", {"number": "4"})
    assert (missing.success, missing.message) == (False, "no harness 4; harnesses: 1, 2, 3")


# -- tools ----------------------------------------------------------------------------------------------


def test_all_tools(session: Session) -> None:
    result = call(session, "all_tools", {})
    assert (result.success, result.names) == (True, ("gripper_left", "gripper_right", "taping_gun"))


def test_tool_info(session: Session) -> None:
    result = call(session, "tool_info", {"name": "gripper_left"})
    assert (result.success, result.atc_spot) == (True, "ATC1")
    assert result.dimensions == pytest.approx((0.09, 0.06, 0.14))
    assert result.base_wrist_frame.close_to(Pose((0.0, 0.0, 0.14), (1.0, 0.0, 0.0, 0.0)), 1e-12)
    assert result.wrist_action_frame.close_to(Pose((0.0, 0.0, 0.12)), 1e-12)
    # ATC1's seat is at (-0.8, 0.4, 0.05) in the robot base, turned 90° about z (README); the wrist
    # is 0.14 m above it, upside down.
    s = math.sqrt(0.5)
    assert result.parked_wrist_frame.close_to(Pose((-0.8, 0.4, 0.19), (s, s, 0.0, 0.0)), 1e-12)
    unknown = call(session, "tool_info", {"name": "screwdriver"})
    assert unknown.success is False
    assert unknown.message == "no tool 'screwdriver'; tools: gripper_left, gripper_right, taping_gun"


# -- process --------------------------------------------------------------------------------------------


def test_all_op_in_plan_order(session: Session) -> None:
    result = call(session, "all_op", {})
    assert result.success
    assert [op.index for op in result.operations] == list(range(1, 15))
    assert [op.type for op in result.operations] == [
        "insert", "route", "route", "tape",
        "insert", "route", "route", "route", "tape",
        "insert", "route", "route", "route", "tape",
    ]  # fmt: skip
    assert result.operations[0] == OperationInfo(1, "insert", ("H1", "CH1"), ("C10",), "gripper_left")


def test_index_op(session: Session) -> None:
    result = call(session, "index_op", {"index": "7"})
    assert (result.success, result.type, result.spot, result.label, result.tool) == (
        True,
        "route",
        ("G1", "G4", "G6"),
        ("W205", "W206", "W207"),
        "gripper_right",
    )
    for index in ("0", "15"):
        missing = call(session, "index_op", {"index": index})
        assert missing.success is False
        assert missing.message == f"no operation {index}; the plan has operations 1 to 14"


def test_wh_routes(session: Session) -> None:
    result = call(session, "wh_routes", {"number": "2"})
    assert result.success and result.connector == "C20"
    assert [r.cable for r in result.routes] == [f"W2{i:02d}" for i in range(1, 11)]
    by_cable = {r.cable: r for r in result.routes}
    assert by_cable["W205"] == CableRoute(
        "W205", "C20", 5, "C22", 1, ("G1", "G4", "G6"), ("G1", "G4"), (7, 9)
    )
    assert by_cable["W201"].guides == ("G1", "G2", "G3")
    last = call(session, "wh_routes", {"number": "3"}).routes[-1]
    assert last == CableRoute("W311", "C30", 12, "C33", 3, ("G7", "G4", "G5"), ("G7", "G4"), (13, 14))
    assert call(session, "wh_routes", {"number": "7"}).success is False
