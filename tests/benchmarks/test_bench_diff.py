"""benchmarks/bench_diff.py --quick diffs two 300-wire cabinets and finds the changes planted."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT

# A benchmark's smoke run: the script itself, at a size, in a new interpreter.
pytestmark = pytest.mark.slow


def test_bench_diff_quick_finds_the_planted_changes() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_diff.py"), "--quick"],
        capture_output=True, text=True, timeout=900, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr[-3000:]
    assert "(3 wires and 1 components changed)" in result.stdout
    rows = [line.split("|")[1:-1] for line in result.stdout.splitlines() if line.startswith("| 300 | 1 |")]
    (row, median) = rows  # the run, then the medians
    cells = [cell.strip() for cell in row]
    build, diff = float(cells[3]), float(cells[4])
    assert build > 0 and diff > 0 and cells[5].endswith("×")
    assert float(cells[7].replace(",", "")) > 0
    assert cells[8] == "changed 1 component, 2 file, 3 wire"
    assert median[-1].strip() in ("met", "**not met**")
