"""Nothing lost: ``cadkg progress`` killed with SIGKILL at every named step of its change (a
failure, which re-plans in the same generation) leaves the store as before the report or as
after it, the plan with it; two clients reporting at once both have their reports kept."""

from __future__ import annotations

import shutil
import signal
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cadkg.generations import KILL_AT, read_pointer
from cadkg.graph import KnowledgeGraph
from cadkg.plan.cell import store_plan
from cadkg.plan.graph import cell_base, read_plan
from cadkg.plan.progress import read_progress
from tests.changes.cells import MINI
from tests.security.test_atomic_kill import BEFORE, STEPS, _cadkg, _finish

REPORT = ("W2", "failed", "--reason", "screw head stripped")


def _state(store: Path) -> tuple[tuple[tuple[str, str, str], ...], tuple[tuple[str, str], ...]]:
    """(each report's task, state and text; each plan step's task and performer, in order)."""
    with KnowledgeGraph.open(store) as kg:
        reports = tuple(sorted((r.label, r.state, r.reason) for r in read_progress(kg).values()))
        plan = read_plan(kg, cell_base(kg))
        assert plan is not None
        return reports, tuple((s.key, s.performer) for s in plan.steps)


@pytest.fixture(scope="module")
def stores(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Path, Any, Any]]:
    """A planned store, and the state before and after the report."""
    root = tmp_path_factory.mktemp("progress-kill")
    store = root / "store"
    with KnowledgeGraph.build(MINI / "manifest.toml", store) as kg:
        store_plan(kg)
    before = _state(store)
    done = root / "done"
    shutil.copytree(store, done)
    code, err = _finish(_cadkg("progress", done, *REPORT))
    assert code == 0, err
    after = _state(done)
    assert before[0] == () and after[0] == (("W2", "failed", "screw head stripped"),)
    assert ("W2", "robot") in before[1] and ("W2", "human") in after[1]
    yield store, before, after


@pytest.mark.slow  # a new process killed at each of six steps
@pytest.mark.parametrize("step", STEPS)
def test_progress_killed_at_each_step_leaves_the_store_before_or_after(
    stores: tuple[Path, Any, Any], tmp_path: Path, step: str
) -> None:
    store, before, after = stores
    copy = tmp_path / "store"
    shutil.copytree(store, copy)
    code, err = _finish(_cadkg("progress", copy, *REPORT, env={KILL_AT: step}))
    assert code == -signal.SIGKILL, err
    assert _state(copy) == (before if step in BEFORE else after)
    # What the killed change left behind goes with the next one, which then lands whole.
    code, err = _finish(_cadkg("progress", copy, *REPORT))
    assert code == 0, err
    assert _state(copy) == after


def test_two_clients_reporting_at_once_both_have_their_reports_kept(
    stores: tuple[Path, Any, Any], tmp_path: Path
) -> None:
    store, _, _ = stores
    copy = tmp_path / "store"
    shutil.copytree(store, copy)
    live = read_pointer(copy)
    first = _cadkg("progress", copy, "W1", "done", "--client", "arm-1")
    second = _cadkg("progress", copy, *REPORT, "--client", "arm-2")
    for process in (first, second):
        code, err = _finish(process)
        assert code == 0, err
    assert read_pointer(copy) != live
    with KnowledgeGraph.open(copy) as kg:
        reports = sorted((r.label, r.state, r.by) for r in read_progress(kg).values())
    assert reports == [("W1", "done", "arm-1"), ("W2", "failed", "arm-2")]
    # The failure re-planned, in whichever order the two landed.
    assert ("W2", "human") in _state(copy)[1]
