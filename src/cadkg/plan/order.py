"""Order a problem's tasks: break precedence cycles, then a greedy order that respects
precedence and takes, at each step, a ready task needing no tool change, else the tool with
the most ready tasks, and among those the nearest to where the robot's tool is.

People's tasks cost the robot nothing: each is placed as soon as what must come before it is
done. The order is a function of the problem alone (ties go to the files' order), so the same
store gives the same plan.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass, field, replace

import numpy as np

from cadkg.plan.decision import ASSIGNED, Decision, Performer
from cadkg.plan.greedy import PERSON, greedy_order
from cadkg.plan.measure import Measure, lower_bound, measure
from cadkg.plan.solver import solve_order
from cadkg.plan.tasks import Precedence, Problem, Task
from cadkg.plan.times import Timing

__all__ = ["CYCLE", "Plan", "Step", "make_plan"]

CYCLE = "precedence-cycle"
"""The rule of a decision made with ``cadkg assign`` (or an assignments file): it wins over
every other rule, and a cycle is broken elsewhere when it can be."""


@dataclass(frozen=True, slots=True)
class Step:
    """A task at its place in the plan, who does it and why it is there."""

    index: int
    task: Task
    decision: Decision
    why_here: str


@dataclass
class Plan:
    """The ordered tasks, the precedence kept, the edges dropped to break cycles, and measures
    of the plan and of the files' own order; once timed (:mod:`cadkg.plan.balance`), when each
    step starts and ends, and the makespan before a balance moved tasks."""

    steps: list[Step]
    precedence: list[Precedence]
    dropped: list[Precedence] = field(default_factory=list)
    measure: Measure = field(default_factory=Measure)
    files: Measure = field(default_factory=Measure)
    lower_bound: int = 0
    notes: list[tuple[str, str]] = field(default_factory=list)
    timing: Timing | None = None
    unbalanced_makespan_s: float | None = None

    def step_of(self, task: str) -> Step | None:
        """The step of the task keyed or labelled ``task``."""
        return next((s for s in self.steps if task in (s.task.key, s.task.label)), None)


def _break_cycles(problem: Problem) -> tuple[list[Precedence], list[Precedence], dict[str, Decision]]:
    """Give one task of every cycle to a person (one not assigned by hand when there is one);
    its edges inside the cycle are dropped. Returns kept edges, dropped edges, decisions."""
    import networkx as nx  # a fifth of a second to import: only when a plan is made

    decisions = dict(problem.decisions)
    position = {t.key: t.position for t in problem.tasks}
    edges = list(problem.precedence)
    dropped: list[Precedence] = []
    while True:
        graph = nx.DiGraph()
        graph.add_edges_from((e.before, e.after) for e in edges)
        knots = sorted(
            (
                sorted(c, key=position.__getitem__)
                for c in nx.strongly_connected_components(graph)
                if len(c) > 1
            ),
            key=lambda c: position[c[0]],
        )
        if not knots:
            return edges, dropped, decisions
        for knot in knots:
            members = set(knot)
            inside = graph.subgraph(knot)
            chosen = max(
                knot,
                key=lambda key, inside=inside: (  # type: ignore[misc]
                    decisions[key].performer == Performer.HUMAN,
                    decisions[key].rule != ASSIGNED,
                    inside.degree(key),
                    position[key],
                ),
            )
            cycle = [a for a, _ in nx.find_cycle(inside, source=chosen)]
            path = " → ".join([*cycle, cycle[0]])
            old = decisions[chosen]
            if old.performer == Performer.ROBOT and old.rule != ASSIGNED:
                decisions[chosen] = Decision(
                    Performer.HUMAN, CYCLE, f"precedence cycle {path}: no order lets the robot do them all"
                )
            elif old.performer == Performer.ROBOT:
                decisions[chosen] = replace(
                    old, reason=f"{old.reason}; in precedence cycle {path}, whose edges on it are dropped"
                )
            keep: list[Precedence] = []
            for edge in edges:
                inner = edge.before in members and edge.after in members
                (dropped if inner and chosen in (edge.before, edge.after) else keep).append(edge)
            edges = keep


def make_plan(problem: Problem, solver_budget: float = 0.0) -> Plan:
    """The plan of ``problem``: cycles broken, then the greedy order, or the files' own order
    made to respect precedence when that has fewer tool changes (then less travel); with a
    ``solver_budget`` (CP-SAT's deterministic seconds), the solver's order when it does better.

    Raises ImportError when a budget is given and OR-Tools is not installed."""
    edges, dropped, decisions = _break_cycles(problem)
    tasks = sorted(problem.tasks, key=lambda t: t.position)
    index = {t.key: i for i, t in enumerate(tasks)}
    after: list[list[int]] = [[] for _ in tasks]
    waiting = np.zeros(len(tasks), dtype=np.int64)
    then: dict[int, tuple[int, str]] = {}
    for edge in edges:
        after[index[edge.before]].append(index[edge.after])
        waiting[index[edge.after]] += 1
        if edge.immediate:
            then[index[edge.before]] = (index[edge.after], f"right after {edge.before}: {edge.reason}")
    greedy = greedy_order(tasks, decisions, after, waiting.copy(), then)
    kept = _kept([t.label for t in tasks], after, waiting.copy(), then)
    scored = []
    for order in (greedy, kept):
        measured = measure([tasks[i] for i, _ in order], decisions, edges)
        scored.append(((measured.tool_changes, measured.travel), measured, order))
    _, best_measure, best = min(scored, key=lambda s: s[0])
    if solver_budget > 0:
        best_measure, best = _solved(
            tasks, decisions, (after, then, edges), (best_measure, best), solver_budget
        )
    steps = [Step(n, tasks[i], decisions[tasks[i].key], why) for n, (i, why) in enumerate(best)]
    return Plan(
        steps=steps,
        precedence=edges,
        dropped=dropped,
        measure=best_measure,
        files=measure(tasks, decisions, edges),
        lower_bound=lower_bound(tasks, decisions),
        notes=list(problem.notes),
    )


def _solved(
    tasks: list[Task],
    decisions: dict[str, Decision],
    graph: tuple[list[list[int]], dict[int, tuple[int, str]], list[Precedence]],
    found: tuple[Measure, list[tuple[int, str]]],
    budget: float,
) -> tuple[Measure, list[tuple[int, str]]]:
    """CP-SAT's order from ``found``'s, when it has fewer tool changes, or as many and less travel."""
    after, then, edges = graph
    best_measure, best = found
    solved = solve_order(tasks, decisions, after, then, [i for i, _ in best], budget)
    if solved is None:
        return found
    measured = measure([tasks[i] for i in solved], decisions, edges)
    if (measured.tool_changes, measured.travel) >= (best_measure.tool_changes, best_measure.travel):
        return found
    why = (
        f"in the solver's order (CP-SAT from the best order found without it: tool changes "
        f"{measured.tool_changes} instead of {best_measure.tool_changes}, travel {measured.travel:.2f} m "
        f"instead of {best_measure.travel:.2f} m)"
    )
    placed = [(i, why if decisions[tasks[i].key].performer == Performer.ROBOT else PERSON) for i in solved]
    return measured, placed


def _kept(
    labels: list[str], after: list[list[int]], waiting: np.ndarray, then: dict[int, tuple[int, str]]
) -> list[tuple[int, str]]:
    """The files' order, each task moved only as late as its precedence needs."""
    count = len(labels)
    later_first: dict[int, int] = {}  # task → the last task listed after it that must come first
    for i, followers in enumerate(after):
        for j in followers:
            if i > j:
                later_first[j] = max(i, later_first.get(j, i))
    ready = [i for i in range(count) if waiting[i] == 0]
    heapq.heapify(ready)
    order: list[tuple[int, str]] = []
    while ready:
        forced = then.get(order[-1][0]) if order else None
        if forced is not None and forced[0] in ready:
            ready.remove(forced[0])
            heapq.heapify(ready)
            i, why = forced
        else:
            i = heapq.heappop(ready)
            why = "in the files' order (as few tool changes as the greedy order)"
            if i in later_first:
                why = f"in the files' order, moved after {labels[later_first[i]]}, which must come first"
        order.append((i, why))
        for j in after[i]:
            waiting[j] -= 1
            if waiting[j] == 0:
                heapq.heappush(ready, j)
    return order
