"""Nothing lost: ``cadkg assign`` killed with SIGKILL at every named step of its change, and at
random moments, leaves the store as before the change or as after it (the derived graph whole,
every assignment as it was or as asked); an assign during a build waits for it and lands in the
generation the build makes; ``cadkg validate`` calls a derived graph gone missing an error.

The named steps are :func:`cadkg.generations.crash_point`'s (``CADKG_KILL_AT``): the process
kills itself there with SIGKILL, exactly as ``kill -9`` would.
"""

from __future__ import annotations

import os
import random
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pyoxigraph as ox
import pytest

from cadkg.generations import CURRENT, GENERATION, KILL_AT, PREVIOUS, read_pointer
from cadkg.graph import KnowledgeGraph
from tests.conftest import IEMA, ROOT

# Builds and changes killed at every step and at random moments, each in a new process.
pytestmark = pytest.mark.slow

WIRE = "1500.51"
BASE = "https://example.org/cell/iema-qe01/"
STEPS = (
    "change:copied",
    "change:applied",
    "change:derived",
    "publish:pointer-written",
    "publish:renamed",
    "change:published",
)
# Cut short before CURRENT names the new generation: as before; after: as after.
BEFORE = {"change:copied", "change:applied", "change:derived", "publish:pointer-written"}
CAP = 600  # seconds for one command on a loaded 2-core machine; it takes a few


def _cadkg(*args: str | Path, env: dict[str, str] | None = None) -> subprocess.Popen[str]:
    return subprocess.Popen(
        [sys.executable, "-m", "cadkg.cli", *map(str, args)],
        cwd=ROOT,
        env={**os.environ, **(env or {})},
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def _finish(process: subprocess.Popen[str]) -> tuple[int, str]:
    try:
        _, err = process.communicate(timeout=CAP)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        raise
    return process.returncode, err


def _state(store: Path) -> tuple[tuple[str, ...], list[str], str]:
    """(the derived graph as sorted N-Triples, who each assignment in the store names, who
    makes the wire in the cell model the store keeps)."""
    with KnowledgeGraph.open(store) as kg:
        (performer,) = {s.performer for s in kg.cell_model().steps if s.wire == WIRE}
        derived = tuple(sorted(str(q.triple) for q in kg.graph_quads(BASE + "derived")))
        who = kg.query(
            "SELECT ?who WHERE { GRAPH ?g { ?a ck:assignmentOf ?w ; ck:assignedTo ?who }"
            " ?w ck:wireNumber ?n }",
            g=ox.NamedNode(BASE + "assignments"),
            n=WIRE,
        )
        return derived, [str(r["who"]).rsplit("#", 1)[-1] for r in who], performer


@pytest.fixture(scope="module")
def stores(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Path, Any, Any]]:
    """A built store, and the state before and after assigning WIRE to a person."""
    root = tmp_path_factory.mktemp("atomic")
    store = root / "store"
    KnowledgeGraph.build(IEMA, store).close()
    before = _state(store)
    done = root / "done"
    shutil.copytree(store, done)
    code, err = _finish(_cadkg("assign", done, "wire", WIRE, "human"))
    assert code == 0, err
    after = _state(done)
    assert before[1:] == ([], "robot") and after[1:] == (["human"], "human")
    # The derived graph holds the poses (17,445 triples); who makes a wire is not among them.
    assert len(before[0]) > 10_000 and before[0] == after[0]
    assert not any("_:" in triple for triple in before[0] + after[0])  # compared as text
    yield store, before, after


def _either(store: Path, before: Any, after: Any) -> str:
    state = _state(store)
    assert state in (before, after), (len(state[0]), state[1])
    return "before" if state == before else "after"


@pytest.mark.parametrize("step", STEPS)
def test_assign_killed_at_each_step_leaves_the_store_before_or_after(
    stores: tuple[Path, Any, Any], tmp_path: Path, step: str
) -> None:
    store, before, after = stores
    copy = tmp_path / "store"
    shutil.copytree(store, copy)
    code, err = _finish(_cadkg("assign", copy, "wire", WIRE, "human", env={KILL_AT: step}))
    assert code == -signal.SIGKILL, err
    assert _either(copy, before, after) == ("before" if step in BEFORE else "after")
    # What the killed change left behind goes with the next one, which then lands whole.
    code, err = _finish(_cadkg("assign", copy, "wire", WIRE, "human"))
    assert code == 0, err
    assert _state(copy) == after
    # Left: the live generation and the one before it, which 'cadkg diff STORE' compares.
    kept = {read_pointer(copy), read_pointer(copy, PREVIOUS)}
    assert {p.name for p in copy.iterdir() if p.name.startswith(GENERATION)} == kept and len(kept) == 2


def test_assign_killed_at_random_moments_leaves_the_store_before_or_after(
    stores: tuple[Path, Any, Any], tmp_path: Path
) -> None:
    store, before, after = stores
    rng = random.Random(34)
    seen = []
    for attempt in range(8):
        copy = tmp_path / f"store-{attempt}"
        shutil.copytree(store, copy)
        process = _cadkg("assign", copy, "wire", WIRE, "human")
        # The command starts in 1-3 s on a busy machine and changes the store for a few more.
        time.sleep(rng.uniform(0.5, 6.0))
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        seen.append(_either(copy, before, after))
        shutil.rmtree(copy)
    assert seen  # every one of them before or after; which, depends on the machine's speed


def test_an_assign_during_a_build_waits_and_lands_in_the_new_generation(
    stores: tuple[Path, Any, Any], tmp_path: Path
) -> None:
    store, _, after = stores
    for attempt in range(2):
        copy = tmp_path / f"store-{attempt}"
        shutil.copytree(store, copy)
        live = read_pointer(copy)
        build = _cadkg("build", IEMA, "--store", copy)
        deadline = time.monotonic() + CAP
        # Once the build's generation exists, the build holds the writer lock.
        while not any(p.name.startswith(GENERATION) and p.name != live for p in copy.iterdir()):
            assert build.poll() is None and time.monotonic() < deadline, "the build ended before it was seen"
            time.sleep(0.05)
        assign = _cadkg("assign", copy, "wire", WIRE, "human")
        code, err = _finish(assign)
        assert code == 0 and "→ human" in err, err
        code, err = _finish(build)
        assert code == 0, err
        assert read_pointer(copy) != live  # the build published
        assert _state(copy) == after  # and the assignment is in what it published


def _validate(store: Path) -> subprocess.CompletedProcess[str]:
    command = [sys.executable, "-m", "cadkg.cli", "validate", str(store)]
    return subprocess.run(command, capture_output=True, text=True, cwd=ROOT, timeout=CAP, check=False)


def test_validate_calls_a_missing_derived_graph_an_error(
    stores: tuple[Path, Any, Any], tmp_path: Path
) -> None:
    store, _, _ = stores
    copy = tmp_path / "store"
    shutil.copytree(store, copy)
    clean = _validate(copy)
    assert "derived-graph" not in clean.stdout + clean.stderr
    # What a derivation cut between its removal and its load left before it was one transaction.
    with KnowledgeGraph.open(copy, read_only=False) as kg:
        kg._store.remove_graph(ox.NamedNode(BASE + "derived"))
    broken = _validate(copy)
    assert broken.returncode == 1, broken.stdout + broken.stderr
    assert "derived graph" in broken.stdout and "[derived-graph]" in broken.stdout
    assert (copy / CURRENT).is_file()
