"""Runs tests/ros/live with real rclpy in .venv-ros, and reports each of its tests here.

``bash scripts/setup.sh --test`` (the test command's set-up) makes .venv-ros with
scripts/ros-setup.sh before the tests start; nothing is installed or compiled here. The test
is skipped only when that script found the ROS wheels cannot be installed on this machine (no
network, no Python 3.11/3.12); a set-up that was not run, or failed otherwise, fails here.
The live run has its own time cap, generous for a loaded 2-core machine, and is killed with
its whole process group (nodes, colcon, cmake) when it runs over.

The nested run happens once: started by a session on several workers beside them, or for the
first test of this module (:mod:`tests.ros.nested`); each test here is one test
function of tests/ros/live (its parametrized cases together) and passes, fails or skips as it
did there, so a failure names the live test and shows its own report.
"""

from __future__ import annotations

import ast
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from tests.conftest import ROOT
from tests.ros import nested as live_run
from tests.ros.nested import FAILED, PYTHON

pytestmark = pytest.mark.live

CANNOT_INSTALL = ("pip install of the pinned ros-jazzy wheels", "no python3", "cannot create", "needs ")
LIVE = ROOT / "tests" / "ros" / "live"


def _live_tests() -> list[str]:
    """``module::function`` of every test function of tests/ros/live, read from the source, so
    that collecting this module needs no ROS."""
    found = []
    for path in sorted(LIVE.glob("test_*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        found += [
            f"{path.stem}::{node.name}"
            for node in tree.body
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef) and node.name.startswith("test_")
        ]
    return found


@pytest.fixture(scope="module")
def nested(tmp_path_factory: pytest.TempPathFactory) -> dict[str, list[tuple[str, str]]]:
    """The live run's outcomes: per ``module::function``, ``(outcome, report)`` of each case."""
    if FAILED.is_file():
        line = FAILED.read_text(encoding="utf-8").strip()
        if any(reason in line for reason in CANNOT_INSTALL):
            pytest.skip(f"ROS 2 wheels cannot be installed on this machine: {line}")
        pytest.fail(line)
    if not PYTHON.is_file():
        pytest.fail(".venv-ros is missing: run 'bash scripts/setup.sh --test' (the test command does)")
    report, output, code = live_run.outcome(tmp_path_factory.mktemp("ros-live"))
    if not report.is_file():
        pytest.fail(f"the live ROS run wrote no report (exit {code}):\n{output[-6000:]}")
    return _outcomes(report)


def _outcomes(report: Path) -> dict[str, list[tuple[str, str]]]:
    outcomes: dict[str, list[tuple[str, str]]] = {}
    for case in ET.parse(report).getroot().iter("testcase"):
        module = case.get("classname", "").rpartition(".")[2]
        function = case.get("name", "").partition("[")[0]
        found = [child for child in case if child.tag in ("failure", "error", "skipped")]
        outcome = found[0].tag if found else "passed"
        text = "\n".join(f"{child.get('message', '')}\n{child.text or ''}" for child in found)
        outcomes.setdefault(f"{module}::{function}", []).append((outcome, text))
    return outcomes


@pytest.mark.parametrize("name", _live_tests())
def test_live(name: str, nested: dict[str, list[tuple[str, str]]]) -> None:
    cases = nested.get(name)
    assert cases, f"the live ROS run did not report {name}"
    failed = [text for outcome, text in cases if outcome in ("failure", "error")]
    assert failed == [], f"{name}: {len(failed)} of {len(cases)} failed:\n" + "\n".join(failed)[-6000:]
    if all(outcome == "skipped" for outcome, _ in cases):
        pytest.skip(cases[0][1].strip().splitlines()[0] if cases[0][1].strip() else "skipped in the live run")


def test_the_live_run_reported_only_tests_of_its_files(nested: dict[str, list[tuple[str, str]]]) -> None:
    # A test the source scan misses (a class, a generated name) would pass unseen.
    assert sorted(set(nested) - set(_live_tests())) == []
