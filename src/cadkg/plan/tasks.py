"""What a plan is made of: tasks, who does each and why, and what must come first.

The core knows nothing of wires or harnesses: a use case turns its files into a
:class:`Problem` (tasks in the files' order, the tools each needs, where the robot starts and
ends it, the performer decided for each with its reason, precedence edges with theirs), and
:func:`cadkg.plan.order.make_plan` orders it.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from cadkg.geometry.poses import Vec3
from cadkg.plan.decision import Decision

__all__ = ["Precedence", "Problem", "Task"]


@dataclass(frozen=True, slots=True)
class Task:
    """One unit of work, as the files give it.

    ``key`` is unique in the problem (``W1``, ``op3``); ``label`` is what a person calls it (the
    wire number, the operation's code and labels); ``tools`` the tools it needs in the order it
    uses them; ``start`` and ``end`` where the robot's tool is when it starts and ends it;
    ``classes`` what the time model times it by (a wire's ends' terminations; without any, its
    ``kind``); ``assign_as`` what ``cadkg assign`` names it by (``("wire", "1500.51")``,
    ``("operation", "4")``), empty when it cannot be assigned.
    """

    key: str
    label: str
    kind: str
    position: int
    tools: tuple[str, ...] = ()
    start: Vec3 | None = None
    end: Vec3 | None = None
    iri: str = ""
    where: str = ""
    classes: tuple[str, ...] = ()
    assign_as: tuple[str, str] | tuple[()] = ()


@dataclass(frozen=True, slots=True)
class Precedence:
    """``before`` must be done before ``after`` (task keys), because of ``reason``; right before
    it when ``immediate`` (the robot holds what the first task picked up until the second)."""

    before: str
    after: str
    reason: str
    immediate: bool = False


@dataclass
class Problem:
    """The tasks of a cell in the files' order, the decisions on who does them, and precedence."""

    tasks: list[Task]
    decisions: dict[str, Decision]
    precedence: list[Precedence] = field(default_factory=list)
    # Notes the use case found while making the tasks (a name no file defines ...): (where, text).
    notes: list[tuple[str, str]] = field(default_factory=list)
