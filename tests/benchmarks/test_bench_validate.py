"""benchmarks/bench_validate.py --quick validates a clean synthetic cell and prints its row."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT

# A benchmark's smoke run: the script itself, at a size, in a new interpreter.
pytestmark = pytest.mark.slow


def test_bench_validate_quick_prints_a_clean_row() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_validate.py"), "--quick"],
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr[-3000:]
    (row,) = [line.split("|")[1:-1] for line in result.stdout.splitlines() if line.startswith("| 300 |")]
    cells = [cell.strip() for cell in row]
    build, semantic, shacl, total = (float(cells[i]) for i in (2, 3, 4, 5))
    # Printed to the hundredth of a second: the compiled shapes on 300 wires may print 0.00.
    assert build > 0 and min(semantic, shacl) >= 0
    assert abs(total - (build + semantic + shacl)) <= 0.02
    # The generator writes a clean cell: no findings, and no unknown label or pin without data.
    assert cells[6] == "0"
    assert cells[10].endswith("×")
    wire_ends = 300  # one row per wire of the cell, from either engine alike
    assert cells[11] == f"0/{wire_ends}/0"
