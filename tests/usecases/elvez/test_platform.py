"""The frame tree of the cell, the points of interest of an element's definition, and cells
whose files do not agree (the build goes through, the services and cadkg validate say what is
missing)."""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import pytest

from cadkg.errors import NotFound, QueryError
from cadkg.geometry.frames import quaternion_from_rpy
from cadkg.geometry.poses import Pose
from cadkg.graph import KnowledgeGraph
from cadkg.query.validate import validate
from cadkg.services.session import Session
from cadkg.services.table import call
from cadkg.usecases.elvez.files.definitions import PlacedBox
from cadkg.usecases.elvez.files.xml_fields import rotation_xyz
from cadkg.usecases.elvez.platform import FrameTree, tape_spot_centre, xyz_angles
from tests.conftest import ROOT

EXAMPLE = ROOT / "examples" / "elvez-cell"


def yaw(degrees: float) -> tuple[float, float, float, float]:
    return quaternion_from_rpy(0.0, 0.0, math.radians(degrees))


@pytest.fixture
def tree() -> FrameTree:
    return FrameTree(
        {
            "base": ("cell", Pose((1.0, 0.0, 0.0), yaw(180))),
            "platform": ("cell", Pose((0.0, 1.0, 0.0), yaw(90))),
            "element": ("platform", Pose((0.5, 0.0, 0.1))),
            "loose_wrist": ("loose_base", Pose((0.0, 0.0, 0.2))),
        }
    )


def test_pose_walks_up_and_down_the_tree(tree: FrameTree) -> None:
    # element in cell: (0, 1, 0) + Rz(90)(0.5, 0, 0.1) = (0, 1.5, 0.1), yaw 90;
    # in base: Rz(-180)((0, 1.5, 0.1) - (1, 0, 0)) = (1, -1.5, 0.1), yaw -90.
    assert tree.pose("element", "base").close_to(Pose((1.0, -1.5, 0.1), yaw(-90)), 1e-12)
    assert tree.pose("base", "element").close_to(tree.pose("element", "base").inverse(), 1e-12)
    assert tree.pose("cell", "cell").close_to(Pose(), 0.0)
    assert tree.rooted("element")[0] == "cell"
    assert ("platform", "element") in {(p, c) for p, c, _ in tree.transforms()}


def test_unknown_and_unconnected_frames(tree: FrameTree) -> None:
    with pytest.raises(NotFound, match="no frame 'nowhere'"):
        tree.pose("nowhere", "base")
    with pytest.raises(
        QueryError, match=r"'loose_wrist' \(under 'loose_base'\) and frame 'base' \(under 'cell'\)"
    ):
        tree.pose("loose_wrist", "base")


def test_a_cycle_is_reported() -> None:
    cyclic = FrameTree({"a": ("b", Pose()), "b": ("a", Pose())})
    with pytest.raises(QueryError, match="form a cycle: a → b → a"):
        cyclic.rooted("a")


@pytest.mark.parametrize("angles", [(0.3, -0.2, 1.1), (-1.57, 0.0, -1.57), (0.0, 1.2, 3.0)])
def test_the_definition_angles_are_read_back(angles: tuple[float, float, float]) -> None:
    assert xyz_angles(rotation_xyz(*angles)) == pytest.approx(angles, abs=1e-12)


def test_a_taping_spot_beside_its_guide_and_one_straight_ahead() -> None:
    spot = PlacedBox("1", (0.03, 0.04, 0.005), Pose((0.015, 0.0, 0.06)), 1, "1")
    centre = tape_spot_centre(spot, Pose((0.005, 0.02, 0.075)))
    along = math.hypot(0.01, 0.02) * math.cos(1.57 - math.atan(2.0))
    assert centre.close_to(Pose((0.03, along, 0.075)), 1e-15)
    # The guide right in front of the corner: the reference divides by zero; a right angle here.
    ahead = tape_spot_centre(spot, Pose((0.015, 0.02, 0.07)))
    assert ahead.close_to(Pose((0.03, 0.02 * math.cos(1.57 - math.pi / 2), 0.07)), 1e-15)


def _copy(tmp_path: Path) -> Path:
    target = tmp_path / "cell"
    shutil.copytree(EXAMPLE, target)
    return target


def _session(manifest: Path) -> Session:
    kg = KnowledgeGraph.build(manifest)
    return Session(kg.cell_model(), kg=kg)


def test_two_scenes_of_one_platform_name_are_refused(tmp_path: Path) -> None:
    cell = _copy(tmp_path)
    (cell / "other").mkdir()
    shutil.copy(cell / "combs_cad.x3d", cell / "other" / "platform_cad.x3d")
    manifest = cell / "manifest.toml"
    manifest.write_text(
        manifest.read_text() + '\n[[source]]\npath = "other/platform_cad.x3d"\nframe = "combs_rf"\n'
    )
    with pytest.raises(
        QueryError, match=r"frame 'ID0001platform' is placed more than once \(and 2 more frames\)"
    ):
        call(_session(manifest), "guide_info", {"name": "J1"})


def test_without_a_robot_base_the_answers_are_in_the_cell(tmp_path: Path) -> None:
    cell = _copy(tmp_path)
    manifest = cell / "manifest.toml"
    manifest.write_text(manifest.read_text().replace('child = "robot_base"', 'child = "robot_mount"'))
    result = call(_session(manifest), "guide_info", {"name": "J1"})
    assert (result.success, result.frame) == (True, "cell")
    # README: J1 at (0.4 - 0.05, 0.2 + 0.10, 0.7 + 0.01) in the cell, turned 90°.
    assert result.origin_frame.close_to(Pose((0.35, 0.30, 0.71), yaw(90)), 1e-12)


def test_a_cell_whose_files_do_not_agree(tmp_path: Path) -> None:
    cell = _copy(tmp_path)
    sequence = cell / "Assembly_sequence.csv"
    sequence.write_bytes(sequence.read_bytes().replace(b"6;EC;WH2;C2.1.R", b"6;EC;WH3;C3.1.R"))
    harnesses = cell / "WH_configuration.xml"
    harnesses.write_text(harnesses.read_text().replace('tray="B1.2"', 'tray="B3.1"'))
    ids = cell / "platform_ids.wri"
    ids.write_bytes(ids.read_bytes().replace(b"ID0005\tJ4\t0015", b"ID0005\tJ4\t0099"))
    jigs = cell / "Jigs_definition_v2.xml"
    jigs.write_text(jigs.read_text().replace('xcenter="10" ycenter="10" xcolli="40" ycolli="20"', ""))
    manifest = cell / "manifest.toml"
    kg = KnowledgeGraph.build(manifest)  # the build goes through
    session = Session(kg.cell_model(), kg=kg)
    step = call(session, "CAD_platform.index_operation", {"index": "5"})
    assert step.success and step.type == "EC"
    assert step.message == (
        "operation 5 (order 6): EC WH3 at C3.1.R; WH3 is in no harness of the harness configuration and "
        "not in the components; spot C3.1: C3 is on no platform"
    )
    assert call(session, "CAD_platform.connector_info", {"label": "WH3"}).success is False
    assert call(session, "CAD_platform.tray_info", {"box": "B3", "tray": "1"}).message == (
        "no box 'B3'; known: B1 (harness tray B3.1 names it)"
    )
    assert call(session, "CAD_platform.guide_info", {"jig": "J4", "guide": "1"}).message == (
        "J4 (platform_ids.wri:5) is of model 0099, which no definition gives"
    )
    found = [(f.location, f.severity, f.message) for f in validate(kg, shacl=False) if f.check == "elvez"]
    assert found == [
        ("Assembly_sequence.csv:3", "error", "spot J4.1: J4 has no definition (model 0099)"),
        (
            "Assembly_sequence.csv:7",
            "error",
            "WH3 is in no harness of the harness configuration and not in the components",
        ),
        ("Assembly_sequence.csv:7", "error", "spot C3.1: C3 is on no platform"),
        ("Assembly_sequence.csv:8", "error", "spot J4.1: J4 has no definition (model 0099)"),
        ("WH_configuration.xml:14", "error", "tray B3.1 of harness 2: no box B3 on the platforms"),
        ("platform_ids.wri:5", "error", "J4: no definition of model 0099"),
    ]
    kg.close()


def test_the_example_is_consistent() -> None:
    kg = KnowledgeGraph.build(EXAMPLE / "manifest.toml")
    assert validate(kg) == []
    kg.close()
