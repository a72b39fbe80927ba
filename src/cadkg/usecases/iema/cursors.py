"""The cursor services of Table 1: connection providers and the rail scanner.

A cursor is per client (a ROS node, a CLI user) and walks only the work assigned to
the robot: wires, operations and components assigned to a human are skipped.

``full_connection_provider(occupancy)`` hands out wire *ends*: with the gripper
empty (``occupancy=False``) it gives the origin of the current wire and does not
move; with the wire in hand (``occupancy=True``) it gives the destination and moves
to the next wire. ``group_connection_provider()`` gives a whole wire and moves on.
Both share one position, so they can be mixed, and ``reset_connection_list`` rewinds it.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from decimal import Decimal, InvalidOperation
from typing import Any, TypeVar, cast

from cadkg.usecases.iema.cabinet import CadPin, CellModel, WireStep
from cadkg.geometry.poses import Pose, Vec3
from cadkg.errors import QueryError
from cadkg.mapping.core import node_iri

T = TypeVar("T")

__all__ = [
    "ConnectionEnd",
    "CursorState",
    "GroupConnection",
    "RailScan",
    "ResetResult",
    "ResetToResult",
    "Session",
]


@dataclass(frozen=True)
class ConnectionEnd:
    end: bool
    missing_pin_data: bool = False
    list_position: int = 0
    source: str = ""
    label: str = ""
    pin: str = ""
    direction: bool = True
    component_pose: Pose | None = None
    wire: str = ""


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


@dataclass
class Session:
    """What the services of one served cell share: the cabinet model, the cursors of every
    client, the graph, and the models of the other profiles, each built on first use."""

    model: CellModel
    states: dict[str, CursorState] = field(default_factory=dict)
    kg: Any = None
    _models: dict[str, Any] = field(default_factory=dict, repr=False)

    def profile_model(self, key: str, build: Callable[[Any], T]) -> T:
        """The model ``build(kg)`` of a profile, built once per session (so once per reload)."""
        if key not in self._models:
            if self.kg is None:
                raise QueryError(f"the {key} services need a graph; this session has none")
            self._models[key] = build(self.kg)
        return cast(T, self._models[key])

    def forget(self, key: str) -> None:
        """Drop the model of a profile, so the next call rebuilds it from the (changed) graph."""
        self._models.pop(key, None)

    def __post_init__(self) -> None:
        self._robot_steps = [s for s in self.model.steps if s.performer == "robot"]
        # Per ``source`` argument of reset_to_connection_list: the first robot step of each
        # wire number and of each list position, built on first use.
        self._lookup: dict[str, tuple[dict[Decimal, int], dict[int, int]]] = {}
        self._human_components = {
            label
            for label in self.model.components
            if self.model.performers.get(node_iri(self.model.base, "component", label)) == "human"
        }

    def state(self, client: str) -> CursorState:
        return self.states.setdefault(client, CursorState())

    def dump(self) -> dict[str, dict[str, object]]:
        return {client: asdict(state) for client, state in self.states.items()}

    def load(self, data: dict[str, dict[str, object]]) -> None:
        for client, values in data.items():
            self.states[client] = CursorState(
                int(values.get("step", 0)),  # type: ignore[call-overload]
                bool(values.get("holding", False)),
                int(values.get("rail", 0)),  # type: ignore[call-overload]
            )

    # -- connections ------------------------------------------------------------
    def _current(self, client: str) -> WireStep | None:
        state = self.state(client)
        return self._robot_steps[state.step] if state.step < len(self._robot_steps) else None

    def full_connection_provider(self, occupancy: bool, client: str = "default") -> ConnectionEnd:
        step = self._current(client)
        if step is None:
            return ConnectionEnd(end=True)
        state = self.state(client)
        pin = step.destination if occupancy else step.origin
        if occupancy:
            state.step += 1
            state.holding = False
        else:
            state.holding = True
        geometry = self.model.components.get(pin.label)
        return ConnectionEnd(
            end=False,
            missing_pin_data=pin.missing,
            list_position=step.position,
            source=step.source,
            label=pin.label,
            pin=pin.pin,
            direction=not occupancy,
            component_pose=geometry.original if geometry else None,
            wire=step.wire,
        )

    def group_connection_provider(self, client: str = "default") -> GroupConnection:
        step = self._current(client)
        if step is None:
            return GroupConnection(end=True)
        state = self.state(client)
        state.step += 1
        state.holding = False
        return GroupConnection(
            end=False,
            missing_pin_data=", ".join(step.missing),
            list_position=step.position,
            origin=step.origin,
            destination=step.destination,
            wire=step.wire,
            wire_path=";".join(step.ducts),
            path_keypoints=step.keypoints,
        )

    def reset_connection_list(self, client: str = "default") -> ResetResult:
        state = self.state(client)
        state.step, state.holding = 0, False
        return ResetResult(True)

    def reset_to_connection_list(
        self, data: float, source: str = "", client: str = "default"
    ) -> ResetToResult:
        """Move the cursor to the wire numbered ``data`` (1500.5 matches 1500.50), else to position ``data``.

        ``source`` picks the connection list (its path, file name or stem) when a cell has several.
        """
        by_wire, by_position = self._lookup_of(source)
        if not by_position:
            return ResetToResult(False, f"no connection list {source!r} with robot work")
        index = by_wire.get(Decimal(repr(float(data))).normalize())
        if index is None and float(data).is_integer():
            index = by_position.get(int(data))
        if index is None:
            return ResetToResult(False, f"no robot wire numbered {data:g} and no list position {data:g}")
        state = self.state(client)
        step = self._robot_steps[index]
        state.step, state.holding = index, False
        return ResetToResult(True, f"next: list position {step.position} of {step.source}, wire {step.wire}")

    def _lookup_of(self, source: str) -> tuple[dict[Decimal, int], dict[int, int]]:
        """Wire number → and list position → index of the first robot step of ``source``'s list."""
        lookup = self._lookup.get(source)
        if lookup is None:
            by_wire: dict[Decimal, int] = {}
            by_position: dict[int, int] = {}
            for i, s in enumerate(self._robot_steps):
                names = (s.source, s.source.rsplit("/", 1)[-1], s.source.rsplit(".", 1)[0])
                if source and source not in names:
                    continue
                number = _as_decimal(s.wire)
                if number is not None and number.is_finite():
                    by_wire.setdefault(number, i)
                by_position.setdefault(s.position, i)
            lookup = self._lookup[source] = (by_wire, by_position)
        return lookup

    # -- rails ------------------------------------------------------------------------
    def rail_scanner(self, client: str = "default") -> RailScan:
        state = self.state(client)
        if state.rail >= len(self.model.rails):
            return RailScan(end=True)
        rail = self.model.rails[state.rail]
        state.rail += 1
        labels = [c for c in rail.components if c not in self._human_components]
        geometries = [self.model.components[c] for c in labels]
        return RailScan(
            end=False,
            rail=rail.label,
            rail_start=rail.start,
            component_poses=tuple(g.original for g in geometries if g.original is not None),
            components_dimensions=tuple(g.dimensions or (0.0, 0.0, 0.0) for g in geometries),
            components_label=tuple(labels),
        )

    def reset_rail_scanner(self, client: str = "default") -> ResetResult:
        self.state(client).rail = 0
        return ResetResult(True)


def _as_decimal(text: str) -> Decimal | None:
    try:
        return Decimal(text).normalize()
    except InvalidOperation:
        return None
