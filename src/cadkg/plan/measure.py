"""How good an order is for the robot: tool changes, travel between consecutive tasks, and the
precedence edges it breaks; and the fewest tool changes any order could have."""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from cadkg.plan.decision import Decision, Performer
from cadkg.plan.tasks import Precedence, Task

__all__ = ["Measure", "lower_bound", "measure"]


@dataclass(frozen=True, slots=True)
class Measure:
    """Of an order: the robot's tool changes, its travel in metres from one task's end to the
    next one's start (where both are known), and the precedence edges it breaks."""

    tool_changes: int = 0
    travel: float = 0.0
    violations: int = 0


def measure(order: Sequence[Task], decisions: Mapping[str, Decision], edges: Iterable[Precedence]) -> Measure:
    """The measures of ``order`` (every task; people's tasks cost the robot nothing)."""
    changes, travel, tool, here = 0, 0.0, "", None
    for task in order:
        if decisions[task.key].performer != Performer.ROBOT:
            continue
        for used in task.tools:
            if tool and used != tool:
                changes += 1
            tool = used
        if here is not None and task.start is not None:
            travel += math.dist(here, task.start)
        here = task.end if task.end is not None else here
    at = {task.key: n for n, task in enumerate(order)}
    broken = sum(
        1
        for e in edges
        if e.before in at
        and e.after in at
        and (at[e.before] + 1 != at[e.after] if e.immediate else at[e.before] > at[e.after])
    )
    return Measure(changes, travel, broken)


def lower_bound(tasks: Iterable[Task], decisions: Mapping[str, Decision]) -> int:
    """The fewest tool changes any order can have: the tool classes the robot's tasks use less
    one, or the changes inside tasks (a wire whose two ends need two tools), whichever is more."""
    robots = [t for t in tasks if decisions[t.key].performer == Performer.ROBOT]
    tools = {tool for t in robots for tool in t.tools}
    inside = sum(1 for t in robots for a, b in zip(t.tools, t.tools[1:], strict=False) if a != b)
    return max(0, len(tools) - 1, inside)
