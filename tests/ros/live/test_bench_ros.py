"""benchmarks/bench_ros.py --quick runs over real rclpy and the ROS answers equal the in-process ones."""

from __future__ import annotations

import os
import re
import subprocess
import sys

from tests.ros.live.conftest import ROOT


def test_bench_ros_quick_prints_a_table_of_equal_answers() -> None:
    # A domain of its own, apart from the other live tests' 1-100; DDS ports allow at most 232.
    env = {**os.environ, "ROS_DOMAIN_ID": str(101 + os.getpid() % 100)}
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_ros.py"), "--quick"],
        capture_output=True, text=True, timeout=300, check=False, cwd=ROOT, env=env,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr[-3000:]
    rows = re.findall(r"^\| `(\w+)` \| [\w-]+ \| 100 \|([^\n]*)\| (yes|differs) \|$", result.stdout, re.M)
    assert [(name, verdict) for name, _, verdict in rows] == [("cad_service", "yes"), ("cable_info", "yes")]
    for _, figures, _ in rows:
        p50_local, _, p50_ros = (float(v.replace(",", "")) for v in figures.split("|")[:3])
        assert 0 < p50_local < p50_ros  # a round trip costs more than the call it carries
