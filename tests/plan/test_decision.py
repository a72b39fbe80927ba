"""The one decision of who does a task: the order of its rules, whatever the use case."""

from __future__ import annotations

import json

import pytest

from cadkg.plan.decision import ASSIGNED, Assignments, Decision, Performer, decide

TASK = ("wire", "W1")
PARTS = (("component", "K1"), ("component", "K2"))


def _outside(task: object) -> Decision:
    return Decision(Performer.HUMAN, "zone", "zone P is outside")


def _too_thick(task: object) -> Decision:
    return Decision(Performer.HUMAN, "cross-section", "too thick")


def _no_tool(task: object) -> Decision:
    return Decision(Performer.HUMAN, "termination", "no tool")


def _lets_through(task: object) -> None:
    return None


def test_the_performers_are_the_words_of_the_files_and_the_json() -> None:
    assert [p.value for p in Performer] == ["robot", "human"]
    assert json.dumps({"performer": Performer.HUMAN}) == '{"performer": "human"}'
    assert f"{Performer.ROBOT}" == "robot" and Performer("human") is Performer.HUMAN


def test_an_assignment_of_the_task_wins_over_every_rule() -> None:
    assigned = Assignments({TASK: "robot"})
    decision = decide(None, assigned, (TASK,), scope=_outside, parts=PARTS, abilities=(_too_thick,))
    assert decision == Decision(
        Performer.ROBOT, ASSIGNED, "wire W1 assigned to the robot by hand; wins over the rules"
    )


def test_the_first_name_assigned_decides() -> None:
    assigned = Assignments({("operation", "3"): "human", TASK: "robot"})
    decision = decide(None, assigned, (("operation", "3"), TASK))
    assert decision.reason.startswith("operation 3 assigned to a person")


def test_the_scope_rule_comes_before_a_parts_assignment_and_the_abilities() -> None:
    assigned = Assignments({("component", "K1"): "robot"})
    decision = decide(None, assigned, (TASK,), scope=_outside, parts=PARTS, abilities=(_too_thick,))
    assert (decision.performer, decision.rule) == (Performer.HUMAN, "zone")


def test_a_part_given_to_a_person_gives_the_task_to_a_person() -> None:
    assigned = Assignments({("component", "K1"): "robot", ("component", "K2"): "human"})
    decision = decide(None, assigned, (TASK,), scope=_lets_through, parts=PARTS, abilities=(_too_thick,))
    # The first part assigned names the reason; any part a person's makes it a person's.
    assert decision == Decision(
        Performer.HUMAN, ASSIGNED, "component K1 assigned to a person by hand; wins over the rules"
    )


def test_a_part_given_to_the_robot_skips_the_abilities() -> None:
    assigned = Assignments({("component", "K2"): "robot"})
    decision = decide(None, assigned, (TASK,), parts=PARTS, abilities=(_too_thick,))
    assert (decision.performer, decision.rule) == (Performer.ROBOT, ASSIGNED)


def test_the_abilities_are_asked_in_turn_and_the_robot_does_the_rest() -> None:
    none = Assignments()
    assert decide(None, none, (TASK,), abilities=(_lets_through, _no_tool, _too_thick)).rule == "termination"
    assert decide(None, none, (TASK,), abilities=(_lets_through,)) == Decision(Performer.ROBOT)


def test_assignments_are_found_by_kind_and_id_from_the_iris_the_graph_holds() -> None:
    performers = {"b:wire/W1": "human", "b:component/K1": "robot", "b:wire/other": "robot"}
    found = Assignments.of_targets(performers, [TASK, ("component", "K1"), ("wire", "W2")], "b:{}/{}".format)
    assert (found.get(*TASK), found.get("component", "K1"), found.get("wire", "W2")) == (
        Performer.HUMAN,
        Performer.ROBOT,
        None,
    )
    assert len(found) == 2


def test_an_unknown_performer_is_refused() -> None:
    with pytest.raises(ValueError):
        Assignments({TASK: "someone"})
