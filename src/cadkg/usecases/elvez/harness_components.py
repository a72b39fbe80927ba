"""Reader of the harness components list: every cable, connector and capacitor with its attributes.

A delimited text file (comma, semicolon or tab) with a header row naming its columns;
lengths in millimetres, colours as red, green, blue from 0 to 255 (D3.1 section 4.3, Table 2
``cable_info`` and ``con_info``). Records hold metres. See docs/formats/elvez-components.md.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.text import (
    Row,
    check_columns,
    find_header,
    first_line,
    named_columns,
    parse_decimal,
    read_text,
    split_cells,
)

__all__ = ["COMPONENT_KINDS", "HarnessComponent", "looks_like_harness_components", "read_harness_components"]

COMPONENT_KINDS = ("cable", "connector", "capacitor")
_COLUMNS = (
    "name",
    "type",
    "red",
    "green",
    "blue",
    "diameter_mm",
    "length_mm",
    "x_mm",
    "y_mm",
    "z_mm",
    "description",
)
_REQUIRED = ("name", "type", "red", "green", "blue", "diameter_mm", "length_mm", "x_mm", "y_mm", "z_mm")
_SIGNATURE = {"name", "type", "red", "green", "blue"}
_EXPECTED = (
    "a header row: name, type, red, green, blue, diameter_mm, length_mm, x_mm, y_mm, z_mm[, description]"
)
_NAME = re.compile(r"^[^\s;,]+$")
_MM = Decimal("0.001")


@dataclass(frozen=True, slots=True)
class HarnessComponent:
    """One row: a cable (colour, diameter, length) or a connector or capacitor (colour, size)."""

    name: str
    kind: str
    rgb: tuple[int, int, int] | None
    diameter_m: Decimal | None
    length_m: Decimal | None
    dimensions_m: tuple[Decimal, Decimal, Decimal] | None
    description: str | None
    line: int


def looks_like_harness_components(head: bytes) -> bool:
    """Whether the first non-empty line names the columns name, type, red, green and blue."""
    return {c.lower() for c in split_cells(first_line(head))} >= _SIGNATURE


def _columns(row: Row) -> dict[str, int]:
    return named_columns(row, _COLUMNS)


def read_harness_components(path: str | Path) -> list[HarnessComponent]:
    """Read a harness components list.

    Raises
    ------
    IngestError
        On an empty or binary file, a missing header or column, an unknown column or type, a
        malformed name, number or colour, a missing or misplaced value (a cable needs diameter
        and length, a connector or capacitor dimensions), or a name given twice.
    """
    text = read_text(path, expected=_EXPECTED)
    rows, header, columns = find_header(text, path, _columns, _SIGNATURE.issubset, _EXPECTED, scan_rows=5)
    head = rows[header]
    check_columns(path, head, columns, _COLUMNS, _REQUIRED, _EXPECTED)
    components: list[HarnessComponent] = []
    seen: dict[str, int] = {}
    for row in rows[header + 1 :]:
        if row.is_blank:
            continue
        component = _component(path, row, columns)
        if component.name in seen:
            raise IngestError(
                path,
                f"component {component.name!r} given twice (first on line {seen[component.name]})",
                line=row.line,
                expected="each name once",
            )
        seen[component.name] = row.line
        components.append(component)
    if not components:
        raise IngestError(path, "no component rows after the header", line=head.line, expected=_EXPECTED)
    return components


def _component(path: str | Path, row: Row, columns: dict[str, int]) -> HarnessComponent:
    def cell(name: str) -> str:
        return row.cell(columns[name]) if name in columns else ""

    def fail(reason: str, found: object = None, expected: str | None = None) -> IngestError:
        return IngestError(path, reason, line=row.line, found=found, expected=expected)

    name = cell("name")
    if not _NAME.match(name):
        raise fail("malformed name", name, "a name without spaces, ',' or ';'")
    kind = cell("type").lower()
    if kind not in COMPONENT_KINDS:
        raise fail(f"unknown type of {name!r}", cell("type"), " | ".join(COMPONENT_KINDS))

    def millimetres(column: str) -> Decimal | None:
        raw = cell(column)
        if not raw:
            return None
        try:
            value, unit = parse_decimal(raw)
        except ValueError:
            value, unit = Decimal(-1), "?"
        if unit not in ("", "mm") or value < 0:
            raise fail(f"{column} of {name!r} is not a length in millimetres", raw, "a number >= 0, e.g. 1.6")
        return value * _MM

    colour = [cell(c) for c in ("red", "green", "blue")]
    rgb: tuple[int, int, int] | None = None
    if any(colour):
        if not all(re.fullmatch(r"\d{1,3}", c) and int(c) <= 255 for c in colour):
            raise fail(
                f"colour of {name!r} is not three whole numbers 0 to 255", " ".join(colour), "e.g. 255 0 0"
            )
        rgb = (int(colour[0]), int(colour[1]), int(colour[2]))
    elif kind != "capacitor":
        raise fail(f"{kind} {name!r} has no colour", expected="red, green and blue from 0 to 255")
    diameter, length = millimetres("diameter_mm"), millimetres("length_mm")
    sizes = [millimetres(c) for c in ("x_mm", "y_mm", "z_mm")]
    dimensions: tuple[Decimal, Decimal, Decimal] | None = None
    if kind == "cable":
        if diameter is None or length is None:
            raise fail(f"cable {name!r} needs diameter_mm and length_mm", expected="both, in millimetres")
        if any(s is not None for s in sizes):
            raise fail(
                f"cable {name!r} has x_mm, y_mm or z_mm",
                expected="dimensions only for connectors and capacitors",
            )
    else:
        if any(s is None for s in sizes):
            raise fail(f"{kind} {name!r} needs x_mm, y_mm and z_mm", expected="its dimensions in millimetres")
        if diameter is not None or length is not None:
            raise fail(
                f"{kind} {name!r} has a diameter or length",
                expected="diameter_mm and length_mm only for cables",
            )
        x, y, z = sizes
        assert x is not None and y is not None and z is not None
        dimensions = (x, y, z)
    return HarnessComponent(
        name=name,
        kind=kind,
        rgb=rgb,
        diameter_m=diameter,
        length_m=length,
        dimensions_m=dimensions,
        description=cell("description") or None,
        line=row.line,
    )
