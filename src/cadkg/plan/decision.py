"""Who does a task, and why: the one decision every consumer of it asks.

The order of the rules is the same for every cell: an explicit assignment of the task itself
(overlay file or ``cadkg assign``) wins; then the use case's scope rule (what is the robot's
work at all: an IEMA cabinet's zones and CAD labels); then an assignment of a part the task
handles (a wire end's component); then the robot's abilities in the use case's order
(cross-section, tools, pin data ...); else the robot. A use case supplies the rules as data
(callables), never a second ordering of them.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from enum import StrEnum
from typing import TypeVar

__all__ = ["ASSIGNED", "BALANCE", "Assignments", "Decision", "Performer", "Rule", "decide"]

# The rule of a decision an explicit assignment made.
ASSIGNED = "assigned"
# The rule of a robot's task a balanced plan hands to a person (cadkg.plan.balance).
BALANCE = "balance"

T = TypeVar("T")


class Performer(StrEnum):
    """Who does a task; the values are the words the files, the graph and the JSON use."""

    ROBOT = "robot"
    HUMAN = "human"

    @property
    def who(self) -> str:
        """The performer as a reason names it."""
        return "the robot" if self is Performer.ROBOT else "a person"


@dataclass(frozen=True, slots=True)
class Decision:
    """Who does a task, the rule that said so (``rule``, '' when no rule did) and the values it
    saw (``reason``)."""

    performer: Performer
    rule: str = ""
    reason: str = ""


# A rule of a use case: a decision about the task, or None when the rule lets it through.
Rule = Callable[[T], Decision | None]


class Assignments:
    """Explicit assignments by kind and id (``("wire", "1500.51")``): who, as the files and
    ``cadkg assign`` said, the later winning."""

    def __init__(self, chosen: Mapping[tuple[str, str], str] | None = None) -> None:
        self._chosen = {name: Performer(who) for name, who in (chosen or {}).items()}

    @classmethod
    def of_targets(
        cls,
        performers: Mapping[str, str],
        things: Iterable[tuple[str, str]],
        mint: Callable[[str, str], str],
    ) -> Assignments:
        """The assignments of ``things`` (kind, id) among ``performers`` (the IRI the graph
        holds an assignment of → performer), each thing's IRI minted by ``mint(kind, id)``."""
        chosen = {}
        for kind, ident in things:
            who = performers.get(mint(kind, ident))
            if who is not None:
                chosen[(kind, ident)] = who
        return cls(chosen)

    def get(self, kind: str, ident: str) -> Performer | None:
        return self._chosen.get((kind, ident))

    def __len__(self) -> int:
        return len(self._chosen)


def _by_hand(kind: str, ident: str, performer: Performer) -> Decision:
    return Decision(
        performer, ASSIGNED, f"{kind} {ident} assigned to {performer.who} by hand; wins over the rules"
    )


def decide(
    task: T,
    assignments: Assignments,
    names: Sequence[tuple[str, str]],
    *,
    scope: Rule[T] | None = None,
    parts: Sequence[tuple[str, str]] = (),
    abilities: Sequence[Rule[T]] = (),
) -> Decision:
    """Who does ``task``, in the order of the module's rules.

    ``names`` are the (kind, id) the task is known by, first match wins; ``parts`` those of the
    things it handles: one assigned to a person makes the task a person's, else a part's
    assignment gives it to the robot. ``abilities`` are asked in turn; the first decision wins.
    """
    for kind, ident in names:
        performer = assignments.get(kind, ident)
        if performer is not None:
            return _by_hand(kind, ident, performer)
    if scope is not None and (scoped := scope(task)) is not None:
        return scoped
    assigned = [(kind, ident, who) for kind, ident in parts if (who := assignments.get(kind, ident))]
    if assigned:
        kind, ident, _ = assigned[0]
        human = any(who is Performer.HUMAN for _, _, who in assigned)
        return _by_hand(kind, ident, Performer.HUMAN if human else Performer.ROBOT)
    for rule in abilities:
        if (decided := rule(task)) is not None:
            return decided
    return Decision(Performer.ROBOT)
