"""The reference CAD platform node's services about the harnesses' components
(``CAD_platform/connector_info``, ``CAD_platform/cable_info``), transport-free.

As the reference computes them: colours by name, lengths, diameters and sizes in millimetres
as the components file gives them, cavities as [row, column] text. An unknown label is
``success=False`` with a message (the reference answered any label of connector_info with
success).
"""

from __future__ import annotations

from dataclasses import dataclass

from cadkg.usecase import Answer
from cadkg.usecases.elvez.files.harnesses import split_tray
from cadkg.usecases.elvez.model import ElvezModel, known

__all__ = ["ConnectorInfoResult", "PinsData", "PlatformCableInfoResult", "cable_info", "connector_info"]


@dataclass(frozen=True)
class PinsData:
    """A connector or cable and the cavity it names: ``pins`` = [row, column] as text."""

    label: str
    pins: tuple[str, ...]


@dataclass(frozen=True)
class ConnectorInfoResult(Answer):
    component: str = ""
    reference: str = ""
    model: str = ""
    type: str = ""
    color: str = ""
    wh: str = ""
    box: str = ""
    tray: str = ""
    cables: tuple[PinsData, ...] = ()
    dimensions: tuple[float, ...] = ()


@dataclass(frozen=True)
class PlatformCableInfoResult(Answer):
    component: str = ""
    color: str = ""
    length: float = 0.0
    diameter: float = 0.0
    wh: str = ""
    box: str = ""
    tray: str = ""
    connectors: tuple[PinsData, ...] = ()


def _mm(value: float | None) -> float:
    return round(value * 1000, 6) if value is not None else 0.0


def connector_info(model: ElvezModel, label: str) -> ConnectorInfoResult:
    """A connector or device: its kind (CON, DEV), colour, reference, model, size (mm) or
    device type; for a harness's first connector every cable of the harness, for an end
    connector its own, each with its cavity in the first connector."""
    label = label.strip()
    component = model.components.get(label)
    kind = {"connector": "CON", "device": "DEV"}.get(component.kind, "") if component is not None else ""
    cables: list[PinsData] = []
    wh = box = tray = ""
    for harness in model.harnesses:
        ends = (
            harness.end_connectors
            if harness.first_connector == label
            else [e for e in harness.end_connectors if e.label == label]
        )
        if ends:
            wh, (box, tray) = harness.id, split_tray(harness.tray)
            cables = [
                PinsData(c.label, tuple(str(v) for v in c.first_cavity)) for e in ends for c in e.cables
            ]
    if component is None or not kind:
        if not wh:
            connectors = [c.label for c in model.components.values() if c.kind != "cable"]
            return ConnectorInfoResult(
                False, f"no connector or device {label!r}; connectors and devices: {known(connectors)}"
            )
        return ConnectorInfoResult(
            True,
            f"{label}: not in the components definition",
            wh=wh,
            box=box,
            tray=tray,
            cables=tuple(cables),
        )
    size = component.size if kind == "CON" else None
    return ConnectorInfoResult(
        True,
        label,
        component=kind,
        reference=component.reference if kind == "CON" else "",
        model=component.model,
        type=component.device_type if kind == "DEV" else "",
        color=component.colour,
        wh=wh,
        box=box,
        tray=tray,
        cables=tuple(cables),
        dimensions=tuple(_mm(v) for v in size) if size else (),
    )


def cable_info(model: ElvezModel, label: str) -> PlatformCableInfoResult:
    """A cable: colour, length and diameter (mm), harness, box, tray, and the cavities it sits
    in: [row, column] in the first connector, and in its end connector when given."""
    label = label.strip()
    component = model.components.get(label)
    if component is None or component.kind != "cable":
        cables = [c.label for c in model.components.values() if c.kind == "cable"]
        return PlatformCableInfoResult(False, f"no cable {label!r}; cables: {known(cables)}")
    found = model.harness_of(label)
    connectors: tuple[PinsData, ...] = ()
    wh = box = tray = ""
    harness, end, cable = found if found is not None else (None, None, None)
    if harness is not None and end is not None and cable is not None:
        wh, (box, tray) = harness.id, split_tray(harness.tray)
        connectors = (
            PinsData(harness.first_connector, tuple(str(v) for v in cable.first_cavity)),
            PinsData(end.label, tuple(str(v) for v in cable.end_cavity or ())),
        )
    return PlatformCableInfoResult(
        True,
        f"cable {label}" + ("" if wh else ": in no harness of the harness configuration"),
        "CAB",
        component.colour,
        _mm(component.length),
        _mm(component.diameter),
        wh,
        box,
        tray,
        connectors,
    )
