"""The merge of scenes, element models and WRI tables into one frame tree, and what breaks it."""

from __future__ import annotations

import math
import re
import shutil
from pathlib import Path

import pytest

from cadkg.errors import NotFound, QueryError
from cadkg.geometry.frames import quaternion_from_rpy
from cadkg.geometry.poses import Pose
from cadkg.graph import KnowledgeGraph
from cadkg.services.session import Session
from cadkg.services.table import call
from cadkg.usecases.elvez.platform import FrameTree, element_type
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
    assert ("cell", "element") not in {(p, c) for p, c, _ in tree.transforms()}
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


@pytest.mark.parametrize(
    ("label", "kind"),
    [
        ("G4", "guide"),
        ("H1", "guide"),
        ("CH2", "connector_holder"),
        ("ATC3", "atc_slot"),
        ("FS1", "flat_surface"),
    ],
)
def test_element_type_from_the_label_prefix(label: str, kind: str) -> None:
    assert element_type(label) == kind
    assert element_type("Q1") == element_type("12") == "element"


def _copy(tmp_path: Path) -> Path:
    target = tmp_path / "cell"
    shutil.copytree(EXAMPLE, target)
    return target


def _session(manifest: Path) -> Session:
    kg = KnowledgeGraph.build(manifest)
    return Session(kg.cell_model(), kg=kg)


def test_cad_ids_repeated_across_platforms_are_refused(tmp_path: Path) -> None:
    cell = _copy(tmp_path)
    for name in ("holder/holder.x3d", "holder/holder.wri"):
        path = cell / name
        path.write_text(path.read_text().replace("ID000101", "ID000001"))
    session = _session(cell / "manifest.toml")
    with pytest.raises(
        QueryError, match=r"frame 'ID000001' is placed more than once.*unique across the cell"
    ):
        call(session, "guide_info", {"name": "G4"})


def test_without_a_robot_base_the_answer_says_so(tmp_path: Path) -> None:
    cell = _copy(tmp_path)
    manifest = cell / "manifest.toml"
    manifest.write_text(manifest.read_text().replace('child = "robot_base"', 'child = "robot_mount"'))
    session = _session(manifest)
    result = call(session, "guide_info", {"name": "G4"})
    assert (result.success, result.message) == (False, "G4: no frame 'robot_base'")
    assert call(session, "guide_info", {"name": "G4", "frame": "cell_top_corner"}).success


def test_a_model_without_key_frames_is_named_in_the_message(tmp_path: Path) -> None:
    cell = _copy(tmp_path)
    models = cell / "assembly" / "assembly-models.xml"
    text = models.read_text()
    models.write_text(re.sub(r'    <frame name="key_corner" x="-5"[^\n]*\n', "", text, count=1))
    result = call(_session(cell / "manifest.toml"), "guide_info", {"name": "G4"})
    assert result.success and result.key_frame is not None and result.key_corner_frame is None
    assert result.message.endswith("; model 0009 defines no key_corner frame")


def test_plan_references_the_other_files_do_not_define(tmp_path: Path) -> None:
    cell = _copy(tmp_path)
    plan = cell / "action-plan.csv"
    plan.write_text(
        plan.read_text()
        .replace("7,route,W205;", "7,route,W299;")
        .replace("G1;G4;G6,gripper_right", "G1;G9;G6,drill")
    )
    session = _session(cell / "manifest.toml")
    result = call(session, "index_op", {"index": "7"})
    assert result.success
    assert result.message == (
        "operation 7: route; spot G9 is not on any platform; W299 is not a cable of the harness files; "
        "tool drill is not in the tools file"
    )
    assert call(session, "all_op", {}).message.startswith(
        "14 operations; operation 7: spot G9 is not on any platform"
    )
    assert call(session, "index_op", {"index": "8"}).message == "operation 8: route"
