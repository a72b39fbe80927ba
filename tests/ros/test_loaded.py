"""What the ROS node serves, loaded without ROS: an approach distance derives the model anew."""

from __future__ import annotations

import pytest

from cadkg.ros_adapter.loaded import load
from tests.conftest import ROOT

MINI = ROOT / "tests" / "data" / "cells" / "mini" / "manifest.toml"


def test_an_approach_distance_derives_the_model_with_it() -> None:
    kept, near = load(str(MINI)), load(str(MINI), approach_distance=0.3)
    assert kept.profile == near.profile == "iema"
    assert kept.model.approach_distance == 0.15 and near.model.approach_distance == 0.3
    before, after = kept.model.components["K1"].target, near.model.components["K1"].target
    assert after.position[2] == pytest.approx(before.position[2] + 0.15)
    # The frames and meshes are the files', whatever the model.
    assert near.placements == kept.placements and near.placements.frames
