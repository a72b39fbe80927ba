"""What goes on /tf_static and ~/markers, computed without ROS on the mini cell."""

from __future__ import annotations

from pathlib import Path

import pytest

from cadkg.geometry.poses import Pose
from cadkg.graph import KnowledgeGraph
from cadkg.query.placements import placements
from cadkg.services.display import Frame
from cadkg.services.frames import ARROW_LENGTH, marker_specs, static_frames
from tests.conftest import ROOT

MINI = ROOT / "tests" / "data" / "cells" / "mini" / "manifest.toml"


def test_frames_and_markers_of_the_mini_cell() -> None:
    with KnowledgeGraph.build(MINI) as kg:
        placed, model = placements(kg), kg.cell_model()
        frames = {f.child: f for f in static_frames(placed, model, "iema")}
        specs = marker_specs(placed, model, kg.files_dir, "iema")
        assert frames["cabinet"].parent == "world" and frames["cabinet"].pose.position == (1.0, 0.0, 0.0)
        assert frames["K1/corner"].parent == "cabinet"
        assert frames["K1/corner"].pose.position == pytest.approx((0.15, 0.5, 0.0075))
        assert frames["X1/terminal_start"].pose.position == pytest.approx((0.25, 0.5, 0.0075))
        assert frames["RAIL1/start"].pose.position == pytest.approx((0.1, 0.5, 0.0))
        assert frames["ID000003"].parent == "ID000002"
        assert "K9/original" not in frames  # K9 has no CAD data: no frame rather than a made-up one
        meshes = [s for s in specs if s.kind == "mesh"]
        assert len(meshes) == 8 and len({s.id for s in meshes}) == 8
        assert all(s.mesh_uri.startswith("file:///") and Path(s.mesh_uri[7:]).is_file() for s in meshes)
        assert {s.frame_id for s in meshes} <= set(frames)
        arrows = [s for s in specs if s.kind == "arrow"]
        a1 = next(s for s in arrows if s.text == "K1:A1")
        assert a1.points[1] == pytest.approx((0.155, 0.57, 0.0675))
        assert a1.points[0] == pytest.approx((0.155, 0.57, 0.0675 + ARROW_LENGTH))
        screws = sum(1 for g in model.components.values() for p in g.pins.values() if p.screw)
        assert len(arrows) == screws > 0


def _compose(frames: dict[str, Frame], child: str, root: str) -> Pose:
    pose, name = Pose(), child
    while name != root:
        frame = frames[name]
        pose = frame.pose * pose
        name = frame.parent
    return pose


def test_elvez_publishes_every_element_and_point_of_interest() -> None:
    from cadkg.services.session import Session

    with KnowledgeGraph.build(ROOT / "examples" / "elvez-cell" / "manifest.toml") as kg:
        session = Session(kg.cell_model(), kg=kg)
        placed = placements(kg)
        frames = {f.child: f for f in static_frames(placed, session.model, "elvez", session)}
        # J1 is ID0002 of the platform; its guide's key centre hangs in it, the scene in the
        # platform's frame, as the reference node names them (examples/elvez-cell/README.md).
        assert frames["ID0002platformguide1"].parent == "ID0002platform"
        assert frames["ID0002platform"].parent == "ID0001platform"
        assert frames["ID0001platform"].parent == "platform_rf"
        assert frames["ID0002combs"].parent == "ID0001combs"  # the same CAD ID on another platform
        key = _compose(frames, "ID0002platformguide1", "cell")
        base = _compose(frames, "robot_base", "cell")
        in_base = base.inverse() * key
        assert in_base.position == pytest.approx((0.662, -0.305, 0.345), abs=1e-12)
        assert in_base.close_to(Pose((0.662, -0.305, 0.345), (0.0, 0.0, -(0.5**0.5), 0.5**0.5)), 1e-12)
        assert not any(name.endswith(("/original", "/corner", "/target")) for name in frames)
        specs = marker_specs(placed, session.model, kg.files_dir, "elvez", session)
        elements = {s.text: s for s in specs if s.ns == "elements"}
        assert elements["J1"].frame_id == "ID0002platform"
        assert {s.frame_id for s in specs} <= set(frames)
        assert not [s for s in specs if s.ns == "meshes"]  # no mesh in a frame named by a bare CAD ID
        stl = Path(elements["J1"].mesh_uri.removeprefix("file://")).read_bytes()
        triangles = int.from_bytes(stl[80:84], "little")
        assert triangles > 0 and len(stl) == 84 + 50 * triangles  # a binary STL RViz can load


def test_elimco_publishes_the_bench_pin_frames() -> None:
    from cadkg.services.session import Session

    with KnowledgeGraph.build(ROOT / "examples" / "elimco-bench" / "manifest.toml") as kg:
        session = Session(kg.cell_model(), kg=kg)
        frames = {f.child: f for f in static_frames(placements(kg), session.model, "elimco", session)}
        pins = [name for name in frames if name.startswith("pin_")]
        assert pins and all(frames[name].parent.startswith(("pins_centroid", "pin_")) for name in pins)
        assert "pins_centroid" in frames
