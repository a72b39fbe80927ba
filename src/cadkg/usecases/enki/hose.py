"""Reader of hose product tables: the parameters a robot needs to handle a hose (ENKI).

D3.1 (section 4.5) asks only for the diameter of the hose to handle, open to more
product parameters later; this small CSV is ours (docs/formats/hose.md)::

    product,diameter_mm,length_m,material,bend_radius_mm
    HX-16,16,2.5,EPDM,80

The unit of each measure is part of its column name (``diameter_mm`` or ``diameter_m``,
also written ``diameter (mm)``), so a table never leaves it to be guessed. ``product``
and a diameter are required; length, material and bend radius may be left out, as a
column or as an empty cell. Records carry metres.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.text import Row, first_line, iter_rows, parse_decimal, read_text

__all__ = ["HoseProduct", "looks_like_hose_table", "read_hoses"]

_EXPECTED = "a header row: product, diameter_mm (or diameter_m), optional length_m, material, bend_radius_mm"
_MEASURE = re.compile(r"^(diameter|length|bend[ _]?radius)\s*(?:_|\(|\[)\s*(mm|m)\s*[)\]]?$")
_SCALE = {"mm": Decimal("0.001"), "m": Decimal(1)}


@dataclass(frozen=True, slots=True)
class HoseProduct:
    """One hose product: outer diameter, and when given cut length, material and minimum bend radius."""

    product: str
    diameter_m: float
    length_m: Decimal | None
    material: str | None
    bend_radius_m: float | None
    line: int


def _column(cell: str) -> tuple[str, str | None] | None:
    """A header cell as (field, unit): ``'Diameter (mm)'`` → ``('diameter', 'mm')``; None if unknown."""
    text = re.sub(r"\s+", " ", cell.strip().strip('"').lower())
    if text in ("product", "material"):
        return text, None
    match = _MEASURE.match(text)
    if match is None:
        return None
    field = "bend_radius" if match.group(1).startswith("bend") else match.group(1)
    return field, match.group(2)


def read_hoses(path: str | Path) -> list[HoseProduct]:
    """Read a hose product table (comma, semicolon or tab separated).

    Raises
    ------
    IngestError
        On an empty or binary file, a missing or unknown column, a column without its
        unit, a product given twice, an empty product or diameter, or a measure that is
        not a positive number; located at file:line.
    """
    text = read_text(path, expected=_EXPECTED)
    first = next((line for line in text.splitlines() if line.strip()), "")
    delimiter = max(("\t", ";", ","), key=lambda d: sum(_column(c) is not None for c in first.split(d)))
    rows = [row for row in iter_rows(text, delimiter, path) if not row.is_blank]
    if not rows:
        raise IngestError(path, "no rows", line=1, expected=_EXPECTED)
    header = rows[0]
    columns: dict[str, tuple[int, str | None]] = {}
    for index, cell in enumerate(header.cells):
        if not cell.strip():
            continue
        known = _column(cell)
        if known is None:
            bare = cell.strip().lower()
            unitless = bare in ("diameter", "length", "bend_radius", "bend radius")
            raise IngestError(
                path,
                f"column {cell.strip()!r} without its unit"
                if unitless
                else f"unknown column {cell.strip()!r}",
                line=header.line,
                found=cell.strip()[:80],
                expected=_EXPECTED,
            )
        if known[0] in columns:
            raise IngestError(path, f"two {known[0]} columns", line=header.line, expected=_EXPECTED)
        columns[known[0]] = (index, known[1])
    missing = [name for name in ("product", "diameter") if name not in columns]
    if missing:
        raise IngestError(
            path,
            f"missing column {', '.join(missing)}",
            line=header.line,
            found=delimiter.join(header.cells)[:200],
            expected=_EXPECTED,
        )
    hoses: list[HoseProduct] = []
    seen: dict[str, int] = {}
    for row in rows[1:]:
        hose = _hose(path, row, columns)
        if hose.product in seen:
            raise IngestError(
                path,
                f"product {hose.product!r} given twice (first on line {seen[hose.product]})",
                line=row.line,
                expected="each product once",
            )
        seen[hose.product] = row.line
        hoses.append(hose)
    if not hoses:
        raise IngestError(path, "no hose after the header", line=header.line, expected="one row per product")
    return hoses


def _hose(path: str | Path, row: Row, columns: dict[str, tuple[int, str | None]]) -> HoseProduct:
    def cell(name: str) -> str:
        return row.cell(columns[name][0]) if name in columns else ""

    def measure(name: str, required: bool) -> Decimal | None:
        raw = cell(name)
        if not raw:
            if required:
                raise IngestError(path, f"empty {name}", line=row.line, expected=f"the {name} of the hose")
            return None
        unit = columns[name][1] or "m"
        try:
            number, written = parse_decimal(raw)
        except ValueError:
            number, written = Decimal(-1), ""
        exponent = number.adjusted()
        if number <= 0 or written not in ("", unit) or not -30 <= exponent <= 30:
            raise IngestError(
                path,
                f"not a {name.replace('_', ' ')}",
                line=row.line,
                found=raw,
                expected=f"a positive number of {unit}",
            )
        return (number * _SCALE[unit]).normalize()

    product = cell("product")
    if not product:
        raise IngestError(path, "empty product", line=row.line, expected="a product name or code")
    diameter = measure("diameter", True)
    assert diameter is not None  # required, so measure() raised otherwise
    bend = measure("bend_radius", False)
    return HoseProduct(
        product=product,
        diameter_m=float(diameter),
        length_m=measure("length", False),
        material=cell("material") or None,
        bend_radius_m=None if bend is None else float(bend),
        line=row.line,
    )


def looks_like_hose_table(head: bytes) -> bool:
    """Whether the first non-empty line names a product and a diameter with its unit."""
    first = first_line(head)
    for delimiter in ("\t", ";", ","):
        fields = {known[0] for c in first.split(delimiter) if (known := _column(c)) is not None}
        if {"product", "diameter"} <= fields:
            return True
    return False
