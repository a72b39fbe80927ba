"""Reader of terminal block schemas: which terminal items, in order, form each block.

D3.1 names terminal block characterisation among the component files without fixing
a layout, so this one is ours (docs/formats/terminal-schema.md): one row per terminal
item, the header being the first non-empty row, as CSV or as the first non-empty sheet
of an XLSX or ODS workbook. The order along the block is what a robot walks to find
terminal ``n``, so positions must run 1..n without gaps or repeats.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.eplan.labels import normalize_label
from cadkg.ingest.sheet import SHEET_SUFFIXES, cell_address, cell_text, read_sheet, workbook_strings
from cadkg.ingest.text import first_line, iter_rows, read_text, small_integer, split_cells

__all__ = ["TerminalSlot", "looks_like_terminal_schema", "read_terminal_schema"]

_ALIASES = {
    "terminal block": "block",
    "morsettiera": "block",
    "block": "block",
    "position": "position",
    "posizione": "position",
    "pos.": "position",
    "pos": "position",
    "terminal": "terminal",
    "morsetto": "terminal",
    "terminal name": "terminal",
    "cad id": "cad_id",
    "id cad": "cad_id",
    "item id": "cad_id",
    "commercial": "commercial",
    "codice commerciale": "commercial",
    "part number": "commercial",
    "levels": "levels",
    "livelli": "levels",
    "pins": "levels",
}
_REQUIRED = {
    "block": "Terminal block",
    "position": "Position",
    "terminal": "Terminal",
    "cad_id": "Cad ID",
    "levels": "Levels",
}
_EXPECTED = "a header row naming the columns " + ", ".join(_REQUIRED.values()) + " (Commercial optional)"
_CAD_ID = re.compile(r"^ID\d+$", re.IGNORECASE)


@dataclass(frozen=True, slots=True)
class TerminalSlot:
    """One terminal item at its place along a terminal block; an end plate has no terminal."""

    block: str
    position: int
    terminal: str | None
    cad_id: str
    commercial: str | None
    levels: tuple[str, ...]
    line: int
    sheet: str | None


def read_terminal_schema(path: str | Path) -> list[TerminalSlot]:
    """Read a terminal block schema from CSV/TSV, XLSX or ODS, in file order.

    Raises
    ------
    IngestError
        When the header lacks a column, a cell is empty or malformed, a CAD ID,
        position or terminal repeats, positions of a block leave a gap, or there
        are no rows; located at file:line (CSV) or file:Sheet!A1 (workbooks).
    """
    if Path(path).suffix.lower() in SHEET_SUFFIXES:
        sheet, sheet_rows = read_sheet(path)
        rows = [(r.number, r.cells) for r in sheet_rows]
        return _Table(path, sheet).read(rows)
    text = read_text(path, expected=_EXPECTED)
    return _Table(path, None).read(_csv_rows(text, path))


def looks_like_terminal_schema(head: bytes) -> bool:
    """Whether the first non-empty line names a terminal block and a CAD ID column.

    An XLSX workbook is compressed: its header is looked for among the strings of the sheet
    parts that start in the head. An ODS whose suffix another kind also claims needs its
    kind in the manifest.
    """
    if head.startswith(b"PK\x03\x04"):
        head = "\t".join(workbook_strings(head)).encode("utf-8")
    meanings = {_meaning(c) for c in split_cells(first_line(head))}
    return {"block", "cad_id"} <= meanings


def _meaning(cell: object) -> str | None:
    return _ALIASES.get(re.sub(r"\s+", " ", cell_text(cell).lower()))


def _csv_rows(text: str, path: str | Path) -> list[tuple[int, tuple[object, ...]]]:
    # The header is the first non-empty line; the delimiter is the one that splits it
    # into the most known column names.
    first = next((line for line in text.splitlines() if line.strip()), "")
    delimiter = max(("\t", ";", ","), key=lambda d: sum(_meaning(c) is not None for c in first.split(d)))
    return [(row.line, row.cells) for row in iter_rows(text, delimiter, path)]


# Nine digits, as a text cell may have: a numeric cell holds up to 3.4e38, a damaged one more.
_MAX_INTEGER = 999_999_999


def _integer(value: object) -> int | None:
    if isinstance(value, bool):
        return None
    if isinstance(value, int):
        number = value
    elif isinstance(value, float):
        if not value.is_integer():
            return None
        number = int(value)
    else:
        return small_integer(cell_text(value))
    return number if number <= _MAX_INTEGER else None


def _shown(value: object) -> object:
    # A whole number a workbook stores as a float is shown as the spreadsheet shows it.
    if isinstance(value, float) and value.is_integer() and abs(value) < 1e15:
        return int(value)
    return value


class _Table:
    def __init__(self, path: str | Path, sheet: str | None) -> None:
        self.path = path
        self.sheet = sheet

    def error(
        self, reason: str, row: int, column: int, found: object | None = None, expected: str | None = None
    ) -> IngestError:
        if self.sheet is None:
            return IngestError(self.path, reason, line=row, found=found, expected=expected)
        cell = cell_address(self.sheet, row, column)
        return IngestError(self.path, reason, cell=cell, found=found, expected=expected)

    def ref(self, row: int) -> str:
        return f"line {row}" if self.sheet is None else f"row {row}"

    def read(self, rows: Sequence[tuple[int, Sequence[object]]]) -> list[TerminalSlot]:
        filled = [(n, cells) for n, cells in rows if any(cell_text(c) for c in cells)]
        if not filled:
            raise IngestError(self.path, "no rows", expected=_EXPECTED)
        (header_row, header), *data = filled
        columns: dict[str, int] = {}
        for index, cell in enumerate(header):
            meaning = _meaning(cell)
            if meaning is not None and meaning in columns:
                raise self.error(f"two {_REQUIRED.get(meaning, meaning)!r} columns", header_row, index)
            if meaning is not None:
                columns[meaning] = index
        missing = [name for key, name in _REQUIRED.items() if key not in columns]
        if missing:
            found = ", ".join(t for t in (cell_text(c) for c in header) if t)
            raise self.error(
                f"missing column {', '.join(repr(m) for m in missing)}",
                header_row,
                0,
                found=found[:200],
                expected=_EXPECTED,
            )
        if not data:
            raise self.error("no terminal rows after the header", header_row, 0, expected="one row per item")
        slots = [self.slot(n, cells, columns) for n, cells in data]
        self.check(slots, columns)
        return slots

    def slot(self, row: int, cells: Sequence[object], columns: dict[str, int]) -> TerminalSlot:
        def text(key: str) -> str:
            at = columns.get(key)
            return cell_text(cells[at]) if at is not None and at < len(cells) else ""

        def raw(key: str) -> object:
            at = columns[key]
            return cells[at] if at < len(cells) else None

        block = normalize_label(text("block"))
        if not block:
            raise self.error(
                "empty terminal block label", row, columns["block"], expected="a label such as X1600"
            )
        position = _integer(raw("position"))
        if position is None or position < 1:
            raise self.error(
                "not a position",
                row,
                columns["position"],
                found=_shown(raw("position")),
                expected="a whole number from 1, the place along the block",
            )
        cad_id = text("cad_id")
        if not _CAD_ID.match(cad_id):
            raise self.error(
                "malformed CAD item ID",
                row,
                columns["cad_id"],
                found=cad_id,
                expected="ID followed by digits, e.g. ID000051",
            )
        terminal = text("terminal") or None
        levels = self.levels(row, text("levels"), columns["levels"], terminal)
        commercial = text("commercial") or None
        return TerminalSlot(block, position, terminal, cad_id, commercial, levels, row, self.sheet)

    def levels(self, row: int, raw: str, column: int, terminal: str | None) -> tuple[str, ...]:
        if terminal is None:
            if raw:
                raise self.error(
                    "levels on a row without a terminal (an end plate has none)",
                    row,
                    column,
                    found=raw,
                    expected="an empty cell, or a terminal name in the Terminal column",
                )
            return ()
        parts = tuple(p.strip() for p in re.split(r"[;,]", raw))
        if not raw or not all(parts) or len(set(parts)) != len(parts):
            raise self.error(
                f"bad levels of terminal {terminal!r}",
                row,
                column,
                found=raw,
                expected="distinct level names separated by ';' or ',', e.g. a;b",
            )
        return parts

    def check(self, slots: list[TerminalSlot], columns: dict[str, int]) -> None:
        cad_ids: dict[str, int] = {}
        places: dict[tuple[str, int], int] = {}
        names: dict[tuple[str, str], int] = {}
        for s in slots:
            if (first := cad_ids.setdefault(s.cad_id.upper(), s.line)) != s.line:
                raise self.error(
                    f"CAD item ID {s.cad_id} given twice (first on {self.ref(first)})",
                    s.line,
                    columns["cad_id"],
                    expected="each CAD item ID once",
                )
            if (first := places.setdefault((s.block, s.position), s.line)) != s.line:
                raise self.error(
                    f"position {s.position} of terminal block {s.block} given twice "
                    f"(first on {self.ref(first)})",
                    s.line,
                    columns["position"],
                    expected="each position once per block",
                )
            if (
                s.terminal is not None
                and (first := names.setdefault((s.block, s.terminal), s.line)) != s.line
            ):
                raise self.error(
                    f"terminal {s.terminal!r} of terminal block {s.block} given twice "
                    f"(first on {self.ref(first)})",
                    s.line,
                    columns["terminal"],
                    expected="each terminal name once per block",
                )
        counts: dict[str, int] = {}
        for block, _ in places:
            counts[block] = counts.get(block, 0) + 1
        for s in slots:
            if s.position > counts[s.block]:
                taken = {p for b, p in places if b == s.block}
                # Positions are unique, so one of 1..count is missing: no need to scan to s.position.
                gap = min(p for p in range(1, counts[s.block] + 1) if p not in taken)
                raise self.error(
                    f"terminal block {s.block} has no position {gap}: positions must run 1..n without gaps",
                    s.line,
                    columns["position"],
                    found=s.position,
                    expected=f"at most {counts[s.block]}, the number of items of the block",
                )
