"""``benchmarks/load_http.py --quick``: clients, named queries and a reload under load, no error."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from tests.conftest import ROOT

# A benchmark's smoke run: the script itself, at a size, in a new interpreter.
pytestmark = pytest.mark.slow


def test_quick_load_run_has_no_errors_and_serves_both_generations() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "load_http.py"), "--quick"],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert result.returncode == 0, result.stdout[-4000:] + result.stderr[-2000:]
    out = result.stdout
    assert re.search(r"^OK: [\d,]+ requests, 0 errors$", out, re.MULTILINE)
    overall = out.split("#### Overall", 1)[1].splitlines()
    requests, errors = (cell.strip() for cell in overall[4].strip("|").split("|")[:2])
    assert int(requests.replace(",", "")) > 20 and errors == "0"
    reload_row = out.split("#### Reload under load", 1)[1].splitlines()[4]
    cells = [cell.strip() for cell in reload_row.strip("|").split("|")]
    by_old, by_new = int(cells[2].replace(",", "")), int(cells[3].replace(",", ""))
    assert by_old > 0 and by_new > 0
    assert cells[5] == "0"
    assert "reloaded gen-" in out  # the server's own log line of the switch
    # Every query the synthetic cell can answer was issued, with rows from the cell.
    assert "| pins-of-component | label=" in out
    assert "| connections-in-order |  | 1000 |" in out
