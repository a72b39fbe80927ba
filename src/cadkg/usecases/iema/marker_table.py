"""Reader of the QR-code marker table: where the vision system's marker sits on each CAD item.

A workbook (``.ods`` in the cell's data) with a title row (``ORIENTATIONS OF QR CODES``) and
the header ``Product | Commercial | ID (two columns: label, CAD item ID) | X (m) | Y (m) |
Z (m)``. One row per item; the product and commercial code are merged over the rows of a
block, so a covered cell (read empty) takes the value above it; an empty row ends a block.
The positions are in metres in the item's frame; the table gives no orientation.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.eplan.labels import normalize_label
from cadkg.ingest.sheet import Sheet, SheetRow, cell_text, read_workbook, settle_sheets, sheet_text

__all__ = ["QrMarker", "looks_like_marker_table", "read_marker_table"]

_EXPECTED = "a header row 'Product | Commercial | ID | | X (m) | Y (m) | Z (m)'"
_CAD_ID = re.compile(r"^ID\d+$", re.IGNORECASE)
_AXES = ("x (m)", "y (m)", "z (m)")


@dataclass(frozen=True, slots=True)
class QrMarker:
    """The marker of one CAD item: its product and commercial code, label, and position (m)."""

    product: str | None
    commercial: str | None
    label: str | None
    cad_id: str
    position: tuple[float, float, float]
    line: int
    sheet: str


def looks_like_marker_table(head: bytes) -> bool:
    """Whether a workbook's sheets hold the marker table's header (Commercial, X (m), Y (m))."""
    text = sheet_text(head)
    return text is not None and any(
        "commercial" in cells and "x (m)" in cells and "y (m)" in cells
        for cells in ([c.strip() for c in line.split("\t")] for line in text.lower().splitlines())
    )


def read_marker_table(path: str | Path) -> list[QrMarker]:
    """Read a QR-code marker table.

    Raises
    ------
    IngestError
        When no sheet has the header, a row's CAD item ID is malformed or a coordinate is
        not a number; at the cell.
    """
    markers: list[QrMarker] = []
    skipped = []
    for sheet in read_workbook(path).sheets:
        found = _header(sheet)
        if found is None or markers:
            skipped.append(sheet.name)
            continue
        markers += _rows(path, sheet, *found)
    settle_sheets(path, "a marker table", bool(markers), skipped, _EXPECTED)
    return markers


def _header(sheet: Sheet) -> tuple[int, dict[str, int]] | None:
    for index, row in enumerate(sheet.rows[:40]):
        names = [re.sub(r"\s+", " ", cell_text(c).lower()) for c in row.cells]
        if "commercial" in names and all(axis in names for axis in _AXES):
            return index, {name: column for column, name in reversed(list(enumerate(names))) if name}
    return None


def _rows(path: str | Path, sheet: Sheet, at: int, columns: dict[str, int]) -> list[QrMarker]:
    label_at = columns.get("id", columns["commercial"] + 1)
    product = commercial = None
    markers = []
    for row in sheet.rows[at + 1 :]:
        if row.is_blank:
            product = commercial = None  # a separator row ends the block
            continue
        product = _text(row, columns.get("product")) or product
        commercial = _text(row, columns["commercial"]) or commercial
        cad_id = _text(row, label_at + 1) or ""
        if not _CAD_ID.match(cad_id):
            raise IngestError(
                path,
                "malformed CAD item ID",
                cell=sheet.address(row.number, label_at + 1),
                found=cad_id,
                expected="ID followed by digits, e.g. ID000045",
            )
        label = _text(row, label_at)
        markers.append(
            QrMarker(
                product=product,
                commercial=commercial,
                label=normalize_label(label) if label else None,
                cad_id=cad_id,
                position=_position(path, sheet, row, [columns[a] for a in _AXES]),
                line=row.number,
                sheet=sheet.name,
            )
        )
    return markers


def _text(row: SheetRow, column: int | None) -> str | None:
    return None if column is None else cell_text(row.cell(column)) or None


def _position(
    path: str | Path, sheet: Sheet, row: SheetRow, columns: list[int]
) -> tuple[float, float, float]:
    values = []
    for column in columns:
        value = row.cell(column)
        number = value if isinstance(value, int | float) and not isinstance(value, bool) else _float(value)
        if number is None or not math.isfinite(number):
            raise IngestError(
                path,
                "not a number of metres",
                cell=sheet.address(row.number, column),
                found=cell_text(value),
                expected="a decimal number, e.g. 0.0382",
            )
        values.append(float(number))
    return values[0], values[1], values[2]


def _float(value: object) -> float | None:
    try:
        return float(cell_text(value).replace(",", "."))
    except ValueError:
        return None
