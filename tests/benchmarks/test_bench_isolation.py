"""benchmarks/bench_isolation.py runs end to end: every query answered alike in process and in a
worker (the script asserts it), a row each, and a runaway stopped."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT

# A benchmark's smoke run: the script itself, at a size, in a new interpreter.
pytestmark = pytest.mark.slow


def test_bench_isolation_prints_a_row_per_query() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_isolation.py"), "--sizes", "300", "--reps", "2"],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    rows = {line.split("|")[1].strip(): line for line in result.stdout.splitlines() if line.startswith("| ")}
    assert {"components", "select-10000-rows", "ask"} <= set(rows)
    assert "stopped and its worker killed after" in result.stdout
