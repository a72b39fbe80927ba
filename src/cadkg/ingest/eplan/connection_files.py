"""A connection list from whichever file EPLAN wrote it to: text, a workbook, or labelling XML.

The content decides: a ZIP archive or an OLE2 file is a workbook (the sheet whose header
names ``Componente:pin`` is the list; the Komax workbooks add machine rows above it and
sheets of settings beside it), an ``<EplanLabelling>`` document is EPLAN's XML report, and
anything else is delimited text (:mod:`.connection_list`).
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

from cadkg.errors import IngestError
from cadkg.ingest.eplan.connection_list import (
    Connection,
    ConnectionListInfo,
    connection_records,
    header_in,
    iter_connection_list,
    looks_like_connection_list,
)
from cadkg.ingest.eplan.labelling import looks_like_labelling, read_labelling
from cadkg.ingest.sheet import cell_text, is_workbook, read_workbook, settle_sheets, sheet_text
from cadkg.ingest.text import Row, read_head

__all__ = ["iter_connections", "looks_like_connections", "read_connections"]

_Record = ConnectionListInfo | Connection


def read_connections(path: str | Path) -> list[_Record]:
    """Read a connection list from text, a workbook or EPLAN labelling XML.

    Raises
    ------
    IngestError
        As the reader of each form does; a workbook without a sheet whose header names the
        pin columns, or labelling XML that is no connection list, at the file.
    """
    return list(iter_connections(path))


def iter_connections(path: str | Path) -> Iterator[_Record]:
    """The records of :func:`read_connections` one by one."""
    head = read_head(path, expected="a connection list")
    if is_workbook(head):
        yield from _from_workbook(path)
    elif looks_like_labelling(head):
        yield from _from_labelling(path)
    else:
        yield from iter_connection_list(path)


def looks_like_connections(head: bytes) -> bool:
    """Whether a file's first bytes (and, for a workbook, its sheets' text) hold a connection list."""
    text = sheet_text(head)
    if text is not None:
        return looks_like_connection_list(text.encode("utf-8"))
    if looks_like_labelling(head):
        return b"Componente:pin" in head or any(
            name in head for name in (b"Nome attacco di destinazione", b"Designazione collegamenti")
        )
    return looks_like_connection_list(head)


def _text_rows(rows: tuple[Any, ...]) -> list[Row]:
    return [Row(r.number, tuple(cell_text(c) for c in r.cells)) for r in rows]


def _from_workbook(path: str | Path) -> Iterator[_Record]:
    chosen: tuple[str, list[Row], int, dict[str, int]] | None = None
    skipped = []
    for sheet in read_workbook(path).sheets:
        rows = _text_rows(sheet.rows)
        found = header_in(rows)
        has_data = found is not None and any(not r.is_blank for r in rows[found[0] + 1 :])
        if found is None or not has_data or chosen is not None:
            skipped.append(sheet.name)
            continue
        chosen = (sheet.name, rows, *found)
    expected = "a sheet whose header names 'Componente:pin' (origin and destination) and rows below it"
    settle_sheets(path, "a connection list", chosen is not None, skipped, expected)
    assert chosen is not None
    name, rows, header_at, columns = chosen
    yield from connection_records(path, rows, header_at, columns, name)


def _from_labelling(path: str | Path) -> Iterator[_Record]:
    report = read_labelling(path)
    header = report.canonical_header()
    preamble = [
        Row(0, (label, value))
        for label, key in (("Nome Progetto:", "nome progetto"), ("Commessa:", "commessa"))
        for name, value in report.header.items()
        if name.strip().lower() in (key, {"nome progetto": "project name", "commessa": "job"}[key])
    ]
    rows = [*preamble, header, *report.lines]
    found = header_in([header])
    if found is None:
        raise IngestError(
            path,
            "the EPLAN report is no connection list",
            found=", ".join(report.columns)[:200],
            expected="the columns 'Nome attacco di destinazione (completo)', twice, and"
            " 'Designazione collegamenti'",
        )
    yield from connection_records(
        path, rows, len(preamble), found[1], None, lambda line, column: {"cell": f"<Line> {line}"}
    )
