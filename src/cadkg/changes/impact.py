"""What a change set means for the robot's work: the tasks of a stored plan and the work the
cursors have passed (docs/changes.md, "Impact on the plan and the cursors").

A task is a wire or an operation. Of the things a diff reports, those of a task's kind are
sorted into: **new** (added: work no plan had), **redo** (changed after a cursor passed it: a
changed wire already landed), **changed** (changed, not yet done: the robot does it as it now
is) and **dropped** (removed: a task of the plan, or work a cursor passed, that is gone).
A plan's task is found by the IRI of its work in the plan's own revision; a cursor's work by
its IRI in either revision, else by its kind and identity.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from cadkg.changes.changeset import Change, ChangeSet
from cadkg.plan.graph import PlannedStep, StoredPlan
from cadkg.services.session import Work

__all__ = ["TASK_KINDS", "Impact", "plan_impact"]

TASK_KINDS = ("wire", "operation")


@dataclass
class Impact:
    """The tasks a change set makes new, to redo, changed and dropped; ``cursors`` where each
    cursor is now, where that is known."""

    plan: bool = False
    new: list[dict[str, Any]] = field(default_factory=list)
    redo: list[dict[str, Any]] = field(default_factory=list)
    changed: list[dict[str, Any]] = field(default_factory=list)
    dropped: list[dict[str, Any]] = field(default_factory=list)
    cursors: list[str] = field(default_factory=list)

    def counts(self) -> dict[str, int]:
        return {name: len(getattr(self, name)) for name in ("new", "redo", "changed", "dropped")}

    def to_json(self) -> dict[str, Any]:
        """``{"plan", "new", "redo", "changed", "dropped", "cursors"}``."""
        return {
            "plan": self.plan,
            "new": self.new,
            "redo": self.redo,
            "changed": self.changed,
            "dropped": self.dropped,
            "cursors": self.cursors,
        }


def _task(step: PlannedStep | None) -> dict[str, Any]:
    if step is None:
        return {}
    return {"task": step.key, "step": step.step, "performer": step.performer}


class _Passed:
    """Which cursors passed which work, looked up by IRI, else by kind and identity."""

    def __init__(self, done: Mapping[str, Sequence[Work]]) -> None:
        self.by_iri: dict[str, list[str]] = {}
        self.by_id: dict[tuple[str, str], list[str]] = {}
        for cursor, works in done.items():
            for work in works:
                if work.iri:
                    self.by_iri.setdefault(work.iri, []).append(cursor)
                self.by_id.setdefault((work.kind, work.id), []).append(cursor)

    def of(self, change: Change) -> list[str]:
        for iri in (change.old_iri, change.new_iri):
            if iri and iri in self.by_iri:
                return sorted(set(self.by_iri[iri]))
        # An id shown with its detail (two wires 0V) is looked up without it.
        identity = change.id.split(" (", 1)[0]
        return sorted(set(self.by_id.get((change.kind, identity), [])))


def plan_impact(
    changes: ChangeSet,
    plan: StoredPlan | None = None,
    done: Mapping[str, Sequence[Work]] | None = None,
    new_plan: StoredPlan | None = None,
    cursors: Sequence[str] = (),
) -> Impact | None:
    """The impact of ``changes`` on ``plan`` (the old revision's stored plan) and on the work
    each cursor had passed (``done``, cursor name → work, as :meth:`Session.done` gives it);
    ``new_plan`` (the new revision's, if made) gives the steps of new tasks. None when there is
    neither a plan nor a cursor."""
    if plan is None and not done and new_plan is None:
        return None
    tasks = {step.work: step for step in plan.steps if step.work} if plan is not None else {}
    new_tasks = {step.work: step for step in new_plan.steps if step.work} if new_plan is not None else {}
    passed = _Passed(done or {})
    impact = Impact(plan=plan is not None or new_plan is not None, cursors=list(cursors))
    for change in changes:
        if change.kind not in TASK_KINDS:
            continue
        item: dict[str, Any] = {"kind": change.kind, "id": change.id}
        step = tasks.get(change.old_iri or "")
        by = passed.of(change)
        if change.change == "added":
            impact.new.append({**item, **_task(new_tasks.get(change.new_iri or ""))})
        elif change.change == "removed":
            if step is not None or by:
                impact.dropped.append({**item, **_task(step), "done": bool(by), "passed_by": by})
        elif by:
            impact.redo.append(
                {**item, **_task(step), "attributes": sorted(change.attributes), "passed_by": by}
            )
        else:
            impact.changed.append({**item, **_task(step), "attributes": sorted(change.attributes)})
    return impact
