"""Reader of the WRI ID table: CAD item ID ↔ device label ↔ commercial code.

The table is tab separated, usually without a header row, with CRLF line ends.
A row may leave the commercial code empty (and may then drop the last tab).
Several CAD items may share a label: a component drawn as several items, or a
terminal block made of terminal items.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.eplan.labels import normalize_label
from cadkg.ingest.text import iter_rows, read_text

__all__ = ["IdEntry", "iter_wri", "looks_like_wri", "read_wri"]

_CAD_ID = re.compile(r"^ID\d+$", re.IGNORECASE)
_FIRST_ROW = re.compile(rb"^(?:\xef\xbb\xbf)?\s*ID\d+\t[^\t\r\n]+(?:\t|\r|\n|$)", re.IGNORECASE)
_HEADER = ("cad id", "label", "commercial")
_EXPECTED = "tab-separated rows: Cad ID, Label, Commercial (e.g. ID000041<TAB>X00005.2<TAB>6013277)"


@dataclass(frozen=True, slots=True)
class IdEntry:
    """One row of the WRI table."""

    cad_id: str
    label: str
    raw_label: str
    commercial: str | None
    line: int


def looks_like_wri(head: bytes) -> bool:
    """Whether a file opens with a WRI row (``ID000001<TAB>=-PE<TAB>``): a ``.txt`` copy of the table."""
    return _FIRST_ROW.match(head) is not None


def read_wri(path: str | Path) -> list[IdEntry]:
    """Read a WRI ID table.

    Raises
    ------
    IngestError
        On an empty or binary file, a row without a label, a malformed CAD ID or a
        CAD ID given twice; the message names the file and line.
    """
    return list(iter_wri(path))


def iter_wri(path: str | Path) -> Iterator[IdEntry]:
    """The entries of :func:`read_wri` one by one; a malformed row raises when it is reached."""
    text = read_text(path, expected=_EXPECTED)
    count = 0
    seen: dict[str, int] = {}
    for row in iter_rows(text, "\t", path):
        if row.is_blank:
            continue
        cells = [c.strip() for c in row.cells]
        if not count and tuple(c.lower() for c in cells[:3]) == _HEADER:
            continue
        while len(cells) > 3 and not cells[-1]:
            cells.pop()
        if len(cells) < 2 or len(cells) > 3:
            raise IngestError(
                path,
                f"{len(cells)} field(s) in the row",
                line=row.line,
                found="\\t".join(cells)[:60],
                expected="3 tab-separated fields: Cad ID, Label, Commercial",
            )
        cad_id, raw_label = cells[0], cells[1]
        commercial = cells[2] if len(cells) == 3 and cells[2] else None
        if not _CAD_ID.match(cad_id):
            raise IngestError(
                path,
                "malformed CAD item ID",
                line=row.line,
                found=cad_id,
                expected="ID followed by digits, e.g. ID000041",
            )
        label = normalize_label(raw_label)
        if not label:
            raise IngestError(path, "empty label", line=row.line, expected="a device label such as F1500.1")
        if cad_id.upper() in seen:
            raise IngestError(
                path,
                f"CAD item ID {cad_id} given twice (first on line {seen[cad_id.upper()]})",
                line=row.line,
                expected="each CAD item ID once",
            )
        seen[cad_id.upper()] = row.line
        count += 1
        yield IdEntry(cad_id, label, raw_label, commercial, row.line)
    if not count:
        raise IngestError(path, "no ID rows", expected=_EXPECTED)
