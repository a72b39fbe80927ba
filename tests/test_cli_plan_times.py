"""``cadkg plan``'s times, side by side lanes and balance, on hand-made cabinets whose figures
are worked by hand below; and the ``[time]`` values a rules file may not give."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from tests.cli import run
from tests.conftest import ROOT
from tests.test_cli_services import call

CABINET = ROOT / "tests" / "data" / "plan" / "cabinet"
HEADER = (
    "N. Pagina\tZona\tComponente:pin\tN. Pagina\tZona\tComponente:pin\tNumero filo\tSezione\tColore\t"
    "Tipo pot.\tNome pot.\tL filo (m)\tTraccia collegamenti\tTerminazione Origine\tTerminazione Destinazione"
)


def _rules(tmp_path: Path, text: str) -> Path:
    """A rules file of the screwdriver alone and ``text``: its other [time] keys the defaults."""
    rules = tmp_path / "robot.toml"
    rules.write_text(
        f'{text}\n[[tool]]\nname = "screwdriver"\nserves = ["PUNTALINO_vite"]\n', encoding="utf-8"
    )
    return rules


def _plan(*args: str | Path) -> dict[str, object]:
    result = run("plan", *args, "--format", "json")
    assert result.returncode == 0, result.stderr
    data: dict[str, object] = json.loads(result.stdout)
    return data


def _steps(data: dict[str, object]) -> dict[str, dict[str, object]]:
    return {str(s["task"]): s for s in data["steps"]}  # type: ignore[attr-defined]


@pytest.fixture(scope="module")
def blocked(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The plan cabinet (tests/data/plan/cabinet) stored, with every wire but W1 a person's."""
    tmp = tmp_path_factory.mktemp("blocked")
    shutil.copytree(CABINET, tmp / "cell")
    store = tmp / "store"
    assert run("build", tmp / "cell" / "manifest.toml", "--store", store).returncode == 0
    # W7, W9, W10 and W12 are already people's (the zone, no tool, no CAD label, the overlay).
    for wire in ("W2", "W3", "W4", "W5", "W6", "W8", "W11"):
        assert run("assign", store, "wire", wire, "human").returncode == 0
    return store


BLOCKING_RULES = """
[time]
robot_tool_change_s = 7
person_task_s = 50
[time.robot_class_s]
PUNTALINO_vite = 1000
"""


def test_a_persons_wire_that_blocks_a_robots_pin_delays_the_robots_lane(
    blocked: Path, tmp_path: Path
) -> None:
    """W1 lands on A1:P, whose exit runs through the approach of A1:Q: W2 (on A1:Q) comes first.
    W2 is a person's, W1 the robot's only wire.

    The person does the 11 people's wires in the plan's order, each ``person_task_s`` = 50 s;
    W2 is ready at once and first of them: 0 → 50 s, so the person's lane is 11 × 50 = 550 s.
    W1 (PUNTALINO_vite at both ends, 1000 s the class; one tool, so no change inside it; the
    robot's first task, so no change nor travel before it) waits for W2: 50 → 1050 s. Robot time
    1000 s, person time 550 s, makespan 1050 s: the robot's lane ends 50 s later than its work.
    """
    data = _plan(blocked, "--rules", _rules(tmp_path, BLOCKING_RULES))
    assert data["summary"] == {  # type: ignore[comparison-overlap]
        **data["summary"],  # type: ignore[dict-item]
        "tasks": 12,
        "robot": 1,
        "robot_time_s": 1000.0,
        "person_time_s": 550.0,
        "makespan_s": 1050.0,
    }
    steps = _steps(data)
    assert (steps["W2"]["start_s"], steps["W2"]["end_s"]) == (0.0, 50.0)
    assert (steps["W1"]["start_s"], steps["W1"]["end_s"]) == (50.0, 1050.0)
    explained = run("plan", blocked, "--rules", _rules(tmp_path, BLOCKING_RULES), "--explain", "W1").stdout
    assert "When: 50 s → 1050 s, in the robot's lane" in explained
    people = sorted(
        (s["start_s"], s["end_s"])  # type: ignore[type-var]
        for s in steps.values()
        if s["performer"] == "human"
    )
    assert people == [(50.0 * n, 50.0 * (n + 1)) for n in range(11)]


def test_the_stored_plan_answers_the_same_over_every_transport(blocked: Path, tmp_path: Path) -> None:
    made = _plan(blocked, "--rules", _rules(tmp_path, BLOCKING_RULES))
    answered = call(blocked, "plan")  # the operation HTTP's /api/plan and the ROS plan service serve
    assert answered["summary"] == made["summary"] and answered["steps"] == made["steps"]
    assert "time: robot 1000 s, person 550 s, makespan 1050 s side by side" in str(answered["message"])
    ttl = run("plan", blocked, "--rules", _rules(tmp_path, BLOCKING_RULES), "--format", "ttl").stdout
    assert 'ck:makespanS "1050"^^xsd:double' in ttl and 'ck:robotTimeS "1000"^^xsd:double' in ttl


def _three_wires(tmp_path: Path) -> Path:
    """Three wires between labels the ID table places, no scene: no positions, so no travel and
    no precedence; every end PUNTALINO_vite (the screwdriver: no tool change)."""
    cell = tmp_path / "three"
    cell.mkdir()
    (cell / "ids.wri").write_text("ID1\tK1\t100\nID2\tK2\t100\n", encoding="utf-8")
    rows = [
        f"1\tQ\t=-K1:{n}\t1\tQ\t=-K2:{n}\tR{n}\t0,75 mm²\tBU\t+\t24V\t0,3 m\t\tPUNTALINO_vite\tPUNTALINO_vite"
        for n in (1, 2, 3)
    ]
    (cell / "connections.tsv").write_text("\n".join([HEADER, *rows]) + "\n", encoding="utf-8")
    (cell / "manifest.toml").write_text(
        '[cell]\nname = "three wires"\nprofile = "iema"\nbase_iri = "https://example.org/cell/three/"\n\n'
        '[[source]]\npath = "ids.wri"\nkind = "wri"\n\n'
        '[[source]]\npath = "connections.tsv"\nkind = "connection-list"\n',
        encoding="utf-8",
    )
    return cell / "manifest.toml"


BALANCE_RULES = """
[time]
person_task_s = 150
[time.robot_class_s]
PUNTALINO_vite = 100
"""


def test_balance_moves_the_one_wire_that_shortens_the_makespan(tmp_path: Path) -> None:
    """R1, R2, R3 are the robot's, 100 s each (the class PUNTALINO_vite); a person takes 150 s.

    Unbalanced: the robot's lane 300 s, the person's empty: makespan 300 s. One wire moved: the
    robot 200 s, the person 150 s, makespan 200 s; two: 100 s and 300 s, makespan 300 s; three:
    450 s. So one wire moves, the first in the plan's order (R1: the three save the robot as
    much per second of a person), and the makespan is 100 s shorter.
    """
    manifest = _three_wires(tmp_path)
    rules = _rules(tmp_path, BALANCE_RULES)
    plain = _plan(manifest, "--rules", rules)
    assert (plain["summary"]["robot_time_s"], plain["summary"]["makespan_s"]) == (300.0, 300.0)  # type: ignore[index]
    balanced = _plan(manifest, "--rules", rules, "--balance")
    summary = balanced["summary"]
    assert (summary["robot"], summary["robot_time_s"], summary["person_time_s"]) == (2, 200.0, 150.0)  # type: ignore[index]
    assert (summary["makespan_s"], summary["unbalanced_makespan_s"]) == (200.0, 300.0)  # type: ignore[index]
    moved = [s for s in balanced["steps"] if s["rule"] == "balance"]  # type: ignore[attr-defined]
    assert [s["task"] for s in moved] == ["R1"] and moved[0]["performer"] == "human"
    assert "makespan 300 s → 200 s (100 s shorter) with 1 task moved" in moved[0]["reason"]
    assert "takes the robot 100 s, a person 150 s" in moved[0]["reason"]
    # The rules file's key does the same; --no-balance overrides it.
    keyed = _rules(tmp_path, BALANCE_RULES.replace("[time]\n", "[time]\nbalance = true\n"))
    assert _plan(manifest, "--rules", keyed)["summary"]["makespan_s"] == 200.0  # type: ignore[index]
    assert _plan(manifest, "--rules", keyed, "--no-balance")["summary"]["makespan_s"] == 300.0  # type: ignore[index]


def test_balance_moves_nothing_when_the_persons_lane_is_the_longer(tmp_path: Path) -> None:
    manifest = _three_wires(tmp_path)
    rules = _rules(tmp_path, BALANCE_RULES.replace("person_task_s = 150", "person_task_s = 400"))
    data = _plan(manifest, "--rules", rules, "--balance")
    # Moving one: robot 200 s, person 400 s: later than the robot's 300 s alone.
    assert data["summary"]["makespan_s"] == 300.0 and "unbalanced_makespan_s" not in data["summary"]  # type: ignore[index,operator]
    assert not [s for s in data["steps"] if s["rule"] == "balance"]  # type: ignore[attr-defined]


@pytest.mark.parametrize(
    ("text", "words"),
    [
        ("[time]\nperson_task_s = -5\n", "[time] person_task_s must be a non-negative number, not -5"),
        ('[time]\nrobot_tool_change_s = "ten"\n', "[time] robot_tool_change_s must be a non-negative number"),
        ("[time]\nrobot_speed_m_s = 0\n", "[time] robot_speed_m_s must be a positive number, not 0"),
        ("[time]\nperson_task_s = true\n", "[time] person_task_s must be a non-negative number, not True"),
        ("[time]\nperson_second_s = 5\n", "unknown key [time] person_second_s; expected one of:"),
        (
            "[time.robot_class_s]\nPUNTALINO_vite = -1\n",
            "[time.robot_class_s] PUNTALINO_vite must be a non-negative",
        ),
        ('[time]\nbalance = "yes"\n', "[time] balance must be true or false, not 'yes'"),
        ("[time]\nrobot_class_s = 3\n", "[time] robot_class_s must be a table"),
        ("time = 3\n", "'time' must be a table [time]"),
    ],
)
def test_a_bad_time_is_one_line_naming_the_file_and_key_and_exit_2(
    tmp_path: Path, text: str, words: str
) -> None:
    rules = _rules(tmp_path, text)
    result = run("plan", _three_wires(tmp_path), "--rules", rules)
    assert result.returncode == 2
    assert result.stderr.strip().count("\n") == 0, result.stderr
    assert f"{rules}: " in result.stderr and words in result.stderr


def test_a_task_the_cell_has_done_is_timed_first_and_a_balance_moves_another(tmp_path: Path) -> None:
    """The three wires of the test above, R1 reported done: it keeps the robot's first 100 s,
    and the balance, which may not move it, moves R2 instead (robot R1 and R3: 200 s, a person
    R2: 150 s; makespan 300 s → 200 s)."""
    store = tmp_path / "store"
    built = run("build", _three_wires(tmp_path), "--store", store)
    assert built.returncode == 0, built.stderr
    rules = _rules(tmp_path, BALANCE_RULES)
    r1 = str(next(s["key"] for s in _plan(store, "--rules", rules)["steps"] if s["task"] == "R1"))  # type: ignore[attr-defined]
    assert run("progress", store, "R1", "done").returncode == 0
    balanced = _plan(store, "--rules", rules, "--balance")
    steps = _steps(balanced)
    assert steps["R1"]["key"] == r1 and steps["R1"]["status"] == "done"
    assert (steps["R1"]["step"], steps["R1"]["performer"], steps["R1"]["start_s"], steps["R1"]["end_s"]) == (
        0,
        "robot",
        0.0,
        100.0,
    )
    assert [t for t, s in steps.items() if s["rule"] == "balance"] == ["R2"]
    summary = balanced["summary"]
    assert (summary["makespan_s"], summary["unbalanced_makespan_s"]) == (200.0, 300.0)  # type: ignore[index]
    assert summary["status"] == {"pending": 2, "started": 0, "done": 1, "failed": 0}  # type: ignore[index]
