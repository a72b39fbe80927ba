"""The robot's task list of a hand-made cabinet whose right order is known
(tests/data/plan/cabinet: a pin in front of another along its approach, a two-level terminal,
two pins each in the other's way) and a wire for every rule that hands work to a person."""

from __future__ import annotations

from pathlib import Path

import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.plan.cell import plan_cell
from cadkg.plan.order import Plan
from cadkg.plan.rules import RulesError
from tests.conftest import ROOT

CABINET = ROOT / "tests" / "data" / "plan" / "cabinet" / "manifest.toml"


@pytest.fixture(scope="module")
def kg() -> KnowledgeGraph:
    return KnowledgeGraph.build(CABINET)


@pytest.fixture(scope="module")
def plan(kg: KnowledgeGraph) -> Plan:
    return plan_cell(kg)


def _at(plan: Plan, wire: str) -> int:
    step = plan.step_of(wire)
    assert step is not None
    return step.index


def test_a_pin_in_front_of_another_along_its_approach_comes_after_it(plan: Plan) -> None:
    # W1 lands on A1:P, whose wire runs down through the approach of A1:Q (W2).
    assert _at(plan, "W2") < _at(plan, "W1")
    edge = next(e for e in plan.precedence if (e.before, e.after) == ("W2", "W1"))
    assert "A1:P" in edge.reason and "approach of A1:Q" in edge.reason and "mm" in edge.reason


def test_the_level_nearer_the_rail_comes_first_when_the_other_blocks_it(plan: Plan) -> None:
    assert _at(plan, "W4") < _at(plan, "W3")
    assert any((e.before, e.after) == ("W4", "W3") and "X1:1:a" in e.reason for e in plan.precedence)


def test_a_cycle_gives_one_wire_to_a_person_and_the_plan_breaks_no_edge(plan: Plan) -> None:
    given = plan.step_of("W6")
    assert given is not None and given.decision.performer == "human"
    assert given.decision.rule == "precedence-cycle" and "W6 → W5 → W6" in given.decision.reason
    assert plan.step_of("W5").decision.performer == "robot"  # type: ignore[union-attr]
    assert {(e.before, e.after) for e in plan.dropped} == {("W5", "W6"), ("W6", "W5")}
    assert plan.measure.violations == 0 and plan.files.violations == 2


@pytest.mark.parametrize(
    ("wire", "performer", "rule", "words"),
    [
        ("W7", "human", "zone", "origin zone B is not among the robot zones Q, QE (the default [derive]"),
        ("W8", "human", "cross-section", "6 mm²"),
        ("W9", "human", "termination", "FASTON"),
        ("W10", "human", "label-not-in-cad", "M9 is not in the CAD"),
        ("W11", "robot", "missing-pin-data", "S2:99"),
        ("W12", "human", "assigned", "wins over the rules"),
        ("W2", "robot", "robot", "screwdriver"),
    ],
)
def test_every_rule_says_why(plan: Plan, wire: str, performer: str, rule: str, words: str) -> None:
    decision = plan.step_of(wire).decision  # type: ignore[union-attr]
    assert (decision.performer, decision.rule) == (performer, rule)
    assert words in decision.reason


def test_explicit_assignment_wins_over_the_rules(tmp_path: Path) -> None:
    kg = KnowledgeGraph.build(CABINET, tmp_path / "store")
    kg.assign("wire", "W7", "robot")  # outside the zones, yet the robot's by hand
    decision = plan_cell(kg).step_of("W7").decision  # type: ignore[union-attr]
    assert (decision.performer, decision.rule) == ("robot", "assigned")
    kg.close()


def test_the_zones_are_the_cells_own_as_the_providers_use_them(tmp_path: Path) -> None:
    # One rule: the manifest's [derive] robot_zones decide for the plan as for the services.
    text = CABINET.read_text(encoding="utf-8").replace('path = "', f'path = "{CABINET.parent}/')
    manifest = tmp_path / "manifest.toml"
    manifest.write_text(text + '\n[derive]\nrobot_zones = ["Q", "P"]\n', encoding="utf-8")
    kg = KnowledgeGraph.build(manifest)
    step = next(s for s in kg.cell_model().steps if s.wire == "W7")
    decision = plan_cell(kg).step_of("W7").decision  # type: ignore[union-attr]
    assert (decision.performer, decision.rule) == (step.performer, "zone") == ("human", "zone")
    assert decision.reason == f"{step.reason} (the manifest's [derive] robot_zones)"
    assert "robot zones P, Q" in decision.reason


def test_a_rules_file_changes_the_decisions(kg: KnowledgeGraph, tmp_path: Path) -> None:
    rules = tmp_path / "robot.toml"
    rules.write_text(
        '[robot]\nzones = ["Q", "B"]\nmissing_pin_data = "human"\ncross_section_max_mm2 = 10\n'
        '[[tool]]\nname = "gun"\nserves = ["PUNTALINO_vite", "ELETTROSALDATO_molla", "FASTON"]\n',
        encoding="utf-8",
    )
    plan = plan_cell(kg, rules)
    rules_of = {w: plan.step_of(w).decision.rule for w in ("W7", "W8", "W9", "W11")}  # type: ignore[union-attr]
    assert rules_of == {"W7": "robot", "W8": "robot", "W9": "robot", "W11": "missing-pin-data"}
    assert plan.step_of("W11").decision.performer == "human"  # type: ignore[union-attr]
    # The rules' zones replace the cell's for the plan, and say whose they are.
    rules.write_text(
        '[robot]\nzones = ["Q", "P"]\nlabel_not_in_cad = "robot"\n'
        '[[tool]]\nname = "screwdriver"\nserves = ["PUNTALINO_vite"]\n',
        encoding="utf-8",
    )
    plan = plan_cell(kg, rules)
    assert plan.step_of("W7").decision.reason.endswith(f"(the zones of {rules})")  # type: ignore[union-attr]
    w10 = plan.step_of("W10").decision  # type: ignore[union-attr]
    assert (w10.performer, w10.rule) == ("robot", "missing-pin-data") and "M9:U1" in w10.reason
    assert plan.lower_bound == 0 and plan.measure.tool_changes == 0


def test_a_malformed_rules_file_is_one_line_naming_it(kg: KnowledgeGraph, tmp_path: Path) -> None:
    rules = tmp_path / "bad.toml"
    rules.write_text("[robot]\nclearance_m = -1\n", encoding="utf-8")
    with pytest.raises(RulesError, match=r"bad\.toml: \[robot\] clearance_m must be a non-negative"):
        plan_cell(kg, rules)
    rules.write_text("[robot\n", encoding="utf-8")
    with pytest.raises(RulesError, match=r"bad\.toml: .*line 1"):
        plan_cell(kg, rules)


def test_the_same_store_gives_the_same_plan(kg: KnowledgeGraph, plan: Plan) -> None:
    again = plan_cell(kg)
    assert [(s.task.key, s.decision, s.why_here) for s in again.steps] == [
        (s.task.key, s.decision, s.why_here) for s in plan.steps
    ]


def test_the_example_cabinet_has_a_complete_violation_free_plan() -> None:
    kg = KnowledgeGraph.build(ROOT / "examples" / "iema-switchgear" / "manifest.toml")
    plan = plan_cell(kg)
    assert len(plan.steps) == len(kg.cell_model().steps)
    assert plan.measure.violations == 0 and plan.precedence
    assert plan.measure.tool_changes <= plan.files.tool_changes
    assert plan.lower_bound <= plan.measure.tool_changes
    by_hand = {
        s.task.label: s.decision.reason.split(" assigned")[0]
        for s in plan.steps
        if s.decision.rule == "assigned"
    }
    assert by_hand["0050.01"] == "component S0050.1" and by_hand["SSB10.08"] == "operation 93"
    assert len(by_hand) == 7


def test_validate_warns_of_the_lists_order_at_its_lines(kg: KnowledgeGraph) -> None:
    from cadkg.query.validate import validate

    found = {f.location: f.message for f in validate(kg, shacl=False) if f.check == "iema-order"}
    assert set(found) == {"connections.tsv:2", "connections.tsv:4", "connections.tsv:6"}
    assert found["connections.tsv:2"].startswith("W1 comes before W2 (connections.tsv:3)")
