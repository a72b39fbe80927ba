"""What goes on /tf_static and ~/markers, computed without ROS on the mini cell."""

from __future__ import annotations

from pathlib import Path

import pytest

from cadkg.derive.extract import extract
from cadkg.ros_adapter.frames import ARROW_LENGTH, marker_specs, static_frames
from cadkg.store import KnowledgeGraph
from tests.conftest import ROOT

MINI = ROOT / "tests" / "data" / "cells" / "mini" / "manifest.toml"


def test_frames_and_markers_of_the_mini_cell() -> None:
    with KnowledgeGraph.build(MINI) as kg:
        inputs, model = extract(kg), kg.cell_model()
        frames = {f.child: f for f in static_frames(inputs, model)}
        specs = marker_specs(inputs, model, kg.files_dir)
        assert frames["cabinet"].parent == "world" and frames["cabinet"].pose.position == (1.0, 0.0, 0.0)
        assert frames["K1/corner"].parent == "cabinet"
        assert frames["K1/corner"].pose.position == pytest.approx((0.15, 0.5, 0.0675))
        assert frames["X1/terminal_start"].pose.position == pytest.approx((0.25, 0.5, 0.0475))
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
