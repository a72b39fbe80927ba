"""benchmarks/bench_reopen.py runs end to end and prints one row per size."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT

# A benchmark's smoke run: the script itself, at a size, in a new interpreter.
pytestmark = pytest.mark.slow


def test_bench_reopen_prints_a_row_per_size() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_reopen.py"), "--sizes", "200,300", "--reps", "1"],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    rows = [
        line.split("|")[1:-1]
        for line in result.stdout.splitlines()
        if line.startswith("| 2") or line.startswith("| 3")
    ]
    assert [row[0].strip() for row in rows] == ["200", "300"]
    for row in rows:
        kept_mib, kept_s, extract_s = (float(row[i]) for i in (3, 4, 5))
        assert kept_mib > 0 and kept_s > 0 and extract_s > 0
        assert row[7].strip().endswith("×")
        assert float(row[8]) > 0  # placements
