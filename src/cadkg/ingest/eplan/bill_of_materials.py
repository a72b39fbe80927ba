"""Reader of EPLAN's bill of materials ("Distinta componenti"): which parts each device uses.

One line per device and article: ``S.E.F.`` (the device tag, as the WRI table labels it),
``N.articolo`` (the article number the WRI table and the component models use), ``Q.ta``,
``Descrizione``, ``Commerciale`` (manufacturer and type), ``Produttore``, and the mounting
zone (``Destinazione`` or ``Zona di Montaggio``). It comes as a workbook (``.xlsx``, the
legacy ``.xls``), the sheet found by its header below a preamble (``Nome Progetto:`` ...
with the value one cell to the right), or as EPLAN's labelling XML. A summarised list
("Distinta riepilogata", one line per article without devices) is not this report.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import Any

from cadkg.errors import IngestError
from cadkg.ingest.eplan.labelling import looks_like_labelling, read_labelling
from cadkg.ingest.eplan.labels import normalize_label
from cadkg.ingest.sheet import cell_address, cell_text, is_workbook, read_workbook, settle_sheets, sheet_text
from cadkg.ingest.text import Row, parse_decimal, read_head, read_text

__all__ = ["BomInfo", "BomLine", "looks_like_bill_of_materials", "read_bill_of_materials"]

_EXPECTED = (
    "a header row naming 'S.E.F.' and 'N.articolo' (Q.ta, Descrizione, Commerciale, Produttore optional)"
)
# Header cell (lower case, white space folded) → meaning.
_ALIASES = {
    "s.e.f.": "label",
    "sef": "label",
    "n.articolo": "part_number",
    "n. articolo": "part_number",
    "q.ta": "quantity",
    "q.tà": "quantity",
    "descrizione": "description",
    "commerciale": "type_number",
    "produttore": "manufacturer",
    "destinazione": "zone",
    "zona di montaggio": "zone",
    "descrizione funzionale": "function",
    # The summarised list's manufacturer type; its 'Commerciale' is the order number there.
    "n. tipo": "summary_type_number",
}
_PREAMBLE = {
    "nome progetto:": "project",
    "commessa:": "job",
    "cliente:": "customer",
    "descrizione macchina:": "machine",
}
_SCAN_ROWS = 40


@dataclass(frozen=True, slots=True)
class BomInfo:
    """What the preamble of a bill of materials says about the project."""

    project: str | None
    job: str | None
    customer: str | None
    machine: str | None


@dataclass(frozen=True, slots=True)
class BomLine:
    """One line: a device and an article it uses, with how many; in a summarised list (no
    ``S.E.F.`` column), an article and how many the project uses, without a device."""

    label: str | None
    raw_label: str | None
    part_number: str | None
    quantity: Decimal | None
    description: str | None
    type_number: str | None
    manufacturer: str | None
    zone: str | None
    function: str | None
    line: int


def _norm(text: str) -> str:
    return re.sub(r"\s+", " ", text.strip().lower())


def _columns(row: Row) -> dict[str, int]:
    columns: dict[str, int] = {}
    for index, cell in enumerate(row.cells):
        meaning = _ALIASES.get(_norm(cell))
        if meaning is not None:
            columns.setdefault(meaning, index)
    if "summary_type_number" in columns:
        columns["type_number"] = columns.pop("summary_type_number")
    return columns


def _is_header(columns: dict[str, int]) -> bool:
    return "part_number" in columns and ("label" in columns or "quantity" in columns)


def looks_like_bill_of_materials(head: bytes) -> bool:
    """Whether a workbook's sheets (or a labelling report's columns) name S.E.F. and N.articolo."""
    text = sheet_text(head)
    if text is not None:
        lines = text.lower().splitlines()[: _SCAN_ROWS * 4]
        return any(_is_header(_columns(Row(0, tuple(line.split("\t"))))) for line in lines)
    articles = (b">Numero articolo<", b">Artikelnummer<", b">Part number<")
    return looks_like_labelling(head) and any(name in head for name in articles)


def read_bill_of_materials(path: str | Path) -> list[BomInfo | BomLine]:
    """Read a bill of materials from a workbook or EPLAN labelling XML.

    Raises
    ------
    IngestError
        When no sheet has the header, a line has no device tag, or a quantity is not a
        positive number; at the cell (``Sheet!D12``) or the ``<Line>``.
    """
    head = read_head(path, expected=_EXPECTED)
    if is_workbook(head):
        return _from_workbook(path)
    if looks_like_labelling(head):
        report = read_labelling(path)
        header = report.canonical_header()
        info = BomInfo(
            *(
                report.header.get(k)
                for k in ("Nome progetto", "Commessa", "Cliente: Nome 1", "Descrizione progetto")
            )
        )
        return [info, *_lines(path, [header, *report.lines], 0, lambda n, c: {"cell": f"<Line> {n}"})]
    read_text(path, expected=_EXPECTED)  # the located error of an empty or binary file
    raise IngestError(path, "not a workbook nor EPLAN labelling XML", expected=_EXPECTED)


def _from_workbook(path: str | Path) -> list[BomInfo | BomLine]:
    found: list[BomInfo | BomLine] | None = None
    skipped = []
    for sheet in read_workbook(path).sheets:
        rows = [Row(r.number, tuple(cell_text(c) for c in r.cells)) for r in sheet.rows]
        at = next((i for i, r in enumerate(rows[:_SCAN_ROWS]) if _is_header(_columns(r))), None)
        if at is None or found is not None:
            skipped.append(sheet.name)
            continue
        found = [_preamble(rows[:at]), *_lines(path, rows, at, _in_sheet(sheet.name))]
    settle_sheets(path, "a bill of materials", found is not None, skipped, _EXPECTED)
    return found or []


def _in_sheet(name: str) -> Callable[[int, int], dict[str, Any]]:
    return lambda row, column: {"cell": cell_address(name, row, column)}


def _preamble(rows: list[Row]) -> BomInfo:
    values: dict[str, str] = {}
    for row in rows:
        for index, cell in enumerate(row.cells):
            key = _PREAMBLE.get(_norm(cell))
            if key is not None:
                values.setdefault(key, next((c.strip() for c in row.cells[index + 1 :] if c.strip()), ""))
    return BomInfo(*(values.get(k) or None for k in ("project", "job", "customer", "machine")))


def _lines(
    path: str | Path, rows: list[Row], at: int, locate: Callable[[int, int], dict[str, Any]]
) -> list[BomLine]:
    columns = _columns(rows[at])
    lines = []
    for row in rows[at + 1 :]:
        if row.is_blank:
            continue

        def text(key: str, row: Row = row) -> str | None:
            index = columns.get(key)
            return (row.cell(index) or None) if index is not None else None

        raw = text("label")
        label = normalize_label(raw or "")
        if "label" in columns and (raw is None or not label):
            raise IngestError(
                path,
                "a line without a device tag",
                found=raw,
                expected="a device tag such as =-F1500.1",
                **locate(row.line, columns["label"]),
            )
        lines.append(
            BomLine(
                label=label or None,
                raw_label=raw,
                part_number=text("part_number"),
                quantity=_quantity(path, text("quantity"), locate(row.line, columns.get("quantity", 0))),
                description=text("description"),
                type_number=text("type_number"),
                manufacturer=text("manufacturer"),
                zone=text("zone"),
                function=text("function") if text("function") != "." else None,
                line=row.line,
            )
        )
    if not lines:
        raise IngestError(
            path,
            "no lines after the header",
            expected="one line per device and article",
            **locate(rows[at].line, 0),
        )
    return lines


def _quantity(path: str | Path, raw: str | None, where: dict[str, Any]) -> Decimal | None:
    if raw is None:
        return None
    try:
        value, unit = parse_decimal(raw)
    except ValueError:
        value, unit = Decimal(0), "?"
    if unit or value <= 0:
        raise IngestError(
            path, "not a positive quantity", found=raw, expected="a number of pieces, e.g. 1 or 9", **where
        )
    return value
