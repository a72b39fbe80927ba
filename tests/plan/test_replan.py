"""``replan``: the stored plan made again, a task switched between the robot and a person first
(what the workbench's review panel does), through ``cadkg call`` and ``POST /api/replan``: the
new plan, the times before and after, the tasks whose performer changed; one new generation;
every refused input one line (CLI) or a 4xx (HTTP), nothing changed.

The figures are the defaults' (``[time]`` of the IEMA rules): a person takes 240 s a wire."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import httpx
import pytest

from cadkg.generations import read_pointer
from cadkg.graph import KnowledgeGraph
from cadkg.server import Settings, create_app
from tests.cli import run
from tests.conftest import ELVEZ, IEMA
from tests.plan.stores import built, copied
from tests.server.serving import serving_app

TOKEN = "replan-token"


def _call(store: Path, *params: str) -> dict[str, Any]:
    done = run("call", store, "replan", *params)
    assert done.returncode == 0, done.stderr
    return dict(json.loads(done.stdout))


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built(IEMA, tmp_path_factory.mktemp("replan") / "iema", planned=True)


def test_a_wire_switched_to_a_person_moves_its_time_to_the_person_lane(planned: Path, tmp_path: Path) -> None:
    store = copied(planned, tmp_path / "iema")
    before = json.loads(run("call", store, "plan").stdout)
    wire = next(s for s in before["steps"] if s["performer"] == "robot" and s["kind"] == "wire")
    generation = read_pointer(store)
    answer = _call(store, f"task={wire['task']}", "performer=human")
    assert read_pointer(store) != generation  # the assignment and the plan: one new generation
    assert answer["makespan_s_before"] == before["summary"]["makespan_s"]
    assert answer["person_time_s"] == answer["person_time_s_before"] + 240.0
    assert answer["robot_time_s"] < answer["robot_time_s_before"]
    assert answer["makespan_s"] == answer["summary"]["makespan_s"]
    moved = {m["key"]: m for m in answer["moved"]}
    assert moved[wire["key"]]["before"] == "robot" and moved[wire["key"]]["after"] == "human"
    assert "assigned to a person by hand" in moved[wire["key"]]["reason"]
    assert f"{wire['key']} → human" in answer["message"]
    stored = {s["key"]: s for s in json.loads(run("call", store, "plan").stdout)["steps"]}
    assert (stored[wire["key"]]["performer"], stored[wire["key"]]["rule"]) == ("human", "assigned")
    # And back: the robot's again, by hand.
    again = _call(store, f"task={wire['key']}", "performer=robot")
    assert [(m["key"], m["after"]) for m in again["moved"]] == [(wire["key"], "robot")]
    assert again["makespan_s"] == pytest.approx(answer["makespan_s_before"], abs=1e-6)
    # Nothing switched: the plan made again as it stands, nothing moved.
    same = _call(store)
    assert same["moved"] == [] and same["makespan_s"] == again["makespan_s"]


def test_an_elvez_operation_is_switched_by_its_label(tmp_path: Path) -> None:
    store = built(ELVEZ, tmp_path / "elvez", planned=True)
    answer = _call(store, "task=RC GR11", "performer=human")
    moved = [(m["task"], m["before"], m["after"]) for m in answer["moved"]]
    assert ("RC GR11", "robot", "human") in moved
    step = next(s for s in answer["steps"] if s["task"] == "RC GR11")
    assert (step["performer"], step["rule"]) == ("human", "assigned")
    # The assignment is the one cadkg assign makes of the operation (its order in the sequence).
    assigned = run("assign", store, "operation", "3", "robot")
    assert assigned.returncode == 0, assigned.stderr
    back = _call(store)
    assert [(m["task"], m["after"]) for m in back["moved"]] == [("RC GR11", "robot")]


@pytest.mark.parametrize(
    ("params", "message"),
    [
        (("task=NO-SUCH", "performer=human"), "replan: no task 'NO-SUCH' in the plan"),
        (("task=1500.51", "performer=person"), "replan: unknown performer 'person'; expected robot or human"),
        (("task=1500.51",), "replan: give task and performer together (or neither)"),
        (("performer=human",), "replan: give task and performer together (or neither)"),
        (("task=0V", "performer=human"), "replan: '0V' names "),
        (("colour=red",), "replan: unknown parameter colour"),
    ],
)
def test_a_refused_replan_is_one_line_and_changes_nothing(
    planned: Path, params: tuple[str, ...], message: str
) -> None:
    generation = read_pointer(planned)
    refused = run("call", planned, "replan", *params)
    assert refused.returncode == 2, refused.stdout
    assert refused.stderr.count("\n") == 1 and message in refused.stderr, refused.stderr
    assert read_pointer(planned) == generation


def test_replan_over_http_needs_post_and_the_token(planned: Path, tmp_path: Path) -> None:
    store = copied(planned, tmp_path / "iema")
    settings = Settings(allow_update=True, token=TOKEN, watch_seconds=0)
    app = create_app(lambda: KnowledgeGraph.open(store, read_only=False), settings)
    auth = {"Authorization": f"Bearer {TOKEN}"}
    with serving_app(app) as base:
        form = {"task": "1500.53", "performer": "human"}
        generation = read_pointer(store)
        refused = [
            httpx.get(f"{base}/api/replan", params=form),
            httpx.post(f"{base}/api/replan", data=form),
            httpx.post(f"{base}/api/replan", data=form, headers={"Authorization": "Bearer nope"}),
            httpx.post(f"{base}/api/replan", data={**form, "task": "NO-SUCH"}, headers=auth),
            httpx.post(f"{base}/api/replan", data={"task": "1500.53"}, headers=auth),
        ]
        assert [r.status_code for r in refused] == [405, 401, 401, 404, 400]
        assert read_pointer(store) == generation
        done = httpx.post(f"{base}/api/replan", data=form, headers=auth, timeout=120)
        assert done.status_code == 200, done.text
        assert [m["key"] for m in done.json()["moved"]] == ["1500.53"]
        plan = httpx.get(f"{base}/api/plan", timeout=60).json()
        assert next(s for s in plan["steps"] if s["key"] == "1500.53")["performer"] == "human"


def test_a_store_without_a_plan_is_measured_against_the_plan_of_the_cell_as_it_stood(tmp_path: Path) -> None:
    store = built(IEMA, tmp_path / "iema")
    planned = json.loads(run("plan", store, "--format", "json").stdout)
    wire = next(s for s in planned["steps"] if s["performer"] == "robot")
    fresh = built(IEMA, tmp_path / "fresh")
    answer = _call(fresh, f"task={wire['task']}", "performer=human")
    assert answer["makespan_s_before"] == planned["summary"]["makespan_s"]
    assert [(m["key"], m["before"], m["after"]) for m in answer["moved"]] == [(wire["key"], "robot", "human")]
