"""CP-SAT's order (``cadkg plan --solve``) where the greedy order is known to travel too far:
nearest-neighbour from the first listed task on a line, with a person's task between."""

from __future__ import annotations

import pytest

from cadkg.plan.decision import Decision, Performer
from cadkg.plan.order import make_plan
from cadkg.plan.tasks import Precedence, Problem, Task

pytest.importorskip("ortools")


def _problem(person: bool = False) -> Problem:
    # Points on a line, listed from x = 0: the greedy order goes 0, 0.1, 0.3, then back to
    # -0.15 (0.75 m); starting at the far end 0.3 it is 0.45 m, the shortest.
    xs = {"A": 0.0, "B": 0.1, "C": -0.15, "D": 0.3}
    points = {k: (x, 0.0, 0.0) for k, x in xs.items()}
    tasks = [Task(k, k, "wire", n, ("t",), p, p) for n, (k, p) in enumerate(points.items())]
    decisions = {k: Decision(Performer.ROBOT, "default", "the robot's") for k in xs}
    edges = [Precedence("D", "C", "D blocks C")]
    if person:
        tasks.append(Task("P", "P", "wire", 4))
        decisions["P"] = Decision(Performer.HUMAN, "zone", "a person's")
        edges += [Precedence("B", "P", "B before P"), Precedence("P", "A", "P before A")]
    return Problem(tasks, decisions, edges)


def test_the_solver_finds_the_shorter_order_and_says_so() -> None:
    greedy = make_plan(_problem())
    assert [s.task.key for s in greedy.steps] == ["A", "B", "D", "C"]
    assert greedy.measure.travel == pytest.approx(0.75)
    solved = make_plan(_problem(), solver_budget=1.0)
    assert [s.task.key for s in solved.steps] == ["D", "B", "A", "C"]
    assert solved.measure.travel == pytest.approx(0.45) and solved.measure.violations == 0
    assert solved.measure.tool_changes == greedy.measure.tool_changes == 0
    why = solved.steps[0].why_here
    assert why.startswith("in the solver's order") and "travel 0.45 m instead of 0.75 m" in why
    again = make_plan(_problem(), solver_budget=1.0)
    assert [s.task.key for s in again.steps] == [s.task.key for s in solved.steps]


def test_people_s_tasks_keep_the_robot_s_precedence_through_them() -> None:
    # B before the person's P before A: the solver's robot order keeps B before A.
    plan = make_plan(_problem(person=True), solver_budget=1.0)
    keys = [s.task.key for s in plan.steps]
    assert plan.measure.violations == 0 and plan.measure.travel == pytest.approx(0.45)
    assert keys.index("B") < keys.index("P") < keys.index("A")
    assert plan.step_of("P").why_here.startswith("a person's task")  # type: ignore[union-attr]


def test_without_a_budget_the_plan_is_the_greedy_one() -> None:
    assert make_plan(_problem()).steps[0].why_here.startswith("starts with")
