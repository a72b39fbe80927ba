"""An optional improvement of the order (docs/plan.md, In which order): OR-Tools CP-SAT on the
robot's tasks as one precedence-constrained sequence, started from the best order found so
far, within a budget of the solver's deterministic time (the same problem and budget give the
same answer on any machine). Installed with ``pip install 'cadkg[solver]'``.

The robot's tasks form a circuit through a depot; an arc from task a to task b costs a tool
change (a's last tool is not b's first) times a weight larger than any travel, plus the
distance from a's end to b's start in millimetres: tool changes first, then travel, as
:func:`cadkg.plan.measure.measure` counts them. A robot task that must come after another,
directly or through people's tasks, comes after it; people's tasks are then placed as soon as
what comes before them is done, as in the greedy order.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Sequence

from cadkg.plan.decision import Decision, Performer
from cadkg.plan.tasks import Task

__all__ = ["MAX_TASKS", "solve_order"]

# Above this many robot tasks the n² arcs of the circuit outgrow any useful budget.
MAX_TASKS = 300


def solve_order(
    tasks: Sequence[Task],
    decisions: dict[str, Decision],
    after: list[list[int]],
    then: dict[int, tuple[int, str]],
    start: Sequence[int],
    budget: float,
) -> list[int] | None:
    """The robot's tasks and people's, in the solver's order (task indices), or None when it
    cannot take the problem (too many robot tasks, a task without tools, ends known for some
    tasks only, a person's task that must come right after another) or finds nothing better
    than ``start``'s sequence of robot tasks.

    Raises ImportError when OR-Tools is not installed.
    """
    from ortools.sat.python import cp_model

    robot = [i for i in start if decisions[tasks[i].key].performer == Performer.ROBOT]
    n = len(robot)
    if n < 2 or n > MAX_TASKS or any(not tasks[i].tools for i in robot):
        return None
    located = {tasks[i].start is not None and tasks[i].end is not None for i in robot}
    if len(located) > 1 or any(
        decisions[tasks[j].key].performer != Performer.ROBOT for j, _ in then.values()
    ):
        return None
    slot = {i: k for k, i in enumerate(robot)}
    must = _robot_precedence(robot, slot, after)
    forced = {(slot[i], slot[j]) for i, (j, _) in then.items() if i in slot and j in slot}
    cost = [[_arc(tasks[a], tasks[b]) for b in robot] for a in robot]
    weight = n * max((c[1] for row in cost for c in row), default=0) + 1

    model = cp_model.CpModel()
    position = [model.new_int_var(0, n - 1, f"p{k}") for k in range(n)]
    arcs: list[tuple[int, int, cp_model.IntVar]] = []
    terms = []
    for k in range(n):
        first, last = model.new_bool_var(f"s{k}"), model.new_bool_var(f"e{k}")
        arcs += [(0, k + 1, first), (k + 1, 0, last)]
        model.add(position[k] == 0).only_enforce_if(first)
        model.add(position[k] == n - 1).only_enforce_if(last)
        for m in range(n):
            if m == k or (m, k) in must:
                continue
            arc = model.new_bool_var(f"a{k}_{m}")
            arcs.append((k + 1, m + 1, arc))
            model.add(position[m] == position[k] + 1).only_enforce_if(arc)
            changes, millimetres = cost[k][m]
            if changes or millimetres:
                terms.append((changes * weight + millimetres) * arc)
            if (k, m) in forced:
                model.add(arc == 1)
    model.add_circuit(arcs)
    for k, m in must:
        model.add(position[k] < position[m])
    model.minimize(sum(terms))
    # The start: the robot's tasks in ``start``'s order, arc by arc.
    for k in range(n):
        model.add_hint(position[k], k)
    for tail, head, arc in arcs:
        model.add_hint(arc, head == tail + 1 or (tail == 0 and head == 1) or (head == 0 and tail == n))
    solver = cp_model.CpSolver()
    solver.parameters.max_deterministic_time = budget
    solver.parameters.num_workers = 1
    if solver.solve(model) not in (cp_model.OPTIMAL, cp_model.FEASIBLE):
        return None
    ordered = sorted(range(n), key=lambda k: solver.value(position[k]))
    if ordered == list(range(n)):
        return None
    return _with_people(tasks, decisions, after, [robot[k] for k in ordered])


def _arc(a: Task, b: Task) -> tuple[int, int]:
    """(tool changes, millimetres) from task a to task b."""
    changes = int(a.tools[-1] != b.tools[0])
    if a.end is None or b.start is None:
        return changes, 0
    return changes, round(1000 * math.dist(a.end, b.start))


def _robot_precedence(robot: list[int], slot: dict[int, int], after: list[list[int]]) -> set[tuple[int, int]]:
    """(a, b) robot slots where b must come after a, directly or through people's tasks."""
    must = set()
    for i in robot:
        queue, seen = deque(after[i]), set(after[i])
        while queue:
            j = queue.popleft()
            if j in slot:
                must.add((slot[i], slot[j]))
                continue
            for k in after[j]:
                if k not in seen:
                    seen.add(k)
                    queue.append(k)
    return must


def _with_people(
    tasks: Sequence[Task], decisions: dict[str, Decision], after: list[list[int]], robot: list[int]
) -> list[int]:
    """The robot's tasks in ``robot``'s order, each person's task as soon as it is ready."""
    waiting = [0] * len(tasks)
    for followers in after:
        for j in followers:
            waiting[j] += 1
    people = sorted(i for i in range(len(tasks)) if decisions[tasks[i].key].performer != Performer.ROBOT)
    order: list[int] = []
    placed: set[int] = set()

    def place(i: int) -> None:
        order.append(i)
        placed.add(i)
        for j in after[i]:
            waiting[j] -= 1

    for i in [*robot, None]:
        ready = True
        while ready:
            ready = False
            for p in people:
                if p not in placed and waiting[p] == 0:
                    place(p)
                    ready = True
        if i is not None:
            place(i)
    return order
