"""``cadkg plan`` on stores of the hand-made plan cabinet and the ELVEZ example, and the cursor
services following the stored plan."""

from __future__ import annotations

import csv
import io
import json
import shutil
from pathlib import Path

import pytest

from tests.cli import run
from tests.conftest import ROOT
from tests.test_cli_services import call

CABINET = ROOT / "tests" / "data" / "plan" / "cabinet"
ELVEZ = ROOT / "examples" / "elvez-cell"


def _store(source: Path, tmp_path: Path) -> Path:
    cell = tmp_path / "cell"
    shutil.copytree(source, cell)
    store = tmp_path / "store"
    result = run("build", cell / "manifest.toml", "--store", store)
    assert result.returncode == 0, result.stderr
    return store


@pytest.fixture(scope="module")
def cabinet(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return _store(CABINET, tmp_path_factory.mktemp("cabinet"))


def test_csv_has_exactly_the_columns_and_a_step_from_0(cabinet: Path) -> None:
    result = run("plan", cabinet, "--format", "csv")
    assert result.returncode == 0, result.stderr
    table = list(csv.reader(io.StringIO(result.stdout)))
    assert table[0] == ["step", "task", "kind", "performer", "tool", "reason"]
    assert [row[0] for row in table[1:]] == [str(n) for n in range(12)]
    assert [row[1] for row in table[1:3]] == ["W2", "W1"]
    assert "12 tasks: 6 robot, 6 person; tool changes" in result.stderr
    assert "2 broken by the files' order" in result.stderr


def test_json_adds_the_precedence_with_reasons(cabinet: Path) -> None:
    result = run("plan", cabinet, "--format", "json")
    data = json.loads(result.stdout)
    assert {"before": "W2", "after": "W1"}.items() <= data["precedence"][0].items()
    assert "approach of A1:Q" in data["precedence"][0]["reason"]
    assert data["summary"]["tasks"] == 12 and data["summary"]["filesPrecedenceViolations"] == 2
    assert data["steps"][0]["task"] == "W2" and data["steps"][0]["step"] == 0


def test_explain_says_who_and_why_here(cabinet: Path) -> None:
    result = run("plan", cabinet, "--explain", "W1")
    assert result.returncode == 0, result.stderr
    assert "W1 (wire) is step 1 of 12" in result.stdout
    assert "Comes after W2 (step 0): wire W1 landed on A1:P" in result.stdout
    missing = run("plan", cabinet, "--explain", "W99")
    assert missing.returncode == 2 and "no task 'W99'" in missing.stderr


def test_the_plan_is_a_named_graph_that_sparql_sees(cabinet: Path) -> None:
    run("plan", cabinet)
    ttl = run("plan", cabinet, "--format", "ttl").stdout
    assert "ck:PlannedTask" in ttl and "ck:PrecedenceEdge" in ttl
    result = run("query", cabinet, "plan-steps", "--format", "csv")
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader(io.StringIO(result.stdout)))
    assert [r["task"] for r in rows[:2]] == ["W2", "W1"] and rows[5]["performer"] == "human"


def test_the_connection_provider_follows_the_plan_and_skips_peoples_wires(cabinet: Path) -> None:
    run("plan", cabinet)
    run("call", cabinet, "reset_connection_list")
    wires = [call(cabinet, "group_connection_provider")["wire"] for _ in range(7)]
    assert wires == ["W2", "W1", "W4", "W3", "W5", "W11", ""]


def test_a_bad_rules_file_is_one_line_and_exit_2(cabinet: Path, tmp_path: Path) -> None:
    rules = tmp_path / "robot.toml"
    rules.write_text("[robot]\nzones = 3\n", encoding="utf-8")
    result = run("plan", cabinet, "--rules", rules)
    assert result.returncode == 2
    assert result.stderr.strip().count("\n") == 0 and "zones must be a list of strings" in result.stderr


def test_a_misspelt_setting_is_refused_not_left_at_its_default(cabinet: Path, tmp_path: Path) -> None:
    rules = tmp_path / "robot.toml"
    rules.write_text("[robot]\ncross_section_max = 1.0\n", encoding="utf-8")
    result = run("plan", cabinet, "--rules", rules)
    assert result.returncode == 2 and result.stderr.strip().count("\n") == 0
    assert "unknown key [robot] cross_section_max" in result.stderr
    assert "cross_section_max_mm2" in result.stderr  # the keys there are


def test_the_manifests_rules_are_kept_in_the_store(tmp_path: Path) -> None:
    cell = tmp_path / "cell"
    shutil.copytree(CABINET, cell)
    (cell / "robot.toml").write_text(
        '[robot]\nzones = ["Q", "B"]\n[[tool]]\nname = "any"\nserves = ["PUNTALINO_vite"]\n', encoding="utf-8"
    )
    with (cell / "manifest.toml").open("a", encoding="utf-8") as manifest:
        manifest.write('\n[plan]\nrules = "robot.toml"\n')
    store = tmp_path / "store"
    assert run("build", cell / "manifest.toml", "--store", store).returncode == 0
    result = run("plan", store, "--explain", "W7")
    assert "Who: robot" in result.stdout and "robot.toml (the manifest's [plan] rules)" in result.stderr


def test_next_operation_follows_the_elvez_plan(tmp_path: Path) -> None:
    store = _store(ELVEZ, tmp_path)
    result = run("plan", store, "--format", "csv")
    assert result.returncode == 0, result.stderr
    planned = [row[1] for row in list(csv.reader(io.StringIO(result.stdout)))[1:]]
    served = [call(store, "CAD_platform.next_operation") for _ in range(9)]
    assert [f"{s['type']} {'-'.join(s['label'])}" for s in served] == planned  # type: ignore[arg-type]
    assert served[-1]["end"] is True and planned[-2:] == ["TJ WH2", "T WH1"]


def test_a_cell_whose_use_case_makes_no_task_list_is_one_line() -> None:
    result = run("plan", ROOT / "examples" / "enki-hose" / "manifest.toml")
    assert (
        result.returncode == 2
        and result.stderr.strip() == "cadkg: error: the enki use case makes no task list"
    )


def test_solve_keeps_a_violation_free_plan_no_worse_than_the_greedy_one(cabinet: Path) -> None:
    pytest.importorskip("ortools")
    greedy = run("plan", cabinet, "--format", "json")
    solved = run("plan", cabinet, "--format", "json", "--solve", "1")
    assert greedy.returncode == 0 == solved.returncode, solved.stderr
    before, after = json.loads(greedy.stdout)["summary"], json.loads(solved.stdout)["summary"]
    assert (after["toolChanges"], after["travelM"]) <= (before["toolChanges"], before["travelM"])
    assert "none by the plan" in solved.stderr
    bad = run("plan", cabinet, "--solve", "-1")
    assert bad.returncode == 2 and "-1" in bad.stderr
