"""Reader of the component list (D3.1, Figure 4, left): which parts make each component.

One row per part of a component, so a Component ID repeats on consecutive rows. The
``XML Data`` cell may embed the part's model, wrapped in ``<pre>``; it is parsed with
the component model reader and its errors point at the physical line inside the cell.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.eplan.labels import normalize_label
from cadkg.ingest.text import Row, find_header, read_text, small_integer
from cadkg.usecases.iema.component_model import ComponentModel, parse_models_fragment

__all__ = ["ComponentListEntry", "looks_like_component_list", "read_component_list"]

_EXPECTED = (
    "a header row naming 'Component ID' and 'Part Number' or 'XML Data' "
    "(Description, Quantity optional), separated by tabs, semicolons or commas"
)
_HEADER_SCAN_ROWS = 40
_ALIASES = {
    "component id": "label",
    "codice componente": "label",
    "description": "description",
    "descrizione": "description",
    "part number": "part_number",
    "codice articolo": "part_number",
    "quantity": "quantity",
    "quantità": "quantity",
    "xml data": "xml",
    "dati xml": "xml",
}
_PRE = re.compile(r"</?pre\s*>", re.IGNORECASE)


@dataclass(frozen=True, slots=True)
class ComponentListEntry:
    """One row: a part of a component, with the models its XML Data cell describes."""

    label: str
    raw_id: str
    description: str | None
    part_number: str | None
    quantity: int | None
    models: tuple[ComponentModel, ...]
    line: int


def looks_like_component_list(head: bytes) -> bool:
    """Whether a line among the first bytes names a Component ID and a Part Number or XML Data column."""
    for line in head.decode("utf-8", errors="replace").splitlines()[:_HEADER_SCAN_ROWS]:
        cells = (c.strip().strip('"').lower() for c in re.split(r"[\t;,]", line))
        meanings = {_ALIASES.get(re.sub(r"\s+", " ", c)) for c in cells}
        if "label" in meanings and meanings & {"part_number", "xml"}:
            return True
    return False


def _columns(row: Row) -> dict[str, int]:
    columns: dict[str, int] = {}
    for index, cell in enumerate(row.cells):
        meaning = _ALIASES.get(re.sub(r"\s+", " ", cell.strip().lower()))
        if meaning is not None:
            columns.setdefault(meaning, index)
    return columns


def _find_header(text: str, path: str | Path) -> tuple[list[Row], Iterator[Row], int, dict[str, int]]:
    return find_header(text, path, _columns, lambda columns: "label" in columns, _EXPECTED, _HEADER_SCAN_ROWS)


def read_component_list(path: str | Path) -> list[ComponentListEntry]:
    """Read a component list.

    Raises
    ------
    IngestError
        When no header is found, a column is missing, a Component ID is empty, a
        quantity is not a positive integer, the XML Data cell is malformed, or
        there are no data rows; located at file:line.
    """
    text = read_text(path, expected=_EXPECTED)
    rows, after, header_at, columns = _find_header(text, path)
    header = rows[header_at]
    if "part_number" not in columns and "xml" not in columns:
        raise IngestError(
            path,
            "missing column 'Part Number' or 'XML Data'",
            line=header.line,
            found=", ".join(c.strip() for c in header.cells if c.strip())[:200],
            expected=_EXPECTED,
        )
    names = {key: re.sub(r"\s+", " ", header.cells[i].strip()) for key, i in columns.items()}
    entries = [_entry(path, row, columns, names) for row in after if not row.is_blank]
    if not entries:
        raise IngestError(path, "no rows after the header", line=header.line, expected="at least one part")
    return entries


def _entry(path: str | Path, row: Row, columns: dict[str, int], names: dict[str, str]) -> ComponentListEntry:
    def text(key: str) -> str | None:
        return (row.cell(columns[key]) if key in columns else "") or None

    raw_id = text("label")
    label = normalize_label(raw_id or "")
    if raw_id is None or not label:
        raise IngestError(
            path,
            f"empty cell in column {names['label']!r}",
            line=row.line,
            found=raw_id,
            expected="a component ID such as -SSB-20B4",
        )
    quantity = None
    raw_quantity = text("quantity")
    if raw_quantity is not None:
        quantity = small_integer(raw_quantity)
        if not quantity:
            raise IngestError(
                path,
                f"not a positive integer in column {names['quantity']!r}",
                line=row.line,
                found=raw_quantity,
                expected="a whole number of parts, e.g. 1",
            )
    return ComponentListEntry(
        label=label,
        raw_id=raw_id,
        description=text("description"),
        part_number=text("part_number"),
        quantity=quantity,
        models=_models(path, row, columns.get("xml"), names.get("xml", "")),
        line=row.line,
    )


def _models(path: str | Path, row: Row, at: int | None, name: str) -> tuple[ComponentModel, ...]:
    if at is None or at >= len(row.cells):
        return ()
    xml = _PRE.sub("", row.cells[at])
    if not xml.strip():
        return ()
    # Cells before this one may hold line breaks of their own; the XML starts after them.
    offset = row.line - 1 + sum(cell.count("\n") for cell in row.cells[:at])
    try:
        return tuple(parse_models_fragment(xml, path, offset))
    except IngestError as err:
        raise IngestError(
            path,
            f"in column {name!r}: {err.reason}",
            line=err.line,
            found=err.found,
            expected=err.expected,
        ) from None
