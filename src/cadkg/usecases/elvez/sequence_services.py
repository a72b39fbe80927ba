"""The assembly sequence as the reference node serves it: every operation, one by index, and
a cursor per client that hands out the next one.

The cursor belongs to a client (``client``, ``default`` when empty): ``next_operation`` gives
the operation at the cursor and moves it on, ``end`` is true on the answer that carries the
last operation and the cursor starts again; ``index_operation`` (from 0) moves the cursor to an
operation and answers as ``next_operation`` with the new cursor as ``index``;
``all_operations`` rewinds it, as the reference does. Every answer gives spots in one form:
element (``jig``), guide (``id``) and, for EC and PC, ``side``.

When the store holds a plan (``cadkg plan``), the cursor walks the plan's robot operations in
the plan's order; operations are still named by their index in the sequence.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from cadkg.plan.graph import robot_positions
from cadkg.plan.progress import finished_work
from cadkg.services.session import Session, Work, cursor_done, cursor_rebase, follow
from cadkg.usecase import Answer
from cadkg.usecases.elvez.files.sequence import SequenceStep
from cadkg.usecases.elvez.model import PROFILE, ElvezModel, model_of, operation_iris, unresolved

__all__ = [
    "AllOperationsResult",
    "IndexOperationResult",
    "NextOperationResult",
    "OperationItem",
    "SequenceCursor",
    "SequenceResetResult",
    "SpotData",
    "all_operations",
    "index_operation",
    "next_operation",
    "reset_sequence_list",
    "reset_sequence_list_to",
]


@dataclass
class SequenceCursor:
    """Where one client is in the sequence: the index (from 0) of its next operation."""

    position: int = 0

    def __post_init__(self) -> None:
        self.position = int(self.position)  # read back from a cursor file: keep the type


@dataclass(frozen=True)
class SpotData:
    jig: str
    id: str
    side: str


@dataclass(frozen=True)
class OperationItem:
    type: str
    label: tuple[str, ...]
    spot: tuple[SpotData, ...]


@dataclass(frozen=True)
class NextOperationResult(Answer):
    type: str = ""
    label: tuple[str, ...] = ()
    spot: tuple[SpotData, ...] = ()
    end: bool = False


@dataclass(frozen=True)
class IndexOperationResult(Answer):
    index: int = 0
    type: str = ""
    label: tuple[str, ...] = ()
    spot: tuple[SpotData, ...] = ()
    end: bool = False


@dataclass(frozen=True)
class SequenceResetResult(Answer):
    """A reset of the sequence cursor: whether it moved, and to which operation."""


@dataclass(frozen=True)
class AllOperationsResult(Answer):
    data: tuple[OperationItem, ...] = ()


def _item(step: SequenceStep) -> OperationItem:
    return OperationItem(step.code, step.labels, tuple(SpotData(s.jig, s.guide, s.side) for s in step.spots))


def _cursor(session: Session, client: str) -> SequenceCursor:
    return session.cursor(PROFILE, client or "default", SequenceCursor)


def _describe(model: ElvezModel, position: int) -> str:
    step = model.sequence[position]
    notes = unresolved(model, step)
    text = (
        f"operation {position} (order {step.order}): {step.code} {'-'.join(step.labels)} at {step.spot_text}"
    )
    return text + ("; " + "; ".join(notes) if notes else "")


def _order(session: Session, model: ElvezModel) -> list[int]:
    """The sequence indices the cursor walks: the stored plan's robot operations, else all."""
    planned = session.memo("elvez-plan-order", lambda: robot_positions(session.kg))
    if planned is None or not all(0 <= p < len(model.sequence) for p in planned):
        planned = list(range(len(model.sequence)))
    finished = session.memo("elvez-finished", lambda: _finished_positions(session.kg, model))
    return [p for p in planned if p not in finished] if finished else planned


def _finished_positions(kg: Any, model: ElvezModel) -> frozenset[int]:
    """The sequence indices of the operations the cell reported done or failed (cadkg progress)."""
    finished = finished_work(kg)
    if not finished:
        return frozenset()
    lines = {line for line, iri in operation_iris(kg).items() if iri in finished}
    return frozenset(n for n, step in enumerate(model.sequence) if step.line in lines)


def _hand_out(
    model: ElvezModel, order: list[int], cursor: SequenceCursor, position: int
) -> tuple[OperationItem, bool, str]:
    item, message = _item(model.sequence[position]), _describe(model, position)
    if position in order:
        cursor.position = order.index(position) + 1
    end = cursor.position >= len(order)
    if end:
        cursor.position = 0
        message += "; end of the sequence"
    return item, end, message


def next_operation(session: Session, client: str = "default") -> NextOperationResult:
    """The operation at the client's cursor; the cursor moves on (to 0 after the last)."""
    model = model_of(session)
    order = _order(session, model)
    if not order:
        return NextOperationResult(False, "the cell has no assembly sequence with robot operations")
    cursor = _cursor(session, client)
    if cursor.position >= len(order):
        cursor.position = 0
    item, end, message = _hand_out(model, order, cursor, order[cursor.position])
    return NextOperationResult(True, message, item.type, item.label, item.spot, end)


def index_operation(session: Session, index: int, client: str = "default") -> IndexOperationResult:
    """The operation at ``index`` (from 0); the client's cursor moves past it, and ``index``
    of the answer is where it is now."""
    model = model_of(session)
    count = len(model.sequence)
    if not 0 <= index < count:
        return IndexOperationResult(
            False, f"no operation {index}; the sequence has operations 0 to {count - 1}"
        )
    cursor = _cursor(session, client)
    item, end, message = _hand_out(model, _order(session, model), cursor, index)
    return IndexOperationResult(True, message, cursor.position, item.type, item.label, item.spot, end)


def reset_sequence_list(session: Session, client: str = "default") -> SequenceResetResult:
    """Rewind the client's cursor to the first operation."""
    _cursor(session, client).position = 0
    return SequenceResetResult(True, "next: operation 0")


def reset_sequence_list_to(session: Session, index: int, client: str = "default") -> SequenceResetResult:
    """Move the client's cursor to operation ``index`` (from 0)."""
    model = model_of(session)
    count, order = len(model.sequence), _order(session, model)
    if not 0 <= index < count:
        return SequenceResetResult(
            False, f"no operation {index}; the sequence has operations 0 to {count - 1}"
        )
    if index not in order:
        return SequenceResetResult(False, f"operation {index} is a person's in the plan")
    _cursor(session, client).position = order.index(index)
    return SequenceResetResult(True, f"next: operation {index}")


def all_operations(session: Session, client: str = "default") -> AllOperationsResult:
    """Every operation in sequence order; rewinds the client's cursor, as the reference does."""
    model = model_of(session)
    _cursor(session, client).position = 0
    notes = [f"operation {i}: {n}" for i, step in enumerate(model.sequence) for n in unresolved(model, step)]
    message = f"{len(model.sequence)} operations" + ("; " + "; ".join(notes) if notes else "")
    return AllOperationsResult(True, message, tuple(_item(s) for s in model.sequence))


# An operation by its code, labels and spots, then by its code and labels (moved to other spots).
_OPERATION_IDENTITIES = (
    lambda s: (s.code, s.labels, s.spot_text),
    lambda s: (s.code, s.labels),
)


@cursor_rebase(PROFILE)
def _rebase(old: Session, new: Session, cursor: SequenceCursor) -> str:
    """Keep ``cursor`` on the same operation of the assembly sequence."""
    before, after = model_of(old).sequence, model_of(new).sequence
    if cursor.position >= len(before):
        cursor.position = 0
        return "at the start of the sequence"
    was = before[cursor.position]
    cursor.position, skipped = follow(before, cursor.position, after, _OPERATION_IDENTITIES)
    name = f"{was.code} {' '.join(was.labels)}"
    if cursor.position >= len(after):
        cursor.position = 0
        return f"operation {name} and every one after it are gone: at the start of the sequence"
    if skipped:
        return f"operation {name} is gone: on the next one still there, index {cursor.position}"
    return f"on operation {name}, index {cursor.position}"


@cursor_done(PROFILE, SequenceCursor)
def _done(session: Session, cursor: SequenceCursor) -> list[Work]:
    """The operations the cursor has passed (in the plan's order when there is one), by code
    and labels."""
    model = model_of(session)
    passed = [model.sequence[i] for i in _order(session, model)[: cursor.position]]
    return [Work("operation", f"{s.code} {';'.join(s.labels)}") for s in passed]
