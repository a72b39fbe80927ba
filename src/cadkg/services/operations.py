"""The operations every cell offers, whatever its use case: who does a piece of work
(``assign``), the stored task list (``plan``), what the cell did with a task (``progress``), the
plan made again (``replan``; these three in :mod:`cadkg.services.plan_operations`), the tf frames
of a label (``label_frames``) and serving the store's current generation (``reload``).

They are services like the use cases' (:class:`~cadkg.services.service.Service`, with their
:class:`~cadkg.services.service.Effect`), in the same table, so ``cadkg call``, the HTTP
endpoint (``/api/<name>``) and the ROS node serve them with the same checks and answers.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import partial

from cadkg.errors import CadkgError, QueryError, StateError, StoreError
from cadkg.services.plan_operations import PLAN_OPERATIONS, PlanDocument, Progressed, Replanned
from cadkg.services.service import Effect, Service
from cadkg.services.session import Session
from cadkg.usecase import Answer

__all__ = [
    "OPERATIONS",
    "Assigned",
    "FramesOfLabel",
    "PlanDocument",
    "Progressed",
    "Reloaded",
    "Replanned",
]


@dataclass(frozen=True)
class Assigned(Answer):
    """An assignment made: ``target`` is the IRI of the wire, component or operation."""

    target: str


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
    from cadkg.plan.cell import assigned_by

    kg = session.kg
    target = kg.assign(kind, ident, performer, partial(assigned_by, kg, kind))
    kept = " (kept in the store)" if kg.directory is not None else " (in memory: not kept)"
    return Assigned(True, f"{kind} {ident} → {performer}{kept}", target)


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
        *PLAN_OPERATIONS,
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
