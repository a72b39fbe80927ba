"""The IEMA services of the reference's Table 1, transport-free, as plain functions of the cell model.

Each function answers from :class:`~cadkg.usecases.iema.derive.cabinet.CellModel` (computed from the
graph once per change) and returns a typed result. An unknown label gives
``success=False`` and a message, never an exception. The cursor services
(connection providers, rail scanner) live in :mod:`cadkg.usecases.iema.cursors`.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, TypeVar

from cadkg.geometry.poses import Pose, Vec3
from cadkg.ingest.eplan.labels import normalize_label
from cadkg.usecase import Answer
from cadkg.usecases.iema.derive.cabinet import CadPin, CellModel, Cluster, ComponentGeometry, WireStep

__all__ = [
    "CadConnection",
    "CadReferenceResult",
    "CadServiceResult",
    "ClusterResult",
    "FullCadServiceResult",
    "ItemScrewResult",
    "PinData",
    "TerminalDataResult",
    "cad_reference",
    "cad_service",
    "cluster_service",
    "connection_of",
    "full_cad_service",
    "get_item_screw_service",
    "get_item_screw_targets",
    "get_terminal_data",
]


@dataclass(frozen=True)
class CadConnection:
    """A connection a component takes part in (``full_cad_service``).

    As the reference node's ``cad_connection``: ``source`` is the component's end (``orig`` or
    ``dest``), ``pin`` its pin with its ``screw_pose`` and ``hole_pose``, ``target_item`` and
    ``target_pin`` the other end's CAD item and pin. ``connection_list`` is the list's file.
    """

    wire: str
    list_position: int
    source: str
    origin: str
    destination: str
    performer: str
    missing_pin_data: bool
    # Why a rule gave the wire to a person (zone, label not in the CAD); empty otherwise.
    reason: str = ""
    pin: str = ""
    target_item: str = ""
    target_pin: str = ""
    screw_pose: Pose | None = None
    hole_pose: Pose | None = None
    connection_list: str = ""


@dataclass(frozen=True)
class _ComponentAnswer(Answer):
    """What the two CAD services say of a component first: where to grip it, its corner, its
    pose in the scene and its size."""

    target_pose: Pose | None = None
    corner_pose: Pose | None = None
    original_pose: Pose | None = None
    dimensions: Vec3 | None = None


_C = TypeVar("_C", bound=_ComponentAnswer)


@dataclass(frozen=True)
class CadServiceResult(_ComponentAnswer):
    pins: tuple[CadPin, ...] = ()


@dataclass(frozen=True)
class FullCadServiceResult(_ComponentAnswer):
    connections: tuple[CadConnection, ...] = ()


@dataclass(frozen=True)
class PinData:
    """What a screwdriver or inserter needs to know of one pin end (the table's ``pyn_type``)."""

    pin: str
    wire: str | None
    termination: str | None
    exact: bool


@dataclass(frozen=True)
class ItemScrewResult(Answer):
    pins: tuple[str, ...] = ()
    screws: tuple[Pose, ...] = ()
    holes: tuple[Pose, ...] = ()
    screw_data: tuple[PinData, ...] = ()
    hole_data: tuple[PinData, ...] = ()


@dataclass(frozen=True)
class TerminalDataResult(Answer):
    pins: tuple[str, ...] = ()
    terminal_start: Pose | None = None
    screws: tuple[Pose, ...] = ()
    holes: tuple[Pose, ...] = ()
    length: float = 0.0
    height: float = 0.0


@dataclass(frozen=True)
class ClusterResult(Answer):
    horizontal: tuple[Cluster, ...] = ()
    vertical: tuple[Cluster, ...] = ()


@dataclass(frozen=True)
class CadReferenceResult(Answer):
    target_pose: Pose | None = None
    corner_pose: Pose | None = None


def _find(model: CellModel, label: str) -> tuple[ComponentGeometry | None, str]:
    key = normalize_label(label) if label else label
    geometry = model.components.get(key)
    if geometry is None:
        return None, f"unknown label {label!r}"
    if geometry.original is None:
        return geometry, f"{key}: no pose in the CAD scene (no scene item for its CAD items)"
    return geometry, "ok"


def _pins_sorted(geometry: ComponentGeometry) -> list[CadPin]:
    return sorted(geometry.pins.values(), key=lambda p: _natural(p.pin))


def _natural(text: str) -> tuple[tuple[int, int, str], ...]:
    # A run of digits compares by its value: fewer digits (leading zeros aside) is smaller,
    # then digit by digit; no int(), which refuses runs of over 4,300 digits.
    return tuple(
        (0, len(t.lstrip("0")), t.lstrip("0")) if t[0] in "0123456789" else (1, 0, t)
        for t in re.findall(r"[0-9]+|[^0-9]+", text)
    )


def _placed(kind: type[_C], geometry: ComponentGeometry, message: str, **rest: Any) -> _C:
    """The answer of a CAD service on a component found in the scene: its poses and size, then
    the ``rest``."""
    return kind(
        True, message, geometry.target, geometry.corner, geometry.original, geometry.dimensions, **rest
    )


def cad_service(model: CellModel, label: str) -> CadServiceResult:
    """Morphology of a component: target, corner and original pose, dimensions, pins."""
    geometry, message = _find(model, label)
    if geometry is None or geometry.original is None:
        return CadServiceResult(False, message)
    return _placed(CadServiceResult, geometry, message, pins=tuple(_pins_sorted(geometry)))


def connection_of(step: WireStep, here: CadPin | None = None) -> CadConnection:
    """A wire seen from its end ``here`` (its origin when not given)."""
    here = here or step.origin
    there = step.destination if here is step.origin else step.origin
    return CadConnection(
        wire=step.wire,
        list_position=step.position,
        source="orig" if here is step.origin else "dest",
        origin=f"{step.origin.label}:{step.origin.pin}",
        destination=f"{step.destination.label}:{step.destination.pin}",
        performer=step.performer,
        missing_pin_data=bool(step.missing),
        reason=step.reason,
        pin=here.pin,
        target_item=there.item or "",
        target_pin=there.pin,
        screw_pose=here.screw,
        hole_pose=here.hole,
        connection_list=step.source,
    )


def full_cad_service(model: CellModel, label: str = "", cad_item: str = "") -> FullCadServiceResult:
    """As :func:`cad_service`, with the connections the component takes part in, in list order.

    By ``cad_item`` (as the reference node's request): the component that item belongs to, and
    the wire ends on that item's pins (a wire between two of them counts twice).
    """
    if cad_item:
        label = next((g.label for g in model.components.values() if cad_item in g.items), "")
        if not label:
            return FullCadServiceResult(False, f"unknown CAD item {cad_item!r}")
    geometry, message = _find(model, label)
    if geometry is None or geometry.original is None:
        return FullCadServiceResult(False, message)
    connections = []
    for step in model.steps_of(geometry.label):
        ends = [end for end in (step.origin, step.destination) if end.label == geometry.label]
        if cad_item:
            connections += [connection_of(step, end) for end in ends if end.item == cad_item]
        else:
            connections.append(connection_of(step, ends[0]))
    return _placed(FullCadServiceResult, geometry, message, connections=tuple(connections))


def get_item_screw_service(model: CellModel, label: str, detected_pose: Pose) -> ItemScrewResult:
    """Screws and holes re-expressed from where a camera found the component.

    ``detected_pose`` is the detected pose of the component's frame (its original
    pose in the CAD), in the same parent frame; every pin moves rigidly with it.
    """
    geometry, message = _find(model, label)
    if geometry is None or geometry.original is None:
        return ItemScrewResult(False, message)
    return _moved(model, geometry, message, detected_pose * geometry.original.inverse())


def get_item_screw_targets(model: CellModel, label: str, cad_pose: Pose) -> ItemScrewResult:
    """As :func:`get_item_screw_service`, the reference node's request: ``cad_pose`` is where the
    component's *target* pose was detected. The pins move rigidly with it (the node shifts their
    x and y only: docs/iema-services.md, Differences from the reference node)."""
    geometry, message = _find(model, label)
    if geometry is None or geometry.target is None:
        return ItemScrewResult(False, message if geometry is None else f"{geometry.label}: no target pose")
    return _moved(model, geometry, message, cad_pose * geometry.target.inverse())


def _moved(model: CellModel, geometry: ComponentGeometry, message: str, shift: Pose) -> ItemScrewResult:
    ends = model.ends_of(geometry.label)
    pins, screws, holes, screw_data, hole_data = [], [], [], [], []
    for pin in _pins_sorted(geometry):
        if pin.missing:
            continue
        screw = pin.screw or pin.hole
        hole = pin.hole or pin.screw
        assert screw is not None and hole is not None
        wire, termination = ends.get(pin.pin, (None, None))
        pins.append(pin.pin)
        screws.append(shift * screw)
        holes.append(shift * hole)
        screw_data.append(PinData(pin.pin, wire, termination, pin.screw is not None))
        hole_data.append(PinData(pin.pin, wire, termination, pin.hole is not None))
    return ItemScrewResult(
        True, message, tuple(pins), tuple(screws), tuple(holes), tuple(screw_data), tuple(hole_data)
    )


def get_terminal_data(model: CellModel, label: str) -> TerminalDataResult:
    """A terminal block's pins in block order, where it starts, its length and height."""
    geometry, message = _find(model, label)
    if geometry is None or geometry.original is None:
        return TerminalDataResult(False, message)
    if not geometry.terminal_block:
        return TerminalDataResult(False, f"{geometry.label} is not a terminal block")
    order = {item: i for i, item in enumerate(geometry.items)}
    pins = sorted(
        (p for p in geometry.pins.values() if not p.missing),
        key=lambda p: (order.get(p.item or "", len(order)), _natural(p.pin)),
    )
    return TerminalDataResult(
        True,
        message,
        tuple(p.pin for p in pins),
        geometry.terminal_start,
        tuple(p.screw or p.hole for p in pins),  # type: ignore[misc]
        tuple(p.hole or p.screw for p in pins),  # type: ignore[misc]
        geometry.length or 0.0,
        geometry.height or 0.0,
    )


def cluster_service(model: CellModel, label: str) -> ClusterResult:
    """The component's connector points grouped by height (horizontal) and by column (vertical)."""
    geometry, message = _find(model, label)
    if geometry is None or geometry.original is None:
        return ClusterResult(False, message)
    horizontal, vertical = model.clusters.get(geometry.label, ([], []))
    return ClusterResult(True, message, tuple(horizontal), tuple(vertical))


def cad_reference(model: CellModel, label: str) -> CadReferenceResult:
    """Only the target and corner pose of a component."""
    geometry, message = _find(model, label)
    if geometry is None or geometry.original is None:
        return CadReferenceResult(False, message)
    return CadReferenceResult(True, message, geometry.target, geometry.corner)
