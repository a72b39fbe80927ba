"""The core's order: precedence first, then fewest tool changes, then least travel; cycles
broken by giving one task to a person; the same problem gives the same plan."""

from __future__ import annotations

from cadkg.plan.decision import ASSIGNED, Decision, Performer
from cadkg.plan.order import CYCLE, make_plan
from cadkg.plan.tasks import Precedence, Problem, Task

ROBOT_OK = Decision(Performer.ROBOT, "default", "the robot's by default")


def _task(key: str, position: int, tool: str = "a", x: float = 0.0) -> Task:
    return Task(key, key, "wire", position, (tool,), (x, 0.0, 0.0), (x, 0.0, 0.0))


def _problem(tasks: list[Task], edges: list[tuple[str, str]] = ()) -> Problem:  # type: ignore[assignment]
    return Problem(
        tasks,
        {t.key: ROBOT_OK for t in tasks},
        [Precedence(a, b, f"{a} blocks {b}") for a, b in edges],
    )


def _keys(problem: Problem) -> list[str]:
    return [s.task.key for s in make_plan(problem).steps]


def test_tools_are_grouped_and_the_bound_is_met() -> None:
    tasks = [_task("A", 0, "x"), _task("B", 1, "y"), _task("C", 2, "x"), _task("D", 3, "y")]
    plan = make_plan(_problem(tasks))
    assert plan.files.tool_changes == 3
    assert plan.measure.tool_changes == 1 == plan.lower_bound
    assert [s.task.key for s in plan.steps] == ["A", "C", "B", "D"]


def test_precedence_wins_over_tools_and_travel() -> None:
    tasks = [_task("A", 0, "x", 0.0), _task("B", 1, "x", 1.0), _task("C", 2, "x", 0.1)]
    assert _keys(_problem(tasks)) == ["A", "C", "B"]
    plan = make_plan(_problem(tasks, [("B", "C")]))
    assert [s.task.key for s in plan.steps] == ["A", "B", "C"]
    assert plan.measure.violations == 0
    assert make_plan(_problem(tasks, [("C", "A")])).files.violations == 1


def test_nearest_next_task_is_taken() -> None:
    tasks = [_task("A", 0, x=0.0), _task("B", 1, x=0.9), _task("C", 2, x=0.2), _task("D", 3, x=0.5)]
    plan = make_plan(_problem(tasks))
    assert [s.task.key for s in plan.steps] == ["A", "C", "D", "B"]
    assert plan.measure.travel < plan.files.travel
    assert "mm from the previous end" in plan.steps[1].why_here


def test_a_cycle_gives_one_task_to_a_person_and_says_why() -> None:
    tasks = [_task("A", 0), _task("B", 1), _task("C", 2)]
    plan = make_plan(_problem(tasks, [("A", "B"), ("B", "A"), ("B", "C")]))
    people = [s for s in plan.steps if s.decision.performer == Performer.HUMAN]
    assert len(people) == 1 and people[0].decision.rule == CYCLE
    assert "precedence cycle" in people[0].decision.reason
    assert len(plan.dropped) >= 1 and plan.measure.violations == 0


def test_an_assigned_task_is_not_the_one_given_away() -> None:
    tasks = [_task("A", 0), _task("B", 1)]
    problem = _problem(tasks, [("A", "B"), ("B", "A")])
    problem.decisions["B"] = Decision(Performer.ROBOT, ASSIGNED, "assigned to the robot with cadkg assign")
    plan = make_plan(problem)
    assert plan.step_of("A").decision.performer == Performer.HUMAN  # type: ignore[union-attr]
    assert plan.step_of("B").decision.performer == Performer.ROBOT  # type: ignore[union-attr]


def test_the_same_problem_gives_the_same_plan() -> None:
    tasks = [_task(f"T{i}", i, "xy"[i % 2], (i * 7919) % 13 / 10) for i in range(40)]
    edges = [(f"T{i}", f"T{i + 3}") for i in range(0, 36, 5)]
    first, second = make_plan(_problem(tasks, edges)), make_plan(_problem(list(reversed(tasks)), edges))
    assert [s.task.key for s in first.steps] == [s.task.key for s in second.steps]


def test_the_nearest_next_task_is_the_nearest_of_all() -> None:
    # Scattered over a cabinet's plate, some far apart (past the rings the grid looks at first).
    import math
    import random

    rng = random.Random(5)
    points = [(rng.uniform(0, 3), rng.uniform(0, 2), rng.uniform(0, 0.1)) for _ in range(300)]
    points += [(rng.uniform(10, 12), rng.uniform(10, 12), 0.0) for _ in range(5)]
    tasks = [Task(f"T{i}", f"T{i}", "wire", i, ("a",), p, p) for i, p in enumerate(points)]
    planned = [s.task.position for s in make_plan(_problem(tasks)).steps]
    expected, left = [0], set(range(1, len(points)))
    while left:
        here = points[expected[-1]]
        nearest = min(left, key=lambda i: (math.dist(here, points[i]), i))
        expected.append(nearest)
        left.remove(nearest)
    assert planned == expected
