"""How long a plan takes: the rules file's time model (its ``[time]`` table) and the two lanes
the robot and a person work in, side by side (docs/plan.md, Times).

Each lane does its tasks in the plan's order, one at a time; a task starts when its lane is
free and every task that must come before it has ended, in either lane, so a person's wire that
blocks a robot's pin holds the robot's lane up. A robot's task takes, besides its work, the
tool change before it (when its first tool is not the one in hand), the changes inside it (a
wire whose two ends need two tools) and the travel from the previous task's end to its start.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from cadkg.plan.tasks import Precedence, Task

__all__ = ["CLASS_TABLES", "NUMBERS", "TIME_KEYS", "Lanes", "TimeModel", "Timing"]

# The [time] keys, their defaults and what each is (docs/plan.md lists their sources); the
# rules file's reader checks them (cadkg.plan.rules).
NUMBERS = {
    "robot_speed_m_s": 0.25,  # the tool's speed between tasks: ISO 10218-1's reduced speed
    "robot_tool_change_s": 10.0,
    "robot_task_s": 60.0,  # a robot's task whose classes robot_class_s does not list
    "person_task_s": 240.0,  # about 4 minutes a connection by hand
}
CLASS_TABLES = ("robot_class_s", "person_class_s")
TIME_KEYS = frozenset({*NUMBERS, *CLASS_TABLES, "balance"})


@dataclass(frozen=True)
class TimeModel:
    """Seconds of the robot's and a person's work. A task's work is the mean of its classes'
    seconds (a wire's two ends' terminations, an operation's code; a class not listed takes
    ``robot_task_s`` / ``person_task_s``)."""

    robot_speed_m_s: float = NUMBERS["robot_speed_m_s"]
    robot_tool_change_s: float = NUMBERS["robot_tool_change_s"]
    robot_task_s: float = NUMBERS["robot_task_s"]
    person_task_s: float = NUMBERS["person_task_s"]
    robot_class_s: Mapping[str, float] = field(default_factory=dict)
    person_class_s: Mapping[str, float] = field(default_factory=dict)
    balance: bool = False

    @classmethod
    def layered(cls, *tables: Mapping[str, Any]) -> TimeModel:
        """The model of checked ``[time]`` values (``Rules.time``), a later table's winning
        key by key (a class table class by class)."""
        merged: dict[str, Any] = {name: {} for name in CLASS_TABLES}
        for table in tables:
            for key, value in table.items():
                merged[key] = {**merged[key], **value} if key in CLASS_TABLES else value
        return cls(**merged)

    def _work(self, task: Task, seconds: Mapping[str, float], default: float) -> float:
        classes = task.classes or (task.kind,)
        return sum(seconds.get(name, default) for name in classes) / len(classes)

    def robot_work(self, task: Task) -> float:
        """The robot's seconds on ``task`` itself, tool changes inside it included."""
        inside = sum(1 for a, b in zip(task.tools, task.tools[1:], strict=False) if a != b)
        return self._work(task, self.robot_class_s, self.robot_task_s) + inside * self.robot_tool_change_s

    def person_work(self, task: Task) -> float:
        return self._work(task, self.person_class_s, self.person_task_s)


@dataclass(frozen=True)
class Timing:
    """When each task of an order starts and ends (seconds from the start, by position in the
    order), the busy seconds of each lane and when the last task ends."""

    start: tuple[float, ...]
    end: tuple[float, ...]
    robot_s: float
    person_s: float
    makespan_s: float


class Lanes:
    """An order of tasks, ready to be timed under any split between robot and person."""

    def __init__(self, order: Sequence[Task], edges: Iterable[Precedence], model: TimeModel) -> None:
        self.order = list(order)
        self.model = model
        at = {task.key: n for n, task in enumerate(self.order)}
        self.before: list[list[int]] = [[] for _ in self.order]
        for edge in edges:
            if edge.before in at and edge.after in at:
                self.before[at[edge.after]].append(at[edge.before])
        self.robot_work = [model.robot_work(t) for t in self.order]
        self.person_work = [model.person_work(t) for t in self.order]

    def run(self, robot: Sequence[bool]) -> Timing:
        """The timing of the order when ``robot[n]`` says who does its n-th task."""
        change, speed = self.model.robot_tool_change_s, self.model.robot_speed_m_s
        start, end = [0.0] * len(self.order), [0.0] * len(self.order)
        free = {True: 0.0, False: 0.0}
        busy = {True: 0.0, False: 0.0}
        tool, here = "", None
        for n, task in enumerate(self.order):
            # The order respects precedence, so every task before this one has its end.
            ready = max((end[p] for p in self.before[n]), default=0.0)
            lane = bool(robot[n])
            if lane:
                took = self.robot_work[n]
                if tool and task.tools and task.tools[0] != tool:
                    took += change
                if here is not None and task.start is not None:
                    took += math.dist(here, task.start) / speed
                tool = task.tools[-1] if task.tools else tool
                here = task.end if task.end is not None else here
            else:
                took = self.person_work[n]
            start[n] = max(free[lane], ready)
            end[n] = free[lane] = start[n] + took
            busy[lane] += took
        return Timing(tuple(start), tuple(end), busy[True], busy[False], max(end, default=0.0))
