"""benchmarks/bench_page.py --quick runs end to end: a 300-wire cabinet in headless Chromium,
drawn three ways, and 10,000 result rows paged and not."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from tests.conftest import ROOT

# The page benchmark drives Chromium.
pytestmark = pytest.mark.live


def test_bench_page_quick_prints_its_tables() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_page.py"), "--quick"],
        capture_output=True, text=True, timeout=600, check=False, cwd=ROOT,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr[-3000:]
    out = result.stdout
    row = r"^\| ([a-z ]+) \| \d+ \| \d+ \| \d+ \| [\d.]+ \| [\d.]+ \| ([\d,]+) \|"
    drawn = dict(re.findall(row, out, re.M))
    assert set(drawn) == {"merged", "instanced", "one mesh per object"}
    # Merged: the objects in one geometry and the wires in another.
    assert drawn["merged"] == "2" and int(drawn["one mesh per object"].replace(",", "")) > 200
    rows = dict(re.findall(r"^\| (paged \(100 rows\)|all rows in the page) \| \d+ \| ([\d,]+) \|", out, re.M))
    assert rows == {"paged (100 rows)": "100", "all rows in the page": "10,000"}
