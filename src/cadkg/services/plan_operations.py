"""The operations on a cell's plan: the stored task list (``plan``), what the cell did with a
task (``progress``) and the plan made again, a task switched between the robot and a person
first (``replan``: what the workbench's review panel does). Declared in
:data:`cadkg.services.operations.OPERATIONS` with the other operations every cell offers.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

from cadkg.errors import NotFound, QueryError, StoreError
from cadkg.plan.decision import Performer
from cadkg.services.service import Effect, Service
from cadkg.services.session import Session
from cadkg.usecase import Answer

__all__ = ["PLAN_OPERATIONS", "PlanDocument", "Progressed", "Replanned"]

# The summary's times, as --format json names them.
TIMES = ("robot_time_s", "person_time_s", "makespan_s")


@dataclass(frozen=True)
class PlanDocument(Answer):
    """The stored plan as ``cadkg plan --format json`` prints it (``summary``, ``steps``,
    ``precedence``); ``message`` is its one-line summary."""

    summary: dict[str, Any]
    steps: list[dict[str, Any]]
    precedence: list[dict[str, Any]]


@dataclass(frozen=True)
class Progressed(Answer):
    """A report recorded: the task's ``key``, its ``status`` now and the IRI of its work
    (``target``); ``replanned`` when the stored plan was refreshed around it."""

    key: str
    status: str
    target: str
    replanned: bool


@dataclass(frozen=True)
class Replanned(PlanDocument):
    """The plan made again: the new plan as :class:`PlanDocument`, the times of the plan it
    replaced (``*_before``: of the plan the store held, else of the plan of the cell as it stood)
    and the tasks whose performer changed (``moved``: ``{key, task, before, after, reason}``,
    ``before`` empty for a new task)."""

    robot_time_s: float
    person_time_s: float
    makespan_s: float
    robot_time_s_before: float
    person_time_s_before: float
    makespan_s_before: float
    moved: list[dict[str, str]]


def _document(kg: Any) -> tuple[dict[str, Any], str] | None:
    """The stored plan as JSON data with each step's status, and its summary line; None when the
    store holds none."""
    from cadkg.plan.graph import cell_base, read_plan
    from cadkg.plan.progress import read_progress, statuses
    from cadkg.plan.report import as_json, summary

    stored = read_plan(kg, cell_base(kg))
    if stored is None:
        return None
    return as_json(stored, statuses(stored, read_progress(kg))), summary(stored)


def _plan(session: Session, client: str = "default") -> PlanDocument:
    found = _document(session.kg)
    if found is None:
        raise NotFound("the store holds no plan: make one with cadkg plan STORE")
    data, line = found
    return PlanDocument(True, line, data["summary"], data["steps"], data["precedence"])


def _progress(session: Session, client: str = "default", **params: str) -> Progressed:
    from cadkg.plan.progress import check_state, record

    task, state, reason = params["task"], check_state(params["state"]), params.get("reason", "")
    kg = _writable(session)
    _task_of(kg, task, "progress")  # an unknown task changes nothing, not even a generation
    with kg.change():  # on the store's latest generation: a concurrent report is kept too
        key, label, work = _task_of(kg, task, "progress")
        record(kg, key, label, work, state, reason, client)
        replanned = state == "failed" and _stored_again(kg)
    again = "; the plan refreshed around the tasks done" if replanned else ""
    return Progressed(True, f"{label}: {state}{_kept(kg)}{again}", key, state, work, replanned)


def _writable(session: Session) -> Any:
    if session.kg.read_only:
        raise StoreError("the store is open read-only")
    return session.kg


def _kept(kg: Any) -> str:
    return " (kept in the store)" if kg.directory is not None else " (in memory: not kept)"


def _tasks(kg: Any) -> list[Any]:
    from cadkg.plan.cell import rules_of
    from cadkg.registry import use_case
    from cadkg.store import cell_profile

    planner = use_case(cell_profile(kg)).planner
    rules = rules_of(kg)
    assert planner is not None  # rules_of raised otherwise
    return list(planner.tasks(kg, rules).tasks)


def _task_of(kg: Any, task: str, what: str) -> tuple[str, str, str]:
    """(key, label, work IRI) of the task named ``task`` (as ``cadkg plan --explain`` takes it),
    in the stored plan, else in the cell's tasks.

    Raises NotFound when there is none, QueryError when the name is a label several tasks share
    or the cell makes no plans."""
    from cadkg.plan.graph import cell_base, read_plan
    from cadkg.plan.progress import no_task

    stored = read_plan(kg, cell_base(kg))
    if stored is not None:
        named = [(s.key, s.label, s.work) for s in stored.steps]
    else:
        named = [(t.key, t.label, t.iri) for t in _tasks(kg)]
    found = [n for n in named if n[0] == task] or [n for n in named if n[1] == task]
    if not found:
        raise no_task(task, what)
    if len(found) > 1:
        keys = ", ".join(key for key, _, _ in found[:5]) + (" ..." if len(found) > 5 else "")
        raise QueryError(f"{what}: {task!r} names {len(found)} tasks ({keys}): give its key")
    return found[0]


def _stored_again(kg: Any) -> bool:
    """Make the stored plan again under the rules it was made by; False when the store holds
    none."""
    from cadkg.plan.cell import store_plan
    from cadkg.plan.graph import cell_base, read_plan

    stored = read_plan(kg, cell_base(kg))
    if stored is None:
        return False
    source = Path(str(stored.summary.get("rulesSource", "")))
    store_plan(kg, source if source.name and source.is_file() else None)
    return True


def _switch(kg: Any, key: str, performer: str) -> None:
    """Assign the task ``key`` to ``performer`` as ``cadkg assign`` would."""
    from cadkg.plan.cell import assign_ids

    tasks = _tasks(kg)
    named = next((t.assign_as for t in tasks if t.key == key), ())
    if not named:
        raise QueryError(f"replan: task {key} cannot be assigned (cadkg assign names no such work)")
    kind, ident = named
    kg.assign(kind, ident, performer, partial(assign_ids, tasks, kind))


def _times(summary: dict[str, Any]) -> tuple[float, float, float]:
    robot, person, makespan = (float(summary.get(name, math.nan)) for name in TIMES)
    return robot, person, makespan


def _moved(before: list[dict[str, Any]], after: list[dict[str, Any]]) -> list[dict[str, str]]:
    was = {s["key"]: s["performer"] for s in before}
    return [
        {
            "key": s["key"],
            "task": s["task"],
            "before": was.get(s["key"], ""),
            "after": s["performer"],
            "reason": s["reason"],
        }
        for s in after
        if was.get(s["key"]) != s["performer"]
    ]


def _replan(session: Session, client: str = "default", task: str = "", performer: str = "") -> Replanned:
    if bool(task) != bool(performer):
        raise QueryError("replan: give task and performer together (or neither)")
    if performer and performer not in tuple(Performer):
        raise QueryError(f"replan: unknown performer {performer!r}; expected robot or human")
    kg = _writable(session)
    # An unknown task changes nothing, not even a generation.
    key = _task_of(kg, task, "replan")[0] if task else ""
    previous = _document(kg)
    if previous is None:
        # What the switch is measured against: the plan as the cell stands, stored as cadkg
        # plan stores it.
        from cadkg.plan.cell import store_plan

        store_plan(kg)
        previous = _document(kg)
        assert previous is not None  # just stored
    with kg.change():
        if key:
            _switch(kg, key, performer)
        _stored_again(kg)
    found = _document(kg)
    assert found is not None  # just stored
    (data, line), (old, _) = found, previous
    moved = _moved(old["steps"], data["steps"])
    switched = f"{key} → {performer}; " if key else ""
    message = f"replanned{_kept(kg)}: {switched}{len(moved)} task(s) changed performer; {line}"
    (robot, person, makespan), (robot_was, person_was, makespan_was) = (
        _times(data["summary"]),
        _times(old["summary"]),
    )
    return Replanned(
        True,
        message,
        data["summary"],
        data["steps"],
        data["precedence"],
        robot,
        person,
        makespan,
        robot_was,
        person_was,
        makespan_was,
        moved,
    )


PLAN_OPERATIONS = (
    Service(
        "plan",
        "The robot's task list the store holds (cadkg plan makes it)",
        {},
        _plan,
        effect=Effect.READS,
    ),
    Service(
        "progress",
        "What the cell did with a task (a wire number, an operation label or a task key): "
        "state started, done or failed, with a reason; a failed robot task goes to a person "
        "and the stored plan is refreshed around the tasks done",
        {"task": str, "state": str, "reason": str},
        _progress,
        effect=Effect.WRITES,
        optional=frozenset({"reason"}),
        ros_name="report_progress",
        ros_type="ReportProgress",
    ),
    Service(
        "replan",
        "Make the stored plan again under the rules it was made by; with task (a wire number, an "
        "operation label or a task key) and performer (robot or human), that task assigned to "
        "that performer first: the new plan, the times before and after, what changed performer",
        {"task": str, "performer": str},
        _replan,
        effect=Effect.WRITES,
        optional=frozenset({"task", "performer"}),
        changes_frames=True,
    ),
)
