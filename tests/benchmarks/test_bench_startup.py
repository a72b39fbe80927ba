"""benchmarks/bench_startup.py runs end to end and prints one row per command, with its ratio."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT


@pytest.mark.slow
def test_bench_startup_prints_a_row_per_command() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_startup.py"), "--runs", "1"],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    rows = {
        cells[0].strip(): cells[1:]
        for cells in (line.split("|")[1:-1] for line in result.stdout.splitlines() if line.startswith("| "))
        if cells[0].strip() not in ("command", "")
    }
    assert list(rows) == [
        "baseline: import pyoxigraph, click",
        "import cadkg",
        "cadkg --help",
        "cadkg kinds",
        "cadkg call",
    ]
    for cells in rows.values():
        assert float(cells[0]) > 0
        assert cells[1].strip().endswith("×") and float(cells[1].strip()[:-1]) > 0
    assert rows["baseline: import pyoxigraph, click"][1].strip() == "1.0×"
    assert rows["import cadkg"][2].strip() == "≤ 3×"
    assert rows["cadkg call"][2].strip() == "≤ 6×"
