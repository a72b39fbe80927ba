"""``validate(kg, progress=...)`` and ``cadkg validate`` tell how far they are, stage by stage."""

from __future__ import annotations

import os
import subprocess
import sys

import cadkg
from cadkg.query.validate import validate
from tests.conftest import BAD, ROOT


def test_validate_reports_its_stages_in_order(iema: cadkg.KnowledgeGraph) -> None:
    steps: list[tuple[str, int, int]] = []
    assert validate(iema, progress=lambda *step: steps.append(step)) == []
    assert [s for s in steps if s[0] == "checks"] == [("checks", 1, 3), ("checks", 2, 3), ("checks", 3, 3)]
    shapes = [s for s in steps if s[0] == "shapes"]
    assert steps[:3] == [s for s in steps if s[0] == "checks"]  # the checks come first
    total = shapes[-1][2]
    assert total > 1 and shapes == [("shapes", n, total) for n in range(1, total + 1)]
    steps.clear()
    validate(iema, shacl=False, progress=lambda *step: steps.append(step))
    assert {s[0] for s in steps} == {"checks"}


def test_the_command_shows_the_stages_on_a_terminal() -> None:
    # rich draws the bar when it takes stderr for a terminal; FORCE_COLOR makes it so in a pipe.
    result = subprocess.run(
        [sys.executable, "-m", "cadkg.cli", "validate", str(BAD)],
        capture_output=True, text=True, cwd=ROOT, check=False, timeout=300,
        env={**os.environ, "FORCE_COLOR": "1"},
    )  # fmt: skip
    assert result.returncode == 1
    assert "checks" in result.stderr and "shapes" in result.stderr
    assert "connections.tsv:6: error" in result.stdout  # findings stay on stdout, undisturbed
