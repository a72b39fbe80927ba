"""The ELVEZ plan: the example's sequence checked and reordered, and broken sequences whose
faults ``cadkg validate`` finds at their lines (a route before its connector is placed, a
taping before its routing, a missing guide)."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.plan.cell import plan_cell
from cadkg.query.validate import Finding, validate
from tests.conftest import ROOT

EXAMPLE = ROOT / "examples" / "elvez-cell"
HEADER = "Order;Type of operation;Label;Spot\n"


def _cell(tmp_path: Path, rows: list[str]) -> KnowledgeGraph:
    copy = tmp_path / "cell"
    shutil.copytree(EXAMPLE, copy)
    (copy / "Assembly_sequence.csv").write_text(HEADER + "".join(r + "\n" for r in rows), encoding="utf-8")
    return KnowledgeGraph.build(copy / "manifest.toml")


def _order(kg: KnowledgeGraph) -> list[Finding]:
    return [f for f in validate(kg, shacl=False) if f.check == "elvez-order"]


@pytest.fixture(scope="module")
def example(elvez: KnowledgeGraph) -> KnowledgeGraph:
    return elvez  # built once per session (tests/conftest.py)


def test_the_example_sequence_breaks_no_precedence_and_the_plan_groups_the_tools(
    example: KnowledgeGraph,
) -> None:
    assert _order(example) == []
    plan = plan_cell(example)
    assert [s.task.label for s in plan.steps][:2] == ["EC WH1", "PC WH1"]
    assert plan.files.tool_changes == 3 and plan.measure.tool_changes == 1 == plan.lower_bound
    assert plan.measure.violations == 0 and all(s.decision.performer == "robot" for s in plan.steps)
    # the gripper holds a connector from its comb to its jig: nothing comes between
    for n, step in enumerate(plan.steps):
        if step.task.kind == "EC":
            assert plan.steps[n + 1].task.kind == "PC" and "right after" in plan.steps[n + 1].why_here
    reasons = {(e.before, e.after): e.reason for e in plan.precedence}
    assert "placed (PC) before its branches are routed" in reasons[("op2", "op3")]
    assert "routed through J1.1, J2.1 before it is taped there" in reasons[("op3", "op5")]


def test_a_route_before_its_connector_is_placed_is_an_error_at_its_line(tmp_path: Path) -> None:
    kg = _cell(
        tmp_path, ["1;EC;WH1;C1.1.L", "2;RC;GR11;J1.1-J2.1-J3.1", "3;PC;WH1;J4.1.L", "4;RC;GR12;J1.1-J3.2"]
    )
    found = _order(kg)
    assert [(f.location.rsplit("/", 1)[-1], f.severity) for f in found if "comes before" in f.message] == [
        ("Assembly_sequence.csv:3", "error")
    ]
    assert any("does not come right after EC WH1" in f.message for f in found)
    plan = plan_cell(kg)
    assert [s.task.label for s in plan.steps] == ["EC WH1", "PC WH1", "RC GR11", "RC GR12"]
    assert plan.files.violations == 2 and plan.measure.violations == 0


def test_a_taping_before_its_routing_is_an_error_and_the_plan_moves_it(tmp_path: Path) -> None:
    rows = [
        "1;EC;WH1;C1.1.L",
        "2;PC;WH1;J4.1.L",
        "3;T;WH1;J1.1-J2.1",
        "4;RC;GR11;J1.1-J2.1-J3.1",
        "5;RC;GR12;J1.1-J3.2",
    ]
    kg = _cell(tmp_path, rows)
    found = [f for f in _order(kg) if f.severity == "error"]
    assert {f.location.rsplit("/", 1)[-1] for f in found} == {"Assembly_sequence.csv:4"}
    assert "T WH1 comes before RC GR11" in found[0].message
    plan = plan_cell(kg)
    assert plan.steps[-1].task.label == "T WH1" and plan.measure.violations == 0


def test_a_missing_guide_sends_the_operation_to_a_person_and_notes_the_unrouted_branch(
    tmp_path: Path,
) -> None:
    kg = _cell(tmp_path, ["1;EC;WH1;C1.1.L", "2;PC;WH1;J4.1.L", "3;RC;GR11;J1.1-J2.9", "4;RC;GR11;J1.1-J2.1"])
    plan = plan_cell(kg)
    missing = plan.step_of("op3")
    assert missing is not None and missing.decision.performer == "human"
    assert missing.decision.rule == "unresolved" and "J2 has no guide 9" in missing.decision.reason
    notes = [f.message for f in _order(kg) if f.severity == "warning"]
    assert "branch GR11 of WH1 is routed 2 times (3, 4)" in notes
    assert "branch GR12 of WH1 is not routed by the sequence" in notes


def test_an_operation_assigned_to_a_person_in_an_assignments_file_says_so(tmp_path: Path) -> None:
    copy = tmp_path / "cell"
    shutil.copytree(EXAMPLE, copy)
    (copy / "assignments.csv").write_text("kind,id,performer\noperation,5,human\n", encoding="utf-8")
    with (copy / "manifest.toml").open("a", encoding="utf-8") as manifest:
        manifest.write('\n[[source]]\npath = "assignments.csv"\nkind = "assignments"\n')
    plan = plan_cell(KnowledgeGraph.build(copy / "manifest.toml"))
    taping = plan.step_of("op5")
    assert taping is not None and taping.decision.performer == "human" and taping.decision.rule == "assigned"
    assert "operation 5 assigned to a person by hand" in taping.decision.reason
