"""What killed builds and servers leave in a store directory: removed by the next successful
build, unless a live process holds it."""

from __future__ import annotations

import contextlib
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

import cadkg
from cadkg.generations import claim
from tests.cli import CADKG
from tests.conftest import IEMA, ROOT, synthetic_manifest

HOLD = "import sys, time; from pathlib import Path; from cadkg.generations import claim; " \
    "held = claim(Path(sys.argv[1])); print('held', flush=True); time.sleep(600)"  # fmt: skip


def _entries(store: Path) -> list[str]:
    return sorted(p.name for p in store.iterdir())


def _live(store: Path) -> str:
    return (store / "CURRENT").read_text().strip()


def _kept(store: Path) -> list[str]:
    """What a store directory holds after a rebuild: the live generation and the one before it."""
    return sorted(["CURRENT", "PREVIOUS", _live(store), (store / "PREVIOUS").read_text().strip()])


def test_a_build_killed_midway_is_removed_by_the_next(tmp_path: Path) -> None:
    store = tmp_path / "store"
    manifest = synthetic_manifest(tmp_path / "cell", 20_000, cabinet=False)
    cadkg.build(IEMA, store).close()
    first = _live(store)
    process = subprocess.Popen(
        [*CADKG, "build", str(manifest), "--store", str(store)],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 120
        while not any(p.is_dir() and p.name != first for p in store.glob("gen-*")):
            assert process.poll() is None, "the build ended before it could be killed"
            assert time.monotonic() < deadline, "the build wrote no generation"
            time.sleep(0.02)
        time.sleep(0.3)
    finally:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait(30)
    left = [name for name in _entries(store) if name.startswith("gen-") and name != first]
    assert len(left) == 1 and _live(store) == first  # what kill -9 leaves, the store intact

    cadkg.build(IEMA, store).close()
    assert _entries(store) == _kept(store)


def test_a_generation_a_live_process_holds_is_kept(tmp_path: Path) -> None:
    store = tmp_path / "store"
    cadkg.build(IEMA, store).close()
    building = store / "gen-20990101T000000-5ee1ab1e"  # another build, still writing
    building.mkdir()
    (building / "000008.sst").write_bytes(b"being written")
    dead = store / "gen-20200101T000000-dead0000"  # one whose build was killed
    dead.mkdir()
    (store / f".CURRENT.{dead.name}").write_text(dead.name + "\n")
    abandoned = store / ".snapshot-0123456789ab"  # the query workers' copy of a killed server
    abandoned.mkdir()
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(building)], cwd=ROOT, stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        cadkg.build(IEMA, store).close()
        assert _entries(store) == sorted([*_kept(store), building.name, f".{building.name}.lock"])
    finally:
        holder.kill()
        holder.wait(30)
    cadkg.build(IEMA, store).close()
    assert _entries(store) == _kept(store)


def test_a_claim_is_exclusive_and_released(tmp_path: Path) -> None:
    entry = tmp_path / "gen-x"
    held = claim(entry)
    assert held is not None
    assert claim(entry, wait=False) is None
    held.release()
    again = claim(entry, wait=False)
    assert again is not None
    again.release()
    assert list(tmp_path.iterdir()) == []


def test_a_killed_servers_memory_snapshot_is_removed_by_the_next(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, iema: cadkg.KnowledgeGraph
) -> None:
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    left = tmp_path / "cadkg-snapshot-0123456789ab"  # a server killed by SIGKILL left it
    (left / "store").mkdir(parents=True)
    held = tmp_path / "cadkg-snapshot-ba9876543210"  # another live server's
    (held / "store").mkdir(parents=True)
    holder = subprocess.Popen(
        [sys.executable, "-c", HOLD, str(held)], cwd=ROOT, stdout=subprocess.PIPE, text=True
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "held"
        snapshot = iema.snapshot()
        try:
            assert snapshot.path.parent.parent == tmp_path
            assert not left.exists() and held.exists()
        finally:
            snapshot.remove()
        assert not snapshot.path.exists()
    finally:
        holder.kill()
        holder.wait(30)
    # The killed holder's lock stays with its snapshot, both for the next sweep.
    assert sorted(p.name for p in tmp_path.iterdir()) == [f".{held.name}.lock", held.name]


OPEN = "import sys, time; import pyoxigraph as ox; store = ox.Store(sys.argv[1]); " \
    "print('open', flush=True); time.sleep(float(sys.argv[2]))"  # fmt: skip


@pytest.mark.slow
def test_a_change_waits_for_the_process_that_holds_the_live_database(tmp_path: Path) -> None:
    """A build keeps the generation it published open until its command ends; a change started
    right after it opens the store once it is let go, not with an error."""
    store = tmp_path / "store"
    cadkg.build(IEMA, store).close()
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            OPEN,
            str(store / _live(store)),
            "8",
        ],  # longer than the command takes to start
        stdout=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        assert holder.stdout is not None and holder.stdout.readline().strip() == "open"
        done = subprocess.run(
            [*CADKG, "assign", str(store), "wire", "1500.51", "human"],
            cwd=ROOT,
            capture_output=True,
            text=True,
            timeout=600,
            check=False,
        )
        assert done.returncode == 0 and "→ human" in done.stderr, done.stderr
        assert holder.poll() is not None  # it waited for the holder to end
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(holder.pid, signal.SIGKILL)
        holder.wait(30)
