"""The served cell's model: an approach distance (the ROS node's parameter) derives it anew."""

from __future__ import annotations

import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.query.placements import placements
from cadkg.served.holder import GraphHolder
from cadkg.served.target import TargetError, model_with, open_target
from tests.conftest import ROOT

MINI = ROOT / "tests" / "data" / "cells" / "mini" / "manifest.toml"


def test_an_approach_distance_derives_the_model_with_it() -> None:
    kept = GraphHolder(open_target(MINI))
    near = GraphHolder(open_target(MINI), model=model_with({"approach_distance": 0.3}))
    try:
        first, second = kept.current.session(), near.current.session()
        assert first.profile == second.profile == "iema"
        assert first.model.approach_distance == 0.15 and second.model.approach_distance == 0.3
        before, after = first.model.components["K1"].target, second.model.components["K1"].target
        assert after.position[2] == pytest.approx(before.position[2] + 0.15)
        # The frames and meshes are the files', whatever the model.
        assert placements(second.kg) == placements(first.kg) and placements(second.kg).frames
    finally:
        kept.close()
        near.close()


def test_a_target_that_is_none_of_the_three_is_refused() -> None:
    with pytest.raises(TargetError, match="neither a store directory nor a manifest"):
        open_target("/nowhere/at/all")
    assert isinstance(open_target(MINI), KnowledgeGraph)
