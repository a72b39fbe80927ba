"""The operations every cell offers, whatever its use case: who does a piece of work
(``assign``), the stored task list (``plan``), what the cell did with a task (``progress``), the
tf frames of a label (``label_frames``) and serving the store's current generation (``reload``).

They are services like the use cases' (:class:`~cadkg.services.service.Service`, with their
:class:`~cadkg.services.service.Effect`), in the same table, so ``cadkg call``, the HTTP
endpoint (``/api/<name>``) and the ROS node serve them with the same checks and answers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from cadkg.errors import CadkgError, NotFound, QueryError, StateError, StoreError
from cadkg.services.service import Effect, Service
from cadkg.services.session import Session
from cadkg.usecase import Answer

__all__ = ["OPERATIONS", "Assigned", "FramesOfLabel", "PlanDocument", "Progressed", "Reloaded"]


@dataclass(frozen=True)
class Assigned(Answer):
    """An assignment made: ``target`` is the IRI of the wire, component or operation."""

    target: str


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
class FramesOfLabel(Answer):
    """Parallel lists: ``labels[i]`` names the frame ``frame_ids[i]``."""

    labels: list[str]
    frame_ids: list[str]


@dataclass(frozen=True)
class Reloaded(Answer):
    """The generation served before and the one served now."""

    previous: str
    generation: str


def _assign(session: Session, client: str = "default", **params: str) -> Assigned:
    kind, ident, performer = params["kind"], params["id"], params["performer"]
    kg = session.kg
    target = kg.assign(kind, ident, performer)
    kept = " (kept in the store)" if kg.directory is not None else " (in memory: not kept)"
    return Assigned(True, f"{kind} {ident} → {performer}{kept}", target)


def _plan(session: Session, client: str = "default") -> PlanDocument:
    from cadkg.plan.graph import cell_base, read_plan
    from cadkg.plan.progress import read_progress, statuses
    from cadkg.plan.report import as_json, summary

    stored = read_plan(session.kg, cell_base(session.kg))
    if stored is None:
        raise NotFound("the store holds no plan: make one with cadkg plan STORE")
    data = as_json(stored, statuses(stored, read_progress(session.kg)))
    return PlanDocument(True, summary(stored), data["summary"], data["steps"], data["precedence"])


def _progress(session: Session, client: str = "default", **params: str) -> Progressed:
    from cadkg.plan.progress import check_state, record

    task, state, reason = params["task"], check_state(params["state"]), params.get("reason", "")
    kg = session.kg
    if kg.read_only:
        raise StoreError("the store is open read-only")
    _task_of(kg, task)  # an unknown task changes nothing, not even a generation
    with kg.change():  # on the store's latest generation: a concurrent report is kept too
        key, label, work = _task_of(kg, task)
        record(kg, key, label, work, state, reason, client)
        replanned = state == "failed" and _replan(kg)
    kept = " (kept in the store)" if kg.directory is not None else " (in memory: not kept)"
    again = "; the plan refreshed around the tasks done" if replanned else ""
    return Progressed(True, f"{label}: {state}{kept}{again}", key, state, work, replanned)


def _task_of(kg: Any, task: str) -> tuple[str, str, str]:
    """(key, label, work IRI) of the task named ``task`` (as ``cadkg plan --explain`` takes it),
    in the stored plan, else in the cell's tasks.

    Raises NotFound when there is none, QueryError when the name is a label several tasks share
    or the cell makes no plans."""
    from cadkg.plan.cell import rules_of
    from cadkg.plan.graph import cell_base, read_plan
    from cadkg.plan.progress import no_task
    from cadkg.registry import use_case
    from cadkg.store import cell_profile

    stored = read_plan(kg, cell_base(kg))
    if stored is not None:
        named = [(s.key, s.label, s.work) for s in stored.steps]
    else:
        planner = use_case(cell_profile(kg)).planner
        rules = rules_of(kg)
        assert planner is not None  # rules_of raised otherwise
        named = [(t.key, t.label, t.iri) for t in planner.tasks(kg, rules).tasks]
    found = [n for n in named if n[0] == task] or [n for n in named if n[1] == task]
    if not found:
        raise no_task(task)
    if len(found) > 1:
        keys = ", ".join(key for key, _, _ in found[:5]) + (" ..." if len(found) > 5 else "")
        raise QueryError(f"progress: {task!r} names {len(found)} tasks ({keys}): give its key")
    return found[0]


def _replan(kg: Any) -> bool:
    """Refresh the stored plan around the reports, under the rules it was made by; False when
    the store holds none."""
    from pathlib import Path

    from cadkg.plan.cell import store_plan
    from cadkg.plan.graph import cell_base, read_plan

    stored = read_plan(kg, cell_base(kg))
    if stored is None:
        return False
    source = Path(str(stored.summary.get("rulesSource", "")))
    store_plan(kg, source if source.name and source.is_file() else None)
    return True


def _label_frames(session: Session, client: str = "default", label: str = "") -> FramesOfLabel:
    from cadkg.query.frames import label_frames
    from cadkg.services.frames import published_frames

    published = [frame.child for frame in published_frames(session)]
    pairs = label_frames(session.kg, published, label)
    found = bool(pairs) or not label
    message = f"{len(pairs)} frame(s)" if found else f"no frames of {label!r}"
    return FramesOfLabel(found, message, [name for name, _ in pairs], [frame for _, frame in pairs])


def _reload(session: Session, client: str = "default") -> Reloaded:
    if session.reopen is None:
        raise QueryError("reload: only a served cell reloads (cadkg serve, cadkg ros); this one opens afresh")
    try:
        previous, generation = session.reopen()
    except StateError:
        raise
    except CadkgError as err:
        raise StoreError(f"reload failed, still serving the old cell: {err}") from None
    return Reloaded(True, f"reloaded: {previous} → {generation}", previous, generation)


OPERATIONS: dict[str, Service] = {
    s.name: s
    for s in (
        Service(
            "assign",
            "Who does a wire (its number), a component (its label) or an operation (its list "
            "position): performer robot or human; kept in the store's assignment graph",
            {"kind": str, "id": str, "performer": str},
            _assign,
            effect=Effect.WRITES,
            changes_frames=True,
        ),
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
            "label_frames",
            "The tf frame ids of a label (its CAD items and derived frames); no label: every label's",
            {"label": str},
            _label_frames,
            effect=Effect.READS,
            optional=frozenset({"label"}),
        ),
        Service(
            "reload",
            "Serve the store's current generation (after a rebuild); cursors stay on their work",
            {},
            _reload,
            effect=Effect.RELOADS,
            changes_frames=True,
        ),
    )
}
