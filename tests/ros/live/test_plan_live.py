"""The node's ``plan`` service: the task list a store holds, through a real rclpy client; the
connection provider served by the node follows it."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from cadkg_interfaces import srv

from tests.ros.live.conftest import ROOT, Server
from tests.ros.live.test_profiles_live import _call

NAMESPACE = "/planned"


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    from cadkg.graph import KnowledgeGraph
    from cadkg.plan.cell import store_plan

    cell = tmp_path_factory.mktemp("plan") / "cabinet"
    shutil.copytree(ROOT / "tests" / "data" / "plan" / "cabinet", cell)
    store = cell / "store"
    with KnowledgeGraph.build(cell / "manifest.toml", store) as kg:
        store_plan(kg)
    running = Server(
        store, cell.parent / "node.log", node_name="cadkg_planned", extra=("--namespace", NAMESPACE)
    )
    yield running
    running.stop()


def test_the_plan_service_gives_the_stored_task_list(ros: Any, planned: Server) -> None:
    call = _call(ros, planned, NAMESPACE)
    answer = call(srv.Plan, "plan")
    assert answer.success, answer.message
    assert answer.message.startswith("12 tasks: 6 robot, 6 person")
    assert [s.task for s in answer.steps[:2]] == ["W2", "W1"] and answer.steps[0].step == 0
    assert answer.steps[5].performer == "human" and "precedence cycle" in answer.steps[5].reason
    first = answer.precedence[0]
    assert (first.before, first.after) == ("W2", "W1") and "approach of A1:Q" in first.reason
    wire = call(srv.GroupConnectionProvider, "group_connection_provider")
    assert wire.wire == "W2"


def test_without_a_plan_the_service_says_how_to_make_one(call: Any, tmp_path: Path) -> None:
    answer = call(srv.Plan, "plan")
    assert not answer.success and "cadkg plan STORE" in answer.message
