"""Reader of EPLAN's terminal diagram ("Schema Morsetti"): the rows along each terminal strip.

Two layouts, each below an optional preamble (``Nome Progetto:`` ...), the header found by
its ``Morsettiera`` cell (docs/formats/terminal-diagram.md):

* one sheet for all strips: ``Morsettiera | Zona | Pin | Comp. Destinazione 1 | (zone) |
  Comp. Destinazione 2 | (zone) | Testo funzionale``. Pin ``0`` is the strip's start (its
  first end stop), ``999999`` its end, a zone without a pin a division (a partition plate),
  the strip's label alone a placeholder EPLAN leaves for an accessory;
* one sheet per strip (``Morsettiera | Pin | Ponte | Tipo Morsetto | Sezione 1 | …| PIANO``)
  whose cells do not sit under their headers: the terminal stands under ``Tipo Morsetto``,
  the destinations under ``Sezione 1`` and right of ``Comp. Destinazione 1``, their zones
  under ``Comp. Destinazione 1`` and ``Sezione 2``, the function text under ``Comp.
  Destinazione 2`` and the terminal type right of it. A row with a type and no terminal is an
  accessory (end bracket, end plate); a row of floor ``PIANO`` 2 or more is a further level of
  the terminal above.

EPLAN's summary of strips (``Morsettiera | Ubicazione | Funzione``) reads as one ``summary``
row per strip. Rows are kept in order per strip: the derivation matches them one to one with the strip's
items in the WRI table, as the cell's software does.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from cadkg.ingest.eplan.labels import normalize_label
from cadkg.ingest.sheet import Sheet, cell_text, read_workbook, settle_sheets, sheet_text

__all__ = ["DiagramRow", "looks_like_terminal_diagram", "read_terminal_diagram"]

_EXPECTED = (
    "a header row 'Morsettiera | Zona | Pin | Comp. Destinazione 1 …' or 'Morsettiera | Pin | Ponte | …'"
)
_SCAN_ROWS = 40
START, END = "0", "999999"


@dataclass(frozen=True, slots=True)
class DiagramRow:
    """One row of a terminal strip, ``position`` its place among the strip's rows (from 1).

    ``kind`` is ``start``, ``end``, ``division``, ``terminal``, ``accessory``, ``floor`` (a
    further level of the terminal above, on the same item), ``placeholder``, or ``summary``
    (a strip as the summary of strips lists it: no place along it).
    ``destinations`` are the pin references the row names, as written, with their zones.
    """

    strip: str
    raw_strip: str
    position: int
    kind: str
    terminal: str | None
    zone: str | None
    destinations: tuple[tuple[str, str | None], ...]
    function: str | None
    terminal_type: str | None
    level: str | None
    line: int
    sheet: str


def _norm(cell: object) -> str:
    return re.sub(r"\s+", " ", cell_text(cell).lower())


def looks_like_terminal_diagram(head: bytes) -> bool:
    """Whether a workbook's sheets hold a terminal diagram header (``Morsettiera`` and ``Pin``)."""
    text = sheet_text(head)
    if text is None:
        return False
    return any(
        cells[:1] == ["morsettiera"] and ({"pin", "funzione"} & set(cells))
        for cells in (_row(line) for line in text.lower().splitlines())
    )


def _row(line: str) -> list[str]:
    return [re.sub(r"\s+", " ", c.strip()) for c in line.split("\t")]


def read_terminal_diagram(path: str | Path) -> list[DiagramRow]:
    """Read the terminal diagram of a workbook (``.ods``, ``.xlsx``, ``.xlsm``, ``.xls``).

    Raises
    ------
    IngestError
        When no sheet has a terminal diagram header, or a pin is neither a terminal name nor
        ``0``/``999999`` where the layout needs one; at the cell.
    """
    records: list[DiagramRow] = []
    skipped = []
    positions: dict[str, int] = {}
    for sheet in read_workbook(path).sheets:
        header = _header(sheet)
        if header is None:
            skipped.append(sheet.name)
            continue
        records += _Layout(path, sheet, *header, positions).rows()
    settle_sheets(path, "a terminal diagram", bool(records), skipped, _EXPECTED)
    return records


def _header(sheet: Sheet) -> tuple[int, dict[str, int]] | None:
    for index, row in enumerate(sheet.rows[:_SCAN_ROWS]):
        names = [_norm(c) for c in row.cells]
        if names[:1] == ["morsettiera"] and ({"pin", "funzione"} & set(names)):
            columns: dict[str, int] = {}
            for column, name in enumerate(names):
                if name:
                    columns.setdefault(name, column)
            return index, columns
    return None


class _Layout:
    def __init__(
        self, path: str | Path, sheet: Sheet, at: int, header: dict[str, int], positions: dict[str, int]
    ) -> None:
        self.path, self.sheet, self.at, self.positions = path, sheet, at, positions
        self.summary = "pin" not in header
        if self.summary:
            # The summary of strips (Sommario Morsettiere): a strip, where it is, what it does.
            self.columns = {"zone": header.get("ubicazione", 1), "function": header.get("funzione", 2)}
            self.per_strip = False
        elif "ponte" in header or "tipo morsetto" in header:
            # One sheet per strip: the cells sit beside their headers, not under them.
            first, second = header.get("comp. destinazione 1", 5), header.get("comp. destinazione 2", 8)
            self.columns = {
                "terminal": header.get("tipo morsetto", 3),
                "dest1": header.get("sezione 1", 4),
                "zone1": first,
                "dest2": first + 1,
                "zone2": header.get("sezione 2", 7),
                "function": second,
                "type": second + 1,
                "level": header.get("piano", 10),
            }
            self.per_strip = True
        else:
            first, second = header.get("comp. destinazione 1", 3), header.get("comp. destinazione 2", 5)
            self.columns = {
                "terminal": header["pin"],
                "zone": header.get("zona", 1),
                "dest1": first,
                "zone1": first + 1,
                "dest2": second,
                "zone2": second + 1,
                "function": header.get("testo funzionale", second + 2),
            }
            self.per_strip = False

    def rows(self) -> list[DiagramRow]:
        found = []
        for row in self.sheet.rows[self.at + 1 :]:
            if row.is_blank:
                continue
            text = self.reader(row.cells)
            raw = cell_text(row.cell(0))
            strip = normalize_label(raw)
            if not strip:
                continue  # a level row of the strip above without its label: nothing to place
            kind = self.kind(text)
            if kind is None:
                continue
            destinations = tuple(
                (ref, text(zone)) for ref, zone in ((text("dest1"), "zone1"), (text("dest2"), "zone2")) if ref
            )
            self.positions[strip] = position = self.positions.get(strip, 0) + 1
            found.append(
                DiagramRow(
                    strip=strip,
                    raw_strip=raw,
                    position=position,
                    kind=kind,
                    terminal=text("terminal") if kind in ("terminal", "floor") else None,
                    zone=text("zone"),
                    destinations=destinations,
                    function=text("function"),
                    terminal_type=text("type"),
                    level=text("level"),
                    line=row.number,
                    sheet=self.sheet.name,
                )
            )
        return found

    def reader(self, cells: tuple[object, ...]) -> Callable[[str], str | None]:
        """The text of a row's cell by meaning; None where empty or the layout has no such cell."""

        def text(key: str) -> str | None:
            at = self.columns.get(key)
            return None if at is None or at >= len(cells) else cell_text(cells[at]) or None

        return text

    def kind(self, text: Callable[[str], str | None]) -> str | None:
        if self.summary:
            return "summary"
        terminal = text("terminal")
        if self.per_strip:
            level = text("level")
            if terminal is None:
                return "accessory" if text("type") else None
            return "floor" if level not in (None, "1") and not text("type") else "terminal"
        if terminal == START:
            return "start"
        if terminal == END:
            return "end"
        if terminal is None:
            return "division" if text("zone") else "placeholder"
        return "terminal"
