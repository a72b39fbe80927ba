"""The reference CAD platform node's services (CAD_platform.*) on the example cell, against the
hand computations of its README, and the cases where the reference node fails."""

from __future__ import annotations

import math
from typing import Any

import pytest

from cadkg.geometry.frames import quaternion_from_rpy
from cadkg.geometry.poses import Pose
from cadkg.graph import KnowledgeGraph
from cadkg.services.session import Session
from cadkg.services.table import call
from cadkg.usecases.elvez.component_services import PinsData
from cadkg.usecases.elvez.platform_services import JigGuideData
from tests.conftest import ROOT

ELVEZ = ROOT / "examples" / "elvez-cell" / "manifest.toml"
S = math.sqrt(0.5)


@pytest.fixture(scope="module")
def session(elvez: KnowledgeGraph) -> Session:
    return Session(elvez.cell_model(), kg=elvez)


def ref(session: Session, service: str, **params: str) -> Any:
    return call(session, f"CAD_platform.{service}", params)


def yaw(degrees: float) -> tuple[float, float, float, float]:
    return quaternion_from_rpy(0.0, 0.0, math.radians(degrees))


def test_guide_info_gives_the_key_and_the_jig_s_extents(session: Session) -> None:
    result = ref(session, "guide_info", jig="J1", guide="1")
    assert result.success and result.message == "guide 1 of J1 (ID0002 on platform) in robot_base"
    data = result.data
    assert (data.id, data.key_length, data.key_gap, data.key_height, data.key_height_corner) == (
        "1",
        0.01,
        0.008,
        0.03,
        0.05,
    )
    assert data.key_corner_frame.close_to(Pose((0.658, -0.30, 0.33), yaw(-90)), 1e-12)
    assert data.key_center_frame.close_to(Pose((0.662, -0.305, 0.345), yaw(-90)), 1e-12)
    assert data.collision_corner_frame.close_to(Pose((0.65, -0.318, 0.265), yaw(-90)), 1e-12)
    assert (data.collision_dimensions, data.dimensions) == ((0.008, 0.02, 0.01), (0.01, 0.024, 0.15))
    assert data.collisions == (0.0, 0.01, -0.008, 0.022)  # the jig's, not the key's
    assert (data.jig_corner_frame, data.jig_center_frame, data.jig_dimensions) == (None, None, ())


@pytest.mark.parametrize(
    ("jig", "guide", "message"),
    [
        ("J9", "1", "no jig or comb 'J9'; known: C1, C2, J1, J2, J3, J4"),
        ("J1", "2", "J1 has no guide '2'; guides: 1"),
        ("B1", "1", "B1 is a box, not a jig or comb"),
        ("Agun", "1", "Agun is an ATC station, not a jig or comb"),
    ],
)
def test_guide_info_failures(session: Session, jig: str, guide: str, message: str) -> None:
    result = ref(session, "guide_info", jig=jig, guide=guide)
    assert (result.success, result.message, result.data) == (False, message, JigGuideData())


def test_all_guides_are_the_jigs_guides_named_by_their_jig(session: Session) -> None:
    result = ref(session, "all_guides")
    assert (result.success, result.message) == (True, "5 guides")
    assert [g.id for g in result.data] == ["J1", "J2", "J3", "J3", "J4"]  # no combs
    first = result.data[0]
    assert first.jig_corner_frame.close_to(Pose((0.65, -0.30, 0.21), yaw(-90)), 1e-12)
    assert first.jig_center_frame.close_to(Pose((0.662, -0.305, 0.21), yaw(-90)), 1e-12)
    assert first.jig_dimensions == (0.01, 0.036, 0.0)
    assert (first.key_corner_frame, first.collisions, first.key_height_corner) == (None, (), 0.0)


def test_jig_info_gives_each_guide_with_its_key_s_extents(session: Session) -> None:
    result = ref(session, "jig_info", jig="J3")
    assert (result.success, result.commercial, result.dimensions) == (True, "0012", (0.06, 0.04, 0.08))
    assert result.corner_frame.close_to(Pose((0.68, -0.50, 0.21), yaw(-90)), 1e-12)
    assert [(g.id, g.collisions) for g in result.guides] == [
        ("1", (0.0, 0.01, -0.004, 0.012)),
        ("2", (0.0, 0.01, -0.004, 0.012)),
    ]
    (spot,) = result.taping_spots
    assert spot.id == "1" and spot.dimensions == (0.03, 0.04, 0.005)
    comb = ref(session, "jig_info", jig="C1")
    assert comb.success and comb.corner_frame.close_to(Pose((0.85, -0.61, 0.38), (S, 0.0, 0.0, S)), 1e-6)
    assert comb.guides[0].key_corner_frame.close_to(Pose((0.857, -0.615, 0.38), (S, 0.0, 0.0, S)), 1e-6)
    assert ref(session, "jig_info", jig="B1").message == "B1 is a box, not a jig or comb"


def test_taping_spot_centre_on_the_cable_line(session: Session) -> None:
    result = ref(session, "taping_spot_info", jig="J3", spot="1")
    assert result.success
    assert result.data.corner_frame.close_to(Pose((0.68, -0.515, 0.27), yaw(-90)), 1e-12)
    # README: 22.3607 mm · cos(1.57 - atan 2) along the spot's y, 15 mm up, half its 30 mm along x.
    along = math.sqrt(500) * math.cos(1.57 - math.atan(2.0)) / 1000
    assert result.data.center_frame.close_to(Pose((0.68 + along, -0.53, 0.285), yaw(-90)), 1e-12)
    assert round(along * 1000, 5) == 20.00796
    missing = ref(session, "taping_spot_info", jig="J1", spot="1")
    assert (missing.success, missing.message) == (False, "J1 has no taping spot '1'; taping spots: none")


def test_tray_info(session: Session) -> None:
    result = ref(session, "tray_info", box="B1", tray="2")
    assert (result.success, result.wh, result.dimensions) == (True, "2", (0.09, 0.14, 0.05))
    assert result.key_corner_frame.close_to(Pose((0.805, -0.755, 0.22), yaw(-90)), 1e-12)
    assert result.key_center_frame.close_to(Pose((0.875, -0.80, 0.22), yaw(-90)), 1e-12)
    assert ref(session, "tray_info", box="B1", tray="1").wh == "1"
    assert ref(session, "tray_info", box="B1", tray="3").message == "B1 has no tray '3'; trays: 1, 2"
    assert ref(session, "tray_info", box="B7", tray="1").message == "no box 'B7'; known: B1"


def test_all_cad_components(session: Session) -> None:
    result = ref(session, "all_cad_components")
    assert result.data == (
        "J1,guides,1", "J2,guides,1", "J3,guides,1", "J3,guides,2", "J3,tape_spots,1", "J4,guides,1",
        "B1,trays,1", "B1,trays,2",
    )  # fmt: skip


def test_tools(session: Session) -> None:
    assert ref(session, "get_tools_service").data == ("gun", "gripper")
    gun = ref(session, "tool_info", name="gun")
    assert (gun.success, gun.type, gun.dim, gun.dim_tool, gun.dim_fingers, gun.pose_nail) == (
        True,
        "gun",
        (),
        (0.22, 0.3, 0.1),
        (),
        None,
    )
    assert gun.pose_base.close_to(Pose((-0.12, -0.76, 0.45)), 1e-6)
    assert gun.pose_end.close_to(Pose((0.1, -0.05, 0.08), quaternion_from_rpy(0.0, math.pi / 2, 0.0)), 1e-12)
    gripper = ref(session, "tool_info", name="gripper")
    assert (gripper.type, gripper.dim_fingers) == ("gripper", (0.013, 0.034, 0.0153))
    # README: R = 90° then Y = 90° about the turned axes, (0.5, -0.5, 0.5, 0.5).
    assert gripper.pose_base.close_to(Pose((-0.125, -0.945, 0.425), (0.5, -0.5, 0.5, 0.5)), 1e-6)
    assert gripper.pose_nail == Pose((0.0, 0.0, 0.26))
    assert ref(session, "tool_info", name="glue").message == "no tool 'glue'; tools: gun, gripper"


def test_connector_info(session: Session) -> None:
    result = ref(session, "connector_info", label="WH1")
    assert (result.success, result.component, result.color, result.reference, result.model) == (
        True,
        "CON",
        "White",
        "111",
        "LUM1",
    )
    assert (result.wh, result.box, result.tray, result.dimensions) == ("1", "B1", "1", (32.9, 14.64, 46.55))
    assert result.cables == (
        PinsData("CA1", ("0", "0")), PinsData("CA2", ("2", "0")), PinsData("CA3", ("1", "0")),
        PinsData("CA4", ("3", "0")), PinsData("CA5", ("4", "0")),
    )  # fmt: skip
    end = ref(session, "connector_info", label="GR12")
    # An end connector's cables with their cavity in the first connector, as the reference gives them.
    assert (end.success, end.component, end.cables) == (
        True,
        "",
        (PinsData("CA4", ("3", "0")), PinsData("CA5", ("4", "0"))),
    )
    device = ref(session, "connector_info", label="K1")
    assert (device.component, device.model, device.type, device.color, device.wh) == (
        "DEV",
        "CAP1",
        "capacitor",
        "Blue",
        "",
    )
    unknown = ref(session, "connector_info", label="CA1")
    assert (unknown.success, unknown.message) == (
        False,
        "no connector or device 'CA1'; connectors and devices: WH1, WH2, K1",
    )


def test_cable_info_in_millimetres(session: Session) -> None:
    result = ref(session, "cable_info", label="CA5")
    assert (result.component, result.color, result.length, result.diameter) == ("CAB", "Brown", 620.0, 4.2)
    assert (result.wh, result.box, result.tray) == ("1", "B1", "1")
    assert result.connectors == (PinsData("WH1", ("4", "0")), PinsData("GR12", ("1", "0")))
    assert ref(session, "cable_info", label="CA1").connectors[1] == PinsData("GR11", ())
    assert ref(session, "cable_info", label="WH1").success is False
