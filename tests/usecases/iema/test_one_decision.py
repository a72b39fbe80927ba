"""One decision, three consumers: the cursors that hand the robot its wires, the planner
(``cadkg plan``) and ``cadkg validate`` say the same of every wire of a cabinet, who makes it
and why, for the IEMA examples, the plan cabinet and a synthetic cabinet."""

from __future__ import annotations

from collections import Counter
from pathlib import Path

import pytest

import cadkg
import cadkg.usecases.iema.cursors as cursors
from cadkg.graph import KnowledgeGraph
from cadkg.plan.cell import plan_cell, store_plan
from cadkg.plan.decision import ASSIGNED, Decision, Performer
from cadkg.query.validate import validate
from cadkg.services.session import Session
from cadkg.usecases.iema.derive.cabinet import WireStep
from cadkg.usecases.iema.robot_scope import LABEL_RULE, ZONE_RULE
from tests.conftest import IEMA, IEMA_FIG3, ROOT, synthetic_manifest

# The rules the cell itself decides by, before the robot's abilities (a rules file's) are asked.
CELL_RULES = {ASSIGNED, ZONE_RULE, LABEL_RULE}
CELLS = {"example": IEMA, "fig3": IEMA_FIG3, "plan-cabinet": ROOT / "tests/data/plan/cabinet/manifest.toml"}
_PREFIX = "wire "
_GIVEN = " is given to a person: "


def _manifest(name: str, tmp_path_factory: pytest.TempPathFactory) -> Path:
    if name == "synthetic":
        return synthetic_manifest(tmp_path_factory.mktemp("synthetic"), 120, cabinet=True)
    return CELLS[name]


@pytest.fixture(scope="module", params=[*CELLS, "synthetic"])
def cell(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory) -> KnowledgeGraph:
    """A cabinet built in memory, with no plan stored: tests must not change it."""
    return cadkg.build(_manifest(request.param, tmp_path_factory))


def _handed(kg: KnowledgeGraph) -> list[tuple[str, int]]:
    """The wires (number, list position) the cursor hands the robot, in its order."""
    session = Session(kg.cell_model(), kg)
    handed = []
    while not (wire := cursors.group_connection_provider(session)).end:
        handed.append((wire.wire, wire.list_position))
    return handed


def _planned(kg: KnowledgeGraph) -> list[tuple[WireStep, Decision]]:
    """Every wire of the cell with the planner's decision on it."""
    steps = kg.cell_model().steps
    return [(steps[s.task.position], s.decision) for s in plan_cell(kg).steps]


def _for_people(kg: KnowledgeGraph) -> Counter[tuple[str, str]]:
    """(wire number, reason) of each wire ``cadkg validate`` says a rule gave to a person."""
    found: Counter[tuple[str, str]] = Counter()
    for finding in validate(kg, shacl=False):
        if finding.check == "wire-for-a-person":
            number, reason = finding.message.removeprefix(_PREFIX).split(_GIVEN, 1)
            found[(number, reason)] += 1
    return found


def test_the_cursors_hand_the_robot_what_the_planner_lets_the_cell_give_it(cell: KnowledgeGraph) -> None:
    planned = _planned(cell)
    assert len(planned) == len(cell.cell_model().steps)
    # Without a stored plan the cursor follows the cell's rules alone: a wire the robot's
    # abilities give to a person is still handed out until `cadkg plan` stores the plan.
    expected = Counter(
        (step.wire, step.position)
        for step, decision in planned
        if decision.performer is Performer.ROBOT or decision.rule not in CELL_RULES
    )
    assert Counter(_handed(cell)) == expected


def test_validate_reports_the_planners_cabinet_rule_decisions_with_their_reason(cell: KnowledgeGraph) -> None:
    found = _for_people(cell)
    ruled = [(step, d) for step, d in _planned(cell) if d.rule in (ZONE_RULE, LABEL_RULE)]
    assert all(d.performer is Performer.HUMAN for _, d in ruled)
    assert sum(found.values()) == len(ruled)
    for step, decision in ruled:
        # The planner says where the rule came from around the reason validate gives.
        assert [r for n, r in found if n == step.wire and r in decision.reason], (step.wire, decision)


def test_the_cursors_follow_the_stored_plans_robot_wires(tmp_path_factory: pytest.TempPathFactory) -> None:
    for name in [*CELLS, "synthetic"]:
        kg = cadkg.build(_manifest(name, tmp_path_factory))
        stored = store_plan(kg)
        robot = [(s.label, s.position) for s in stored.steps if s.performer == Performer.ROBOT]
        steps = kg.cell_model().steps
        assert [(w, p) for w, p in _handed(kg)] == [(w, steps[n].position) for w, n in robot], name
