"""``cadkg progress``: what the cell did with a task, kept in the store as a change, across
rebuilds and renumbering revisions, seen by the plan and by the cursor services; every refused
input is one line, exit 2, and changes nothing."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from cadkg.generations import read_pointer
from cadkg.graph import KnowledgeGraph
from cadkg.plan.progress import read_progress
from cadkg.services.session import Session
from cadkg.services.table import call
from tests.changes.cells import MINI, copy_cell, edit
from tests.cli import run
from tests.conftest import ELVEZ, IEMA
from tests.plan.stores import built, copied


def _plan(store: Path) -> dict[str, Any]:
    done = run("plan", store, "--format", "json")
    assert done.returncode == 0, done.stderr
    return dict(json.loads(done.stdout))


def _steps(plan: dict[str, Any]) -> dict[str, dict[str, Any]]:
    return {s["key"]: s for s in plan["steps"]}


@pytest.fixture(scope="module")
def iema_store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built(IEMA, tmp_path_factory.mktemp("progress") / "iema")


def test_reports_are_kept_counted_and_a_failure_goes_to_a_person(iema_store: Path, tmp_path: Path) -> None:
    store = copied(iema_store, tmp_path / "iema")
    first = _plan(store)
    robot = [s["key"] for s in first["steps"] if s["performer"] == "robot"]
    assert first["summary"]["status"] == {"pending": 110, "started": 0, "done": 0, "failed": 0}
    assert {s["status"] for s in first["steps"]} == {"pending"}
    done, started, failed = robot[0], robot[1], robot[2]
    before = read_pointer(store)
    reported = run("progress", store, done, "done")
    assert reported.returncode == 0 and f"{done}: done (kept in the store)" in reported.stderr
    assert read_pointer(store) != before  # a change: a new generation
    assert run("progress", store, started, "started").returncode == 0
    # Its plan before the failure: what the robot does after it is re-planned around it.
    failing = run("progress", store, failed, "failed", "--reason", "screw head stripped")
    assert failing.returncode == 0 and "the plan refreshed around the tasks done" in failing.stderr
    plan = _plan(store)
    steps = _steps(plan)
    assert plan["summary"]["status"] == {"pending": 107, "started": 1, "done": 1, "failed": 1}
    assert [steps[t]["status"] for t in (done, started, failed)] == ["done", "started", "failed"]
    assert steps[failed]["performer"] == "human" and steps[failed]["rule"] == "failed"
    assert "screw head stripped" in steps[failed]["reason"] and "by cli" in steps[failed]["reason"]
    # The task done keeps its step, the one under way comes next; the rest is planned after.
    assert (steps[done]["step"], steps[started]["step"]) == (0, 1)
    assert steps[done]["performer"] == "robot" and "done (reported by cli" in steps[done]["placement"]
    assert plan["summary"]["robot"] == first["summary"]["robot"] - 1
    explained = run("plan", store, "--explain", failed)
    assert "failed: the robot reported it failed (screw head stripped" in explained.stdout
    # The connection providers hand out neither the wire done nor the one failed.
    with KnowledgeGraph.open(store) as kg:
        session = Session(kg.cell_model(), kg=kg)
        walked = []
        while not (answer := call(session, "group_connection_provider", {})).end:
            walked.append(answer.wire)
    label = {s["key"]: s["task"] for s in first["steps"]}
    assert len(walked) == len(robot) - 2
    assert sorted(walked) == sorted(label[k] for k in robot if k not in (done, failed))


def test_a_done_after_a_failed_is_done_by_the_person_the_failure_gave_it_to(
    iema_store: Path, tmp_path: Path
) -> None:
    store = copied(iema_store, tmp_path / "iema")
    task = next(s["key"] for s in _plan(store)["steps"] if s["performer"] == "robot")
    assert run("progress", store, task, "failed", "--reason", "would not seat").returncode == 0
    assert run("progress", store, task, "done", "--client", "bench-2").returncode == 0
    step = _steps(_plan(store))[task]
    assert step["status"] == "done" and step["step"] == 0
    assert step["performer"] == "human" and "would not seat" in step["reason"]
    assert "done (reported by bench-2" in step["placement"]
    with KnowledgeGraph.open(store) as kg:
        (report,) = read_progress(kg).values()
    assert (report.state, report.by, report.reason) == ("done", "bench-2", "")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("NO-SUCH-WIRE", "done"), "progress: no task 'NO-SUCH-WIRE' in the plan"),
        (
            ("1500.51", "finished"),
            "progress: unknown state 'finished'; expected one of started, done, failed",
        ),
        (("1500.51", "DONE"), "progress: unknown state 'DONE'"),
        (("1500.51", ""), "progress: unknown state ''"),
        (("", "done"), "progress: no task '' in the plan"),
        (("0V", "done"), "progress: '0V' names "),
    ],
)
def test_a_refused_report_is_one_line_and_changes_nothing(
    iema_store: Path, args: tuple[str, str], message: str
) -> None:
    before = read_pointer(iema_store)
    refused = run("progress", iema_store, *args)
    assert refused.returncode == 2
    assert refused.stderr.count("\n") == 1 and message in refused.stderr
    assert "Traceback" not in refused.stderr
    assert read_pointer(iema_store) == before


def test_a_report_on_a_manifest_or_a_missing_store_is_refused(tmp_path: Path) -> None:
    missing = run("progress", tmp_path / "nothing", "W1", "done")
    assert missing.returncode == 2 and "does not exist" in missing.stderr
    on_file = run("progress", IEMA, "1500.51", "done")
    assert on_file.returncode == 2 and "is a file" in on_file.stderr


def test_progress_is_kept_across_a_rebuild_and_a_renumbering_revision(tmp_path: Path) -> None:
    store = tmp_path / "mini"
    KnowledgeGraph.build(MINI / "manifest.toml", store).close()
    assert run("progress", store, "W1", "done").returncode == 0
    assert run("progress", store, "W2", "failed", "--reason", "stripped").returncode == 0
    # Rebuilt from the same files: kept (a rebuild starts without a plan; the next one sees them).
    assert run("build", MINI / "manifest.toml", "--store", store).returncode == 0
    steps = _steps(_plan(store))
    assert (steps["W1"]["status"], steps["W2"]["status"], steps["W3"]["status"]) == (
        "done",
        "failed",
        "pending",
    )
    assert steps["W2"]["performer"] == "human" and "stripped" in steps["W2"]["reason"]
    # Another revision renumbers W1 as W11 (same ends) and moves W2's origin: W11 is done; the
    # wire W2 is now other work, which its report does not speak of.
    manifest = copy_cell(MINI, tmp_path / "revised")
    edit(manifest.parent / "connections.tsv", "\tW1\t", "\tW11\t")
    edit(manifest.parent / "connections.tsv", "=-K1:13\t1\tQ\t=-X1:2:b", "=-K2:A1\t1\tQ\t=-X1:2:b")
    assert run("build", manifest, "--store", store).returncode == 0
    steps = _steps(_plan(store))
    assert steps["W11"]["status"] == "done" and "W1" not in steps
    assert steps["W2"]["status"] == "pending" and steps["W2"]["performer"] == "robot"
    with KnowledgeGraph.open(store) as kg:
        reports = read_progress(kg)
    assert sorted((r.label, r.state) for r in reports.values()) == [("W1", "done")]
    assert next(iter(reports)).endswith("wire/W11")


def test_operations_of_an_elvez_cell_are_reported_and_skipped(tmp_path: Path) -> None:
    store = tmp_path / "elvez"
    KnowledgeGraph.build(ELVEZ, store).close()
    plan = _plan(store)
    robot = [s for s in plan["steps"] if s["performer"] == "robot"]
    first, second = robot[0], robot[1]
    # By its label, and by its key.
    assert run("progress", store, first["task"], "done").returncode == 0
    failed = run("progress", store, second["key"], "failed", "--reason", "gripper lost the connector")
    assert failed.returncode == 0, failed.stderr
    steps = {s["key"]: s for s in _plan(store)["steps"]}
    assert steps[first["key"]]["status"] == "done" and steps[first["key"]]["step"] == 0
    assert steps[second["key"]]["performer"] == "human"
    assert "gripper lost the connector" in steps[second["key"]]["reason"]
    with KnowledgeGraph.open(store) as kg:
        session = Session(kg.cell_model(), kg=kg)
        handed = []
        while True:
            answer = call(session, "CAD_platform.next_operation", {})
            handed.append(answer.message)
            if answer.end:
                break
    skipped = (first["file_position"], second["file_position"])
    assert not any(m.startswith(f"operation {p} ") for m in handed for p in skipped)
    assert len(handed) == len(robot) - 2
