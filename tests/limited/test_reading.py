"""A real input file read under a CPU-time limit it cannot meet: the build stops in one line
naming the file, and the store stays as it was."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

import cadkg
from tests.cli import CADKG
from tests.conftest import IEMA, ROOT, run_capped, synthetic_manifest

# A 250k-wire cell is generated and read to pass the read's CPU-time limit.
pytestmark = pytest.mark.slow

# Its wire list and connection list (some 35 MiB) take seconds of CPU each to read.
WIRES = 250_000


def _live(store: Path) -> str:
    return (store / "CURRENT").read_text().strip()


def test_a_file_past_the_cpu_limit_stops_the_build_and_keeps_the_store(tmp_path: Path) -> None:
    store = tmp_path / "store"
    cadkg.build(IEMA, store).close()
    live = _live(store)
    with cadkg.open_store(store) as before:
        quads = len(before)
    manifest = synthetic_manifest(tmp_path / "cell", WIRES, cabinet=False)
    # Both its files (the wire list and the connection list) take more than a second to read.
    sources = [manifest.parent / "ids.wri", manifest.parent / "lista-cablaggio.csv"]
    env = {**os.environ, "CADKG_READ_CPU_S": "1"}
    result = run_capped([*CADKG, "build", str(manifest), "--store", str(store)], cwd=ROOT, cap=600, env=env)
    assert result.returncode == 2, (result.stdout, result.stderr)
    lines = result.stderr.strip().splitlines()
    assert lines in [
        [f"cadkg: error: {source}: needs more than 1 s of CPU time to read (limit set by CADKG_READ_CPU_S)"]
        for source in sources
    ], lines
    assert _live(store) == live
    with cadkg.open_store(store) as after:
        assert len(after) == quads
