"""A plan timed, and on request balanced: robot's tasks handed to a person while that shortens
the makespan (docs/plan.md, Balance).

A person can do any task; the robot only what the rules let it, so only the robot's tasks move,
and of those not the ones assigned by hand, nor the ones that must come right before or after
another (the robot holds what the first picked up), nor the ones another task waits for (in the
person's lane they would hold the robot's lane up). The candidates are ranked by the robot's seconds each
saves per second it costs a person, the most first, and the fewest of them that bring the
robot's lane down to the person's is found by bisection, each try one timing of the plan's order
(linear in the tasks and edges); the one before and after it are tried too, and the best kept.
The plan is then ordered again with the new split, and kept only when its makespan is shorter.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace

from cadkg.plan.decision import ASSIGNED, BALANCE, Decision, Performer
from cadkg.plan.order import Plan, Step
from cadkg.plan.tasks import Problem
from cadkg.plan.times import Lanes, TimeModel, Timing

__all__ = ["timed"]


def _timing(plan: Plan, model: TimeModel) -> tuple[Lanes, Timing]:
    lanes = Lanes([s.task for s in plan.steps], plan.precedence, model)
    return lanes, lanes.run([s.decision.performer is Performer.ROBOT for s in plan.steps])


def timed(
    problem: Problem,
    plan: Plan,
    model: TimeModel,
    order: Callable[[Problem], Plan],
    balance: bool,
    taken: frozenset[str] = frozenset(),
) -> Plan:
    """``plan`` with its timing; with ``balance``, the balanced plan when it ends sooner
    (``order`` makes a plan of a problem, as :func:`cadkg.plan.order.make_plan` does). The
    tasks of ``taken`` (keys: the cell has started or done them) are not moved."""
    lanes, timing = _timing(plan, model)
    plan.timing = timing
    if not balance or timing.robot_s <= timing.person_s:
        return plan
    moved = _moved(plan, lanes, taken)
    if not moved:
        return plan
    decisions = {s.task.key: s.decision for s in plan.steps}
    for n in moved:
        decisions[plan.steps[n].task.key] = Decision(Performer.HUMAN, BALANCE, "")
    again = order(replace(problem, decisions=decisions))
    lanes_again, timing_again = _timing(again, model)
    if timing_again.makespan_s >= timing.makespan_s:
        return plan
    again.timing, again.unbalanced_makespan_s = timing_again, timing.makespan_s
    was = {plan.steps[n].task.key: plan.steps[n].decision for n in moved}
    shorter = round(timing.makespan_s) - round(timing_again.makespan_s)
    again.steps = [
        _reason(
            step,
            was[step.task.key],
            lanes_again,
            (timing.makespan_s, timing_again.makespan_s, shorter, len(moved)),
        )
        if step.task.key in was
        else step
        for step in again.steps
    ]
    return again


def _reason(step: Step, was: Decision, lanes: Lanes, figures: tuple[float, float, int, int]) -> Step:
    before, after, shorter, count = figures
    robot, person = lanes.robot_work[step.index], lanes.person_work[step.index]
    tasks = "1 task" if count == 1 else f"{count} tasks"
    why = (
        f"moved from the robot to a person to balance the lanes: the makespan {before:.0f} s → "
        f"{after:.0f} s ({shorter} s shorter) with {tasks} moved; this one takes the robot "
        f"{robot:.0f} s, a person {person:.0f} s (the robot's by the rules: {was.reason or was.rule})"
    )
    return replace(step, decision=Decision(Performer.HUMAN, BALANCE, why))


def _moved(plan: Plan, lanes: Lanes, taken: frozenset[str]) -> list[int]:
    """The positions, in the plan, of the robot's tasks to hand to a person (none when no split
    ends sooner on the plan's order)."""
    held = {key for e in plan.precedence if e.immediate for key in (e.before, e.after)}
    # A task another waits for stays the robot's: in a person's lane it would hold the robot up.
    held.update(e.before for e in plan.precedence)
    held.update(taken)
    robot = [s.decision.performer is Performer.ROBOT for s in plan.steps]
    movable = [
        n
        for n, s in enumerate(plan.steps)
        if robot[n] and s.decision.rule != ASSIGNED and s.task.key not in held
    ]
    # Most robot seconds saved per person second spent first; ties to the plan's order.
    ranked = sorted(movable, key=lambda n: (-lanes.robot_work[n] / max(lanes.person_work[n], 1e-9), n))
    tried: dict[int, Timing] = {}

    def trial(k: int) -> Timing:
        if k not in tried:
            split = list(robot)
            for n in ranked[:k]:
                split[n] = False
            tried[k] = lanes.run(split)
        return tried[k]

    low, high = 0, len(ranked)
    while low < high:
        middle = (low + high) // 2
        if trial(middle).robot_s <= trial(middle).person_s:
            high = middle
        else:
            low = middle + 1
    best = min(
        (k for k in (low - 1, low, low + 1) if 0 <= k <= len(ranked)), key=lambda k: (trial(k).makespan_s, k)
    )
    return ranked[:best] if trial(best).makespan_s < trial(0).makespan_s else []
