"""benchmarks/bench_build.py --quick runs end to end and reports every runnable named query."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from tests.conftest import ROOT

# A benchmark's smoke run: the script itself, at a size, in a new interpreter.
pytestmark = pytest.mark.slow


def test_bench_build_quick_prints_its_tables() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_build.py"), "--quick"],
        capture_output=True, text=True, timeout=300, check=False, cwd=ROOT,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr[-3000:]
    out = result.stdout
    # The triples of the 1k-wire cell (the ontology's 1,464 with them): the build's, and the same
    # again loaded by themselves.
    assert len(re.findall(r"^\| 1,000 \| 38,122 \|", out, re.M)) == 2
    throughput = re.search(r"two processes running the reference loop at once do (\d+\.\d\d)× the work", out)
    assert throughput is not None
    # The overlap floor is worked out from the two halves timed alone in table 2.
    floor = re.search(r"^\| 1,000 \| 38,122 \| [\d.]+ \| [\d.]+ \| ([\d.]+) \|", out, re.M)
    halves = re.search(r"^\| 1,000 \| 38,122 \| \d+ \| ([\d.]+) \| ([\d.]+) \|", out, re.M)
    assert floor is not None and halves is not None
    python_side, load = map(float, halves.groups())
    two_cores = min(float(throughput.group(1)), 2.0)
    expected = max((python_side + load) / two_cores, python_side, load)
    assert abs(float(floor.group(1)) - expected) <= 0.02
    rows = dict(re.findall(r"^\| 1,000 \| ([\w-]+) \| [^|]* \| (\d+) \|", out, re.M))
    # The cabinet queries with their row counts on the seeded cell; the other profiles'
    # queries without parameters run and find nothing in a cabinet.
    assert rows["connections-in-order"] == "1000"
    assert rows["components"] == "270"
    assert rows["elvez-plan"] == "0"
    assert "harness-wires-of-connector" not in rows  # needs a connector this cell has none of


def test_bench_build_cabinet_builds_the_complete_cabinet() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_build.py"), "--quick", "--cabinet", "--no-rdflib"],
        capture_output=True, text=True, timeout=300, check=False, cwd=ROOT,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr[-3000:]
    out = result.stdout
    assert out.startswith("Built: the complete synthetic cabinet")
    # The 1k-wire cabinet's triples, derived graph included: the build's, and the same again
    # when the Python side's output is loaded by itself.
    assert len(re.findall(r"^\| 1,000 \| 218,269 \|", out, re.M)) == 2
    rows = dict(re.findall(r"^\| 1,000 \| ([\w-]+) \| [^|]* \| (\d+) \|", out, re.M))
    assert rows["connections-in-order"] == "1000"
    assert rows["components"] == "362"
