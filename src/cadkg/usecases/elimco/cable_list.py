"""Reader of ELIMCO's Excel cable list (D3.1, Figure 11): wire ends by row, merged into wires.

The list has one row per wire *end*: ``ZONA_A``/``BORNIA_A`` is the connector and contact
the row starts from, ``ZONA_B``/``BORNIA_B`` the far end. A wire usually appears twice,
once from each end; the second row carries ``REP = 1``. Rows whose wire (``HILO``) ends
in ``SH`` are shield terminations: the screen of a cable brought to one contact (a
backshell ``BS1`` or a drain pin), listed from both sides with an empty (``-``) contact
on the screen's side. The header names ``CABLE`` twice: the first is the cable a wire is
a core of, the second its construction (``1X5``). ``-`` is an empty cell.

Merging (docs/formats/elimco-cable-list.md): rows are grouped by ``HILO``. A wire has one
or two rows; a second row must state the same two ends the other way round, the same
cable and the same length, and may fill a contact part the first left empty. The row with
``REP = 0`` (else the first) gives the wire's direction: its A end is the wire's origin.
A shield has one or more rows that must agree on the one contact it ends at.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Sequence
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import NoReturn

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.sheet import SHEET_SUFFIXES, cell_address, cell_text, read_sheet, workbook_strings
from cadkg.ingest.text import first_line, iter_rows, parse_decimal, read_text
from cadkg.usecases.elimco.cable_list_records import (
    CableListEnd,
    CableListHarness,
    CableListRecord,
    CableListWire,
    ShieldTermination,
)

__all__ = [
    "CableListEnd",
    "CableListHarness",
    "CableListRecord",
    "CableListWire",
    "ShieldTermination",
    "looks_like_cable_list",
    "read_elimco_cable_list",
]

# Column key -> what it holds; the keys are the header names of Figure 11, upper case,
# runs of blanks and underscores as one underscore. The second CABLE column is CABLE_2.
_COLUMNS = {
    "PN": "harness part number",
    "REV": "harness revision",
    "IND": "harness index",
    "ORDEN": "order group of the row",
    "REP": "1 when the row repeats a wire from its other end",
    "SIMBOLO_A": "symbol of the A end",
    "ZONA_A": "connector of the A end",
    "BORNIA_A": "contact of the A end",
    "CNX_A": "contact part of the A end",
    "SH": "shield group",
    "HILO": "wire",
    "CABLE": "cable",
    "CN_TIPO": "wire type",
    "AWG": "gauge",
    "CABLE_2": "cable construction",
    "LONGITUD": "length (mm)",
    "ROUTA": "route",
    "OB": "remark",
    "ZONA_B": "connector of the B end",
    "BORNIA_B": "contact of the B end",
    "CNX_B": "contact part of the B end",
    "CK_CABLE": "check mark",
}
_REQUIRED = ("PN", "REP", "ZONA_A", "BORNIA_A", "HILO", "CABLE", "LONGITUD", "ZONA_B", "BORNIA_B")
_EXPECTED = "a header row naming " + ", ".join(_REQUIRED) + " (the columns of D3.1 Figure 11)"
_SNIFF_KEYS = {"HILO", "ZONA_A", "BORNIA_A"}
_EMPTY = {"", "-"}
_SHIELD = re.compile(r"SH$", re.IGNORECASE)


@dataclass(frozen=True, slots=True)
class _Row:
    number: int
    values: dict[str, str]


def read_elimco_cable_list(path: str | Path) -> list[CableListRecord]:
    """Read a cable list (XLSX or ODS workbook, or CSV/TSV export) into harness, wires and shields.

    A workbook is read from its first sheet holding any value; the header is the first row
    naming the required columns. Records come in the order of their first row, the
    harness first.

    Raises
    ------
    IngestError
        On a file that is not a readable workbook or text export (corrupt, encrypted,
        empty), a sheet without the cable list header, a missing column, a row without
        a wire, connector or contact, a malformed ``REP`` or ``LONGITUD``, a second
        harness, or rows of one wire or shield that disagree; located at
        ``file:Sheet!A1`` (workbooks) or ``file:line`` (text).

    Warns
    -----
    IngestWarning
        When two differently named wires join the same two contacts (a misspelt name).
    """
    if Path(path).suffix.lower() in SHEET_SUFFIXES:
        sheet, sheet_rows = read_sheet(path)
        return _Table(path, sheet).read([(r.number, r.cells) for r in sheet_rows])
    text = read_text(path, expected=_EXPECTED)
    first = next((line for line in text.splitlines() if line.strip()), "")
    delimiter = max(("\t", ";", ","), key=lambda d: len(_columns(first.split(d))))
    return _Table(path, None).read([(row.line, row.cells) for row in iter_rows(text, delimiter, path)])


def looks_like_cable_list(head: bytes) -> bool:
    """Whether a file's first bytes hold the ``HILO``, ``ZONA_A`` and ``BORNIA_A`` headers.

    Text exports are checked on their first non-empty line; XLSX workbooks on the
    strings of the sheet parts that lie in ``head`` (see :func:`workbook_strings`).
    """
    if head.startswith(b"PK\x03\x04"):  # a workbook
        return {_key(s) for s in workbook_strings(head)} >= _SNIFF_KEYS
    first = first_line(head)
    return any({_key(c) for c in first.split(d)} >= _SNIFF_KEYS for d in ("\t", ";", ","))


def _key(cell: object) -> str:
    return re.sub(r"[\s_]+", "_", cell_text(cell).upper())


def _columns(header: Sequence[object]) -> dict[str, int]:
    """Column key -> index; the second ``CABLE`` is ``CABLE_2``, unknown headers are left out."""
    columns: dict[str, int] = {}
    for index, cell in enumerate(header):
        key = _key(cell)
        if key == "CABLE" and "CABLE" in columns:
            key = "CABLE_2"
        if key in _COLUMNS and key not in columns:
            columns[key] = index
    return columns


class _Table:
    def __init__(self, path: str | Path, sheet: str | None) -> None:
        self.path = path
        self.sheet = sheet
        self.columns: dict[str, int] = {}

    def where(self, row: int, key: str | None = None) -> str:
        if self.sheet is None:
            return f"line {row}"
        return cell_address(self.sheet, row, self.columns.get(key or "HILO", 0))

    def error(
        self, reason: str, row: int, key: str | None = None, found: object = None, expected: str | None = None
    ) -> IngestError:
        if self.sheet is None:
            return IngestError(self.path, reason, line=row, found=found, expected=expected)
        column = self.columns.get(key, 0) if key is not None else 0
        return IngestError(
            self.path, reason, cell=cell_address(self.sheet, row, column), found=found, expected=expected
        )

    def ref(self, row: int) -> str:
        return f"line {row}" if self.sheet is None else f"row {row}"

    # -- rows ---------------------------------------------------------------------------------
    def read(self, rows: Sequence[tuple[int, Sequence[object]]]) -> list[CableListRecord]:
        filled = [(n, cells) for n, cells in rows if any(cell_text(c) for c in cells)]
        header_at = next(
            (i for i, (_, cells) in enumerate(filled[:40]) if set(_REQUIRED) <= set(_columns(cells))), None
        )
        if header_at is None:
            self.raise_no_header(filled)
        header_row, header = filled[header_at]
        self.columns = _columns(header)
        data = [
            _Row(n, {k: self.text(cells, i) for k, i in self.columns.items()})
            for n, cells in filled[header_at + 1 :]
        ]
        # A header repeated further down (a list printed page by page) is not a row.
        data = [r for r in data if _key(r.values["HILO"]) != "HILO"]
        if not data:
            raise self.error("no rows after the header", header_row, expected="one row per wire end")
        harness = self.harness(data)
        return [harness, *self.merge(data, harness.part_number)]

    def raise_no_header(self, filled: Sequence[tuple[int, Sequence[object]]]) -> NoReturn:
        if not filled:
            raise IngestError(self.path, "no rows", expected=_EXPECTED)
        best_row, best = max(filled[:40], key=lambda item: len(set(_REQUIRED) & set(_columns(item[1]))))
        known = set(_columns(best))
        if len(known & set(_REQUIRED)) < 3:
            where = f"sheet {self.sheet!r}" if self.sheet is not None else "the file"
            raise self.error(
                f"{where} holds no cable list: no row of its first 40 names the cable list columns",
                filled[0][0],
                found=", ".join(t for t in (cell_text(c) for c in filled[0][1]) if t)[:200],
                expected=_EXPECTED,
            )
        missing = [k for k in _REQUIRED if k not in known]
        raise self.error(
            f"missing column {', '.join(missing)}",
            best_row,
            found=", ".join(t for t in (cell_text(c) for c in best) if t)[:200],
            expected=_EXPECTED,
        )

    @staticmethod
    def text(cells: Sequence[object], index: int) -> str:
        value = cell_text(cells[index]) if index < len(cells) else ""
        return "" if value in _EMPTY else value

    def harness(self, data: list[_Row]) -> CableListHarness:
        first = data[0]
        part = first.values["PN"]
        if not part:
            raise self.error("empty harness part number", first.number, "PN", expected="a PN such as F929A")
        for row in data[1:]:
            if row.values["PN"] != part:
                raise self.error(
                    f"a second harness (the list is of {part}, from {self.ref(first.number)})",
                    row.number,
                    "PN",
                    found=row.values["PN"] or "-",
                    expected=f"{part}: one harness per cable list",
                )
        return CableListHarness(
            part,
            first.values.get("REV") or None,
            first.values.get("IND") or None,
            first.number,
            self.where(first.number, "PN"),
        )

    def rep(self, row: _Row) -> bool:
        value = row.values["REP"]
        if value not in ("", "0", "1"):
            raise self.error("not a repeat mark", row.number, "REP", found=value, expected="0, 1 or -")
        return value == "1"

    def length(self, row: _Row) -> Decimal | None:
        raw = row.values["LONGITUD"]
        if not raw:
            return None
        try:
            number, unit = parse_decimal(raw)
        except ValueError:
            number, unit = Decimal(-1), ""
        if number <= 0 or unit not in ("", "mm"):
            raise self.error(
                "not a length", row.number, "LONGITUD", found=raw, expected="a positive number of millimetres"
            )
        return (number / 1000).normalize()

    def end(self, row: _Row, side: str) -> CableListEnd:
        connector = row.values[f"ZONA_{side}"]
        if not connector:
            raise self.error(
                f"no connector at the {side} end of wire {row.values['HILO']}",
                row.number,
                f"ZONA_{side}",
                expected="a connector name such as A918VC1A",
            )
        return CableListEnd(
            connector, row.values[f"BORNIA_{side}"] or None, row.values.get(f"CNX_{side}") or None
        )

    # -- merging ------------------------------------------------------------------------------
    def merge(self, data: list[_Row], harness: str) -> list[CableListRecord]:
        groups: dict[str, list[_Row]] = {}
        for row in data:
            name = row.values["HILO"]
            if not name:
                raise self.error("no wire name", row.number, "HILO", expected="a wire such as A4351-1669W")
            if not row.values["CABLE"]:
                raise self.error(f"no cable of wire {name}", row.number, "CABLE", expected="a cable name")
            groups.setdefault(name, []).append(row)
        records: list[CableListRecord] = []
        for name, group in groups.items():
            records.append(
                self.shield(name, group, harness) if _SHIELD.search(name) else self.wire(name, group, harness)
            )
        self.check_contacts([r for r in records if isinstance(r, CableListWire)])
        return records

    def wire(self, name: str, group: list[_Row], harness: str) -> CableListWire:
        if len(group) > 2:
            raise self.error(
                f"wire {name} listed a third time ({self.ref(group[0].number)} and "
                f"{self.ref(group[1].number)} list both ends)",
                group[2].number,
                "HILO",
                expected="one row per wire end",
            )
        reps = [self.rep(r) for r in group]
        # The row that is not a repeat gives the wire's direction.
        first = group[reps.index(False)] if False in reps else group[0]
        other = next((r for r in group if r is not first), None)
        origin, destination = self.end(first, "A"), self.end(first, "B")
        for end, side in ((origin, "A"), (destination, "B")):
            if end.contact is None:
                raise self.error(
                    f"no contact at the {side} end of wire {name}",
                    first.number,
                    f"BORNIA_{side}",
                    expected="a contact; only shield wires (names ending in SH) end at no contact",
                )
        length = self.length(first)
        if other is not None:
            back_a, back_b = self.end(other, "A"), self.end(other, "B")
            if (back_a.connector, back_a.contact, back_b.connector, back_b.contact) != (
                destination.connector,
                destination.contact,
                origin.connector,
                origin.contact,
            ):
                raise self.error(
                    f"wire {name} does not repeat the ends of {self.ref(first.number)} the other way round",
                    other.number,
                    "ZONA_A",
                    found=f"{_end_text(back_a)} to {_end_text(back_b)}",
                    expected=f"{_end_text(destination)} to {_end_text(origin)}",
                )
            for key in ("CABLE", "CN_TIPO"):
                mine, theirs = first.values.get(key, ""), other.values.get(key, "")
                if mine and theirs and mine != theirs:
                    raise self.error(
                        f"wire {name} is given another {_COLUMNS[key]} than on {self.ref(first.number)}",
                        other.number,
                        key,
                        found=theirs,
                        expected=mine,
                    )
            back_length = self.length(other)
            if length is not None and back_length is not None and length != back_length:
                raise self.error(
                    f"wire {name} is given another length than on {self.ref(first.number)}",
                    other.number,
                    "LONGITUD",
                    found=other.values["LONGITUD"],
                    expected=first.values["LONGITUD"],
                )
            length = length if length is not None else back_length
            origin = self.fill(origin, back_b, name, other, "CNX_B")
            destination = self.fill(destination, back_a, name, other, "CNX_A")
        values = first.values
        return CableListWire(
            harness=harness,
            name=name,
            cable=values["CABLE"],
            wire_type=values.get("CN_TIPO") or (other.values.get("CN_TIPO") if other else None) or None,
            length_m=length,
            origin=origin,
            destination=destination,
            symbol=values.get("SIMBOLO_A") or None,
            order=values.get("ORDEN") or None,
            gauge=values.get("AWG") or None,
            construction=values.get("CABLE_2") or None,
            route=values.get("ROUTA") or None,
            remark=values.get("OB") or None,
            check=values.get("CK_CABLE") or None,
            rows=tuple(r.number for r in (first, other) if r is not None),
            location=self.where(first.number),
        )

    def fill(self, end: CableListEnd, seen: CableListEnd, name: str, row: _Row, key: str) -> CableListEnd:
        """The contact part of ``end``, completed (or checked) by the same end seen from the other row."""
        if seen.contact_part is None or seen.contact_part == end.contact_part:
            return end
        if end.contact_part is None:
            return CableListEnd(end.connector, end.contact, seen.contact_part)
        raise self.error(
            f"wire {name} is given another contact part at {_end_text(end)}",
            row.number,
            key,
            found=seen.contact_part,
            expected=end.contact_part,
        )

    def shield(self, name: str, group: list[_Row], harness: str) -> ShieldTermination:
        places: list[tuple[_Row, str, str]] = []
        for row in group:
            a, b = row.values["BORNIA_A"], row.values["BORNIA_B"]
            if a and b and a != b:
                raise self.error(
                    f"shield {name} ends at two contacts",
                    row.number,
                    "BORNIA_B",
                    found=f"{a} and {b}",
                    expected="one contact, the other end '-' (the screen)",
                )
            side = "A" if a else "B"
            contact = a or b
            if not contact:
                raise self.error(
                    f"shield {name} ends at no contact",
                    row.number,
                    "BORNIA_A",
                    expected="the contact the screen is brought to, e.g. BS1",
                )
            places.append((row, self.end(row, side).connector, contact))
        first, connector, contact = places[0]
        for row, other_connector, other_contact in places[1:]:
            if (other_connector, other_contact) != (connector, contact):
                raise self.error(
                    f"shield {name} ends elsewhere than on {self.ref(first.number)}",
                    row.number,
                    "BORNIA_A",
                    found=f"{other_connector}:{other_contact}",
                    expected=f"{connector}:{contact}",
                )
        groups = {r.values.get("SH", "") for r in group} - {""}
        if len(groups) > 1:
            raise self.error(
                f"shield {name} is given two shield groups",
                group[-1].number,
                "SH",
                found=", ".join(sorted(groups)),
                expected="one shield group such as A4351-1669/1",
            )
        shield = next(iter(groups), None)
        cable = shield.split("/", 1)[0] if shield else first.values["CABLE"]
        return ShieldTermination(
            harness=harness,
            name=name,
            shield=shield,
            cable=cable,
            connector=connector,
            contact=contact,
            wire_type=first.values.get("CN_TIPO") or None,
            length_m=self.length(first),
            rows=tuple(r.number for r in group),
            location=self.where(first.number),
        )

    def check_contacts(self, wires: list[CableListWire]) -> None:
        seen: dict[frozenset[tuple[str, str | None]], CableListWire] = {}
        for wire in wires:
            key = frozenset(
                {
                    (wire.origin.connector, wire.origin.contact),
                    (wire.destination.connector, wire.destination.contact),
                }
            )
            first = seen.setdefault(key, wire)
            if first is not wire:
                warnings.warn(
                    IngestWarning(
                        self.path,
                        f"wires {first.name} ({self.ref(first.rows[0])}) and {wire.name} join the same "
                        "two contacts; a misspelt wire name lists one wire twice",
                        line=wire.rows[0] if self.sheet is None else None,
                        cell=None if self.sheet is None else self.where(wire.rows[0]),
                    ),
                    stacklevel=4,
                )


def _end_text(end: CableListEnd) -> str:
    return f"{end.connector}:{end.contact or '-'}"
