"""Reader of EPLAN's parts-management XML: the connection points of each part number.

EPLAN's article database exports, per part, where each connection point sits (``xpos ypos
zpos`` in the document's ``length-unit``, from the corner of the part's box) and from which
direction a wire enters it (``xdir ydir zdir``). Two shapes are read: ``<terminal
P_PART_TERMINAL_NAME>`` holding ``<terminalPosition>`` points (EPLAN's own export, which
the cell keeps as ``<cabinet>_pins.xml``), and ``<part>`` holding ``<terminal>`` points.
A point becomes a pin frame: its origin at the point, its z axis along the wire entry
direction, its x axis the first of X, Y, Z perpendicular to it (docs/formats/parts-management.md).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, replace
from pathlib import Path

from lxml import etree

from cadkg.errors import IngestError, IngestWarning
from cadkg.geometry.frames import Quaternion, quaternion_from_axes
from cadkg.ingest.xml_input import read_xml_file

__all__ = ["ConnectionPoint", "PartPins", "looks_like_parts_management", "read_parts_management"]

_EXPECTED = '<partsmanagement length-unit="mm"> holding <terminal> or <part> elements with connection points'
_UNITS = {"mm": 0.001, "cm": 0.01, "m": 1.0, "in": 0.0254, "inch": 0.0254}
_PARTS = ("terminal", "part")
_POINTS = {"terminal": "terminalPosition", "part": "terminal"}
_POSITION = ("xpos", "ypos", "zpos")
_DIRECTION = ("xdir", "ydir", "zdir")


@dataclass(frozen=True, slots=True)
class ConnectionPoint:
    """One connection point of a part: where a wire end goes and from which direction.

    ``position`` is in metres from the corner of the part's box; ``orientation`` turns the
    part's frame onto the point's (z along the wire entry direction). A name the part gives
    twice (``L`` of input and output) is ``L`` the first time and ``L~2`` the second.
    """

    name: str
    written_name: str
    position: tuple[float, float, float]
    direction: tuple[float, float, float]
    orientation: Quaternion
    direction_code: str | None
    level: str | None
    device_tag: str | None
    line: int


@dataclass(frozen=True, slots=True)
class PartPins:
    """The connection points of one part number (the commercial code the WRI table gives)."""

    part: str
    dimensions: tuple[float, float, float] | None
    points: tuple[ConnectionPoint, ...]
    line: int


def looks_like_parts_management(head: bytes) -> bool:
    """Whether a file's first bytes open an EPLAN parts-management document."""
    return b"<partsmanagement" in head[:4096]


def read_parts_management(path: str | Path) -> list[PartPins]:
    """Read a parts-management XML export.

    Raises
    ------
    IngestError
        On a file that is not parts-management XML, an unknown length unit, a part without
        a name, a point without a name, position or direction, or a zero direction; at
        file:line.
    """
    root = read_xml_file(path, root="partsmanagement", what="parts-management XML", expected=_EXPECTED)
    return _Reader(path, root).parts()


def _axes(z: tuple[float, float, float]) -> Quaternion:
    # x: the first coordinate axis perpendicular to z, as the cell's software builds it.
    if z[0] == 0:
        x = (1.0, 0.0, 0.0)
    elif z[1] == 0:
        x = (0.0, 1.0, 0.0)
    elif z[2] == 0:
        x = (0.0, 0.0, 1.0)
    else:
        x = (1.0, 1.0, -(z[0] + z[1]) / z[2])
    length = math.sqrt(sum(v * v for v in x))
    x = (x[0] / length, x[1] / length, x[2] / length)
    y = (z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0])
    return quaternion_from_axes(x, y, z)


class _Reader:
    def __init__(self, path: str | Path, root: etree._Element) -> None:
        self.path = path
        self.root = root
        self.warned: set[str] = set()
        unit = (root.get("length-unit") or "mm").strip().lower()
        if unit not in _UNITS:
            raise IngestError(
                path, "unknown length-unit", line=root.sourceline, found=unit, expected=", ".join(_UNITS)
            )
        self.scale = _UNITS[unit]

    def warn(self, reason: str, line: int | None) -> None:
        if reason not in self.warned:
            self.warned.add(reason)
            warnings.warn(IngestWarning(self.path, reason, line=line), stacklevel=4)

    def parts(self) -> list[PartPins]:
        by_name: dict[str, PartPins] = {}
        for element in self.root:
            if not isinstance(element.tag, str):
                continue
            if element.tag not in _PARTS:
                self.warn(
                    f"unknown element <{element.tag}> inside <partsmanagement> skipped", element.sourceline
                )
                continue
            part = self.part(element)
            earlier = by_name.pop(part.part, None)
            if earlier is not None:
                warnings.warn(
                    IngestWarning(
                        self.path,
                        f"part {part.part!r} given twice, on lines {earlier.line} and {part.line};"
                        " the later one is read",
                        line=part.line,
                    ),
                    stacklevel=3,
                )
            by_name[part.part] = part
        if not by_name:
            raise IngestError(
                self.path, "no part inside <partsmanagement>", line=self.root.sourceline, expected=_EXPECTED
            )
        return list(by_name.values())

    def part(self, element: etree._Element) -> PartPins:
        line = element.sourceline or 1
        name = self.required(
            element,
            "P_PART_TERMINAL_NAME",
            f"<{element.tag}> without a part number",
            'P_PART_TERMINAL_NAME="..." (the article number)',
        )
        dims = [element.get(a) for a in ("xdim", "ydim", "zdim")]
        dimensions = None
        if all(d is not None for d in dims):
            x, y, z = (self.number(d or "", a, line) * self.scale for d, a in zip(dims, "xyz", strict=True))
            dimensions = (x, y, z)
        points: list[ConnectionPoint] = []
        seen: dict[str, int] = {}
        for child in element:
            if not isinstance(child.tag, str):
                continue
            if child.tag != _POINTS[element.tag]:
                self.warn(f"unknown element <{child.tag}> inside <{element.tag}> skipped", child.sourceline)
                continue
            for extra in child:
                if isinstance(extra.tag, str):
                    self.warn(f"unknown element <{extra.tag}> inside <{child.tag}> skipped", extra.sourceline)
            point = self.point(child, name)
            seen[point.name] = seen.get(point.name, 0) + 1
            if seen[point.name] > 1:
                self.warn(
                    f"part {name!r} names connection point {point.name!r} {seen[point.name]} times;"
                    f" the later ones are read as {point.name}~2, ~3 ...",
                    child.sourceline,
                )
                point = replace(point, name=f"{point.name}~{seen[point.name]}")
            points.append(point)
        return PartPins(name, dimensions, tuple(points), line)

    def required(self, element: etree._Element, attribute: str, reason: str, expected: str) -> str:
        """The attribute's value, stripped; an error saying ``reason`` when it is missing or empty."""
        value = (element.get(attribute) or "").strip()
        if not value:
            raise IngestError(self.path, reason, line=element.sourceline or 1, expected=expected)
        return value

    def number(self, raw: str, what: str, line: int) -> float:
        try:
            value = float(raw.strip())
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            raise IngestError(
                self.path,
                f"not a number in {what}",
                line=line,
                found=raw,
                expected="a decimal number, e.g. 5.3",
            )
        return value

    def point(self, element: etree._Element, part: str) -> ConnectionPoint:
        line = element.sourceline or 1
        name = self.required(
            element, "name", f"a connection point of part {part!r} without a name", 'name="13"'
        )
        values = {}
        for attribute in (*_POSITION, *_DIRECTION):
            raw = element.get(attribute)
            if raw is None:
                raise IngestError(
                    self.path,
                    f"connection point {name!r} of part {part!r} lacks {attribute}",
                    line=line,
                    expected="xpos, ypos, zpos, xdir, ydir and zdir",
                )
            values[attribute] = self.number(raw, f"{attribute} of connection point {name!r}", line)
        x, y, z = (values[a] * self.scale for a in _POSITION)
        dx, dy, dz = (values[a] for a in _DIRECTION)
        length = math.sqrt(dx * dx + dy * dy + dz * dz)
        if length < 1e-9:
            raise IngestError(
                self.path,
                f"connection point {name!r} of part {part!r} has no wire entry direction",
                line=line,
                found="0 0 0",
                expected="xdir, ydir, zdir not all zero",
            )
        direction = (dx / length, dy / length, dz / length)
        return ConnectionPoint(
            name=name,
            written_name=name,
            position=(x, y, z),
            direction=direction,
            orientation=_axes(direction),
            direction_code=_text(element.get("direction")),
            level=_text(element.get("level")),
            device_tag=_text(element.get("devicetag")),
            line=line,
        )


def _text(value: str | None) -> str | None:
    return value.strip() or None if value is not None else None
