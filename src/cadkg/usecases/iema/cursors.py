"""The cursor services of Table 1: connection providers and the rail scanner.

A cursor is per client (a ROS node, a CLI user) and walks only the work assigned to
the robot: wires, operations and components assigned to a human are skipped. When the store
holds a plan (``cadkg plan``), the cursor walks the plan's robot wires in its order instead.

``full_connection_provider()`` hands out wire *ends*, as the cell's software does: the
origin of the current wire (``source="orig"``), then its destination (``"dest"``), then the
next wire's origin. ``occupancy`` says which end is wanted instead (``false``: the gripper is
empty, the origin, without moving; ``true``: the wire is in hand, its destination, and the
cursor moves on). ``group_connection_provider()`` gives a whole wire and moves on. Both share
one position, so they can be mixed, and ``reset_connection_list`` rewinds it. List positions
count from 0, as the cell's software numbers its list.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from decimal import Decimal, InvalidOperation

from cadkg.geometry.poses import Pose, Vec3
from cadkg.plan.decision import Performer
from cadkg.plan.graph import robot_positions
from cadkg.plan.progress import finished_work
from cadkg.services.session import Session, Work, cursor_done, cursor_rebase, follow
from cadkg.usecase import Answer
from cadkg.usecases.iema.derive.cabinet import CadPin, CellModel, WireStep
from cadkg.usecases.iema.robot_scope import assignments_of

__all__ = [
    "ConnectionEnd",
    "CursorState",
    "DisplayResult",
    "GroupConnection",
    "RailScan",
    "ResetResult",
    "ResetToResult",
    "connection_provider_service",
    "displayed",
    "full_connection_provider",
    "gearbox_display",
    "group_connection_provider",
    "rail_scanner",
    "reset_connection_list",
    "reset_rail_scanner",
    "reset_to_connection_list",
    "state",
]

KEY = "iema"


@dataclass(frozen=True)
class ConnectionEnd:
    """One wire end; ``source`` says which (``orig`` or ``dest``), ``connection_list`` from which file."""

    end: bool
    missing_pin_data: bool = False
    list_position: int = 0
    source: str = ""
    label: str = ""
    pin: str = ""
    direction: bool = True
    component_pose: Pose | None = None
    wire: str = ""
    connection_list: str = ""


@dataclass(frozen=True)
class GroupConnection:
    end: bool
    missing_pin_data: str = ""
    list_position: int = 0
    origin: CadPin | None = None
    destination: CadPin | None = None
    wire: str = ""
    wire_path: str = ""
    path_keypoints: tuple[Pose, ...] = ()


@dataclass(frozen=True)
class RailScan:
    end: bool
    rail: str = ""
    rail_start: Pose | None = None
    component_poses: tuple[Pose, ...] = ()
    components_dimensions: tuple[Vec3, ...] = ()
    components_label: tuple[str, ...] = ()


@dataclass(frozen=True)
class ResetResult:
    success: bool


@dataclass(frozen=True)
class ResetToResult:
    success: bool
    output: str


@dataclass
class CursorState:
    """Where one client is: index into the robot's steps, whether its origin was handed out, rail index."""

    step: int = 0
    holding: bool = False
    rail: int = 0

    def __post_init__(self) -> None:
        # Read back from a cursor file: keep the types whatever the JSON held.
        self.step, self.holding, self.rail = int(self.step), bool(self.holding), int(self.rail)


class _Work:
    """The robot's share of a cabinet model, worked out once per session."""

    def __init__(
        self, model: CellModel, planned: list[int] | None = None, finished: frozenset[str] = frozenset()
    ) -> None:
        self.model = model
        # A stored plan (cadkg plan) gives the robot's wires and their order; else the lists do.
        if planned is not None and all(0 <= p < len(model.steps) for p in planned):
            steps = [model.steps[p] for p in planned]
        else:
            steps = [s for s in model.steps if s.performer is Performer.ROBOT]
        # Wires the cell reported done or failed (cadkg progress) are handed out no more.
        self.steps = [s for s in steps if s.iri not in finished]
        # Per ``source`` argument of reset_to_connection_list: the first robot step of each
        # wire number and of each list position, built on first use.
        self.lookup: dict[str, tuple[dict[Decimal, int], dict[int, int]]] = {}
        assigned = assignments_of(model.performers, model.base, (), model.components)
        self.human_components = {
            label for label in model.components if assigned.get("component", label) is Performer.HUMAN
        }


def _work(session: Session) -> _Work:
    return session.memo(
        "iema-work", lambda: _Work(session.model, robot_positions(session.kg), finished_work(session.kg))
    )


def state(session: Session, client: str) -> CursorState:
    """Where ``client`` is in the connection list and along the rails."""
    return session.cursor(KEY, client, CursorState)


def _current(session: Session, client: str) -> WireStep | None:
    steps = _work(session).steps
    cursor = state(session, client)
    return steps[cursor.step] if cursor.step < len(steps) else None


def full_connection_provider(
    session: Session, occupancy: bool | None = None, client: str = "default"
) -> ConnectionEnd:
    step = _current(session, client)
    if step is None:
        return ConnectionEnd(end=True)
    cursor = state(session, client)
    if occupancy is None:
        # Without the gripper's state, the ends alternate: origin, destination, next origin.
        occupancy = cursor.holding
    pin = step.destination if occupancy else step.origin
    if occupancy:
        cursor.step += 1
        cursor.holding = False
    else:
        cursor.holding = True
    geometry = session.model.components.get(pin.label)
    return ConnectionEnd(
        end=False,
        missing_pin_data=pin.missing,
        list_position=step.position,
        source="dest" if occupancy else "orig",
        label=pin.label,
        pin=pin.pin,
        direction=not occupancy,
        # The approach pose over the component, as the cell's software hands it to the robot.
        component_pose=geometry.target if geometry else None,
        wire=step.wire,
        connection_list=step.source,
    )


def group_connection_provider(session: Session, client: str = "default") -> GroupConnection:
    step = _current(session, client)
    if step is None:
        return GroupConnection(end=True)
    cursor = state(session, client)
    cursor.step += 1
    cursor.holding = False
    components = session.model.components
    origin, destination = (
        replace(pin, component_pose=g.target if (g := components.get(pin.label)) else None)
        for pin in (step.origin, step.destination)
    )
    return GroupConnection(
        end=False,
        missing_pin_data=", ".join(step.missing),
        list_position=step.position,
        origin=origin,
        destination=destination,
        wire=step.wire,
        wire_path=step.path,
        path_keypoints=step.keypoints,
    )


def connection_provider_service(
    session: Session, occupancy: bool | None = None, client: str = "default"
) -> ConnectionEnd:
    """The reference node's older provider: the ends in turn, as ``full_connection_provider()``.

    The node skips some labels by name (terminal blocks, ``P`` devices, two strips); here the
    wires given to people are skipped instead (robot_scope)."""
    return full_connection_provider(session, occupancy, client)


@dataclass(frozen=True)
class DisplayResult(Answer):
    display: bool


def gearbox_display(session: Session, client: str = "default") -> DisplayResult:
    """Publish or stop the cabinet's frames (``LABEL/original``, ``/corner``, ``/target``), in turn.

    The frames go on /tf_static (latched): a listener that already has them keeps them; the
    switch decides what the next publication (and a newly joined listener) gets."""
    switch = session.cursor("iema-display", "cell", _Display)
    switch.on = not switch.on
    message = "cabinet frames published" if switch.on else "cabinet frames withdrawn"
    return DisplayResult(True, message, switch.on)


@dataclass
class _Display:
    """One switch for the whole cell (kept with the cursors), not one per client."""

    on: bool = True

    def __post_init__(self) -> None:
        self.on = bool(self.on)


def displayed(session: Session) -> bool:
    """Whether the cabinet's frames are published (yes until ``gearbox_display`` switches them off)."""
    return session.cursor("iema-display", "cell", _Display).on


def reset_connection_list(session: Session, client: str = "default") -> ResetResult:
    cursor = state(session, client)
    cursor.step, cursor.holding = 0, False
    return ResetResult(True)


def reset_to_connection_list(
    session: Session, data: float, source: str = "", connection_list: str = "", client: str = "default"
) -> ResetToResult:
    """Move the cursor to list position ``data`` (from 0), else to the wire numbered ``data``.

    ``source`` says which end comes next, ``orig`` (also when empty) or ``dest``, as in the cell's
    software; ``connection_list`` picks the list (its path, file name or stem) when a cell has several.
    A whole number is a list position first, as the cell's software reads it; a wire number is
    compared as a number (1500.5 matches 1500.50).
    """
    if source not in ("", "orig", "dest"):
        return ResetToResult(
            False, f"source {source!r}: expected orig or dest (the list is connection_list=)"
        )
    by_wire, by_position = _lookup_of(_work(session), connection_list)
    if not by_position:
        return ResetToResult(False, f"no connection list {connection_list!r} with robot work")
    index = by_position.get(int(data)) if float(data).is_integer() else None
    if index is None:
        index = by_wire.get(Decimal(repr(float(data))).normalize())
    if index is None:
        return ResetToResult(False, f"no robot list position {data:g} and no robot wire numbered {data:g}")
    cursor = state(session, client)
    step = _work(session).steps[index]
    cursor.step, cursor.holding = index, source == "dest"
    end = "destination" if cursor.holding else "origin"
    return ResetToResult(
        True, f"next: the {end} of list position {step.position} of {step.source}, wire {step.wire}"
    )


def _lookup_of(work: _Work, source: str) -> tuple[dict[Decimal, int], dict[int, int]]:
    """Wire number → and list position → index of the first robot step of ``source``'s list."""
    lookup = work.lookup.get(source)
    if lookup is None:
        by_wire: dict[Decimal, int] = {}
        by_position: dict[int, int] = {}
        for i, s in enumerate(work.steps):
            names = (s.source, s.source.rsplit("/", 1)[-1], s.source.rsplit(".", 1)[0])
            if source and source not in names:
                continue
            number = _as_decimal(s.wire)
            if number is not None and number.is_finite():
                by_wire.setdefault(number, i)
            by_position.setdefault(s.position, i)
        lookup = work.lookup[source] = (by_wire, by_position)
    return lookup


def rail_scanner(session: Session, client: str = "default") -> RailScan:
    cursor = state(session, client)
    model: CellModel = session.model
    if cursor.rail >= len(model.rails):
        return RailScan(end=True)
    rail = model.rails[cursor.rail]
    cursor.rail += 1
    labels = [c for c in rail.components if c not in _work(session).human_components]
    geometries = [model.components[c] for c in labels]
    return RailScan(
        end=False,
        rail=rail.label,
        rail_start=rail.start,
        component_poses=tuple(g.original for g in geometries if g.original is not None),
        components_dimensions=tuple(g.dimensions or (0.0, 0.0, 0.0) for g in geometries),
        components_label=tuple(labels),
    )


def reset_rail_scanner(session: Session, client: str = "default") -> ResetResult:
    state(session, client).rail = 0
    return ResetResult(True)


def _as_decimal(text: str) -> Decimal | None:
    try:
        return Decimal(text).normalize()
    except InvalidOperation:
        return None


def _ends(step: WireStep) -> tuple[str, str]:
    return (f"{step.origin.label}:{step.origin.pin}", f"{step.destination.label}:{step.destination.pin}")


# A wire by its number and ends, then by its ends (renumbered), then by its number (an end changed).
_WIRE_IDENTITIES = (
    lambda s: (s.wire, *_ends(s)),
    lambda s: tuple(sorted(_ends(s))),
    lambda s: s.wire,
)


@cursor_rebase(KEY)
def _rebase(old: Session, new: Session, cursor: CursorState) -> str:
    """Keep ``cursor`` on the same wire of the robot's list, and its rail scan on the same rail."""
    before, after = _work(old).steps, _work(new).steps
    rails = [r.label for r in new.model.rails]
    if cursor.rail < len(old.model.rails):
        label = old.model.rails[cursor.rail].label
        cursor.rail = rails.index(label) if label in rails else cursor.rail
    if cursor.step >= len(before):
        cursor.step, cursor.holding = len(after), False
        return "at the end of the list"
    wire = before[cursor.step].wire
    cursor.step, skipped = follow(before, cursor.step, after, _WIRE_IDENTITIES)
    if skipped:
        cursor.holding = False
    if cursor.step >= len(after):
        return f"wire {wire} and every robot wire after it are gone: at the end of the list"
    here = after[cursor.step].wire
    if skipped:
        return f"wire {wire} is gone (or no longer the robot's): on wire {here}, the next still there"
    return f"on wire {here}" + ("" if here == wire else f" (was {wire})")


@cursor_done(KEY, CursorState)
def _done(session: Session, cursor: CursorState) -> list[Work]:
    """The robot's wires before the cursor, and the one whose origin it has handed out."""
    steps = _work(session).steps
    passed = steps[: cursor.step + (1 if cursor.holding else 0)]
    return [Work("wire", step.wire, step.iri) for step in passed]
