"""benchmarks/bench_plan.py --quick plans a synthetic cabinet and prints its row."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT

# A benchmark's smoke run: the script itself, at a size, in a new interpreter.
pytestmark = pytest.mark.slow


def test_bench_plan_quick_prints_a_violation_free_row() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_plan.py"), "--quick"],
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr[-3000:]
    # The order table's row, then the times' row.
    row, times = [line.split("|")[1:-1] for line in result.stdout.splitlines() if line.startswith("| 300 |")]
    cells = [cell.strip() for cell in row]
    build, plan = float(cells[1]), float(cells[2])
    assert build > 0 and plan > 0
    robot, tasks = (int(n) for n in cells[4].split("/"))
    assert tasks == 300 and 0 < robot < tasks
    changes, files_changes, bound = int(cells[6]), int(cells[7]), int(cells[8])
    assert bound <= changes <= files_changes
    assert float(cells[11]) <= float(cells[12])  # travel: plan against the list's order
    assert cells[15] == "0"  # the plan breaks no precedence
    hours = [float(cell.strip().replace(",", "")) for cell in times[1:]]
    robot_h, person_h, makespan, moved, balanced = hours[0], hours[1], hours[2], hours[3], hours[6]
    assert makespan >= max(robot_h, person_h) and moved > 0
    assert balanced < makespan < hours[7]  # balanced, unbalanced, the robot then the person
