"""Reader of EPLAN connection lists (wiring lists), the IEMA process description.

Layouts matched by header meaning rather than position: the 11-column form of the
reference's Figure 3 (its last column the wire length in mm); the 15-column Italian "Lista
cablaggio" with preamble rows, decimal commas and units inside cells (``1,5 mm²``); machine
exports, among them the Komax list (machine options, a two-row header whose ``END 1`` and
``END 2`` columns take their meaning from the group label above them). The rows come from
text here, from workbook sheets or EPLAN's labelling XML in :mod:`.connection_files`. The
row order is the operation sequence.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from decimal import Decimal
from itertools import chain, islice
from pathlib import Path
from typing import Any

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.eplan.labels import PinRef, PinSyntaxError, duct_labels, parse_pin_ref
from cadkg.ingest.eplan.list_columns import ALIASES as _ALIASES
from cadkg.ingest.eplan.list_columns import PAIRED as _PAIRED
from cadkg.ingest.eplan.list_columns import PER_END as _PER_END
from cadkg.ingest.sheet_bounds import cell_address
from cadkg.ingest.text import Row, find_header, parse_decimal, read_text

__all__ = [
    "FORMULA_ERRORS",
    "UNKNOWN_END",
    "Connection",
    "ConnectionListInfo",
    "Locate",
    "connection_records",
    "header_in",
    "iter_connection_list",
    "looks_like_connection_list",
    "read_connection_list",
]

_EXPECTED = (
    "a header row naming 'Componente:pin' (origin and destination), 'Numero filo', "
    "'Sezione' and 'Colore', separated by tabs, semicolons or commas"
)
_HEADER_SCAN_ROWS = 40

_END = re.compile(r"^(?P<base>.+?) (?P<end>origine|origin|destinazione|destination)(?: (?P<rest>.*))?$")
_SECTION_UNITS = frozenset({"mm²", "mm2", "mmq", "mm^2"})
_LENGTH_UNITS = frozenset({"m", "mm"})
_REQUIRED = {
    "origin_pin": "Componente:pin (origin)",
    "destination_pin": "Componente:pin (destination)",
    "wire_number": "Numero filo",
    "section": "Sezione",
    "colour": "Colore",
}


@dataclass(frozen=True, slots=True)
class ConnectionListInfo:
    """What the preamble of a connection list says about the project."""

    project: str | None
    job: str | None
    header_line: int


@dataclass(frozen=True, slots=True)
class Connection:
    """One wire to make: a row of the connection list, in operation order."""

    index: int
    line: int
    origin: PinRef
    destination: PinRef
    wire_number: str
    section_mm2: Decimal | None
    colour: str | None
    potential_type: str | None
    potential_name: str | None
    length_m: Decimal | None
    duct_path: tuple[str, ...]
    origin_termination: str | None
    destination_termination: str | None
    origin_page: str | None
    origin_zone: str | None
    destination_page: str | None
    destination_zone: str | None
    cable_name: str | None = None
    job_key: str | None = None
    origin_direction: str | None = None
    destination_direction: str | None = None
    bundling_side: str | None = None
    # The duct path as the list writes it (``=-U3;=-U5`` or ``=-CN2'=-CN3``); ``duct_path`` has its labels.
    duct_text: str | None = None


# The end of a wire whose pin cell holds no reference (a formula EPLAN could not evaluate, shown
# as ``#NAME?``, or the empty cell LibreOffice leaves for it): the wire is kept, this end unknown.
UNKNOWN_END = PinRef(component="?", pin="?", level=None, raw="")


def _norm(header: str) -> str:
    return re.sub(r"\s+", " ", header.strip().lower())


# Komax lists name a per-end column 'END 1' / 'END 2' and say what it is in the row above
# (a group label such as 'DIREZIONE' over both).
_GROUPED_END = re.compile(r"^end ?(?P<end>[12])$")
_GROUPS = {"direzione": "direction", "direction": "direction"}


def _grouped(header: Row, above: Row | None) -> dict[str, int]:
    """Per-end columns named by the group label above them (``DIREZIONE`` over ``END 1``)."""
    if above is None:
        return {}
    columns: dict[str, int] = {}
    group = ""
    for index, cell in enumerate(header.cells):
        label = _norm(above.cells[index]) if index < len(above.cells) else ""
        group = label or group
        end = _GROUPED_END.match(_norm(cell))
        if end is not None and group in _GROUPS:
            side = "origin" if end["end"] == "1" else "destination"
            columns.setdefault(f"{side}_{_GROUPS[group]}", index)
    return columns


def _columns(row: Row) -> dict[str, int]:
    columns: dict[str, int] = {}
    for index, cell in enumerate(row.cells):
        header = _norm(cell)
        meaning = _ALIASES.get(header)
        ends = _END.match(header) if meaning is None else None
        if ends is not None:
            base = f"{ends['base']} {ends['rest'] or ''}".strip()
            if base in _PER_END:
                end = "origin" if ends["end"].startswith("origin") else "destination"
                columns.setdefault(f"{end}_{_PER_END[base]}", index)
            continue
        if meaning is None:
            continue
        if meaning in _PAIRED:
            key = f"origin_{meaning}" if f"origin_{meaning}" not in columns else f"destination_{meaning}"
        else:
            key = meaning
        columns.setdefault(key, index)
    return columns


def _find_header(text: str, path: str | Path) -> tuple[list[Row], Iterator[Row], int, dict[str, int]]:
    # One pin column is enough to take the row for the header, so that a missing twin
    # is reported as a missing column rather than as no header at all.
    rows, after, position, columns = find_header(
        text,
        path,
        _columns,
        lambda columns: bool({"origin_pin", "destination_pin"} & columns.keys()) and len(columns) >= 3,
        _EXPECTED,
        _HEADER_SCAN_ROWS,
    )
    # Figure 3's 11-column form shifts the potential columns: 'Tipo' then 'pot.' whose
    # numbers are the wire length in mm (there is no separate length column).
    if "potential_name" in columns and not ({"length_m", "length_mm"} & columns.keys()):
        header = rows[position]
        if (
            _norm(header.cells[columns["potential_name"]]) == "pot."
            and _norm(header.cells[columns.get("potential_type", -1)] if "potential_type" in columns else "")
            == "tipo"
        ):
            columns["length_mm"] = columns.pop("potential_name")
    return rows, after, position, columns


def _preamble_value(rows: list[Row], label: str) -> str | None:
    for row in rows:
        for i, cell in enumerate(row.cells):
            if _norm(cell) == label:
                for later in row.cells[i + 1 :]:
                    if later.strip():
                        return later.strip()
    return None


def read_connection_list(path: str | Path) -> list[ConnectionListInfo | Connection]:
    """Read an EPLAN connection list into a :class:`ConnectionListInfo` and its connections.

    Raises
    ------
    IngestError
        When no header is found, a required column is missing, a number or pin
        reference is malformed, or there are no data rows; located at file:line.
    """
    return list(iter_connection_list(path))


def iter_connection_list(path: str | Path) -> Iterator[ConnectionListInfo | Connection]:
    """The records of :func:`read_connection_list` one by one, as the rows are converted.

    The header is checked before the first record; a malformed row raises when it is reached.
    """
    text = read_text(path, expected=_EXPECTED)
    rows, after, header_at, columns = _find_header(text, path)
    del text  # the rows after the header hold it still, as long as they are read
    yield from connection_records(path, chain(rows, after), header_at, columns, None)


def header_in(rows: list[Row], scan_rows: int = _HEADER_SCAN_ROWS) -> tuple[int, dict[str, int]] | None:
    """Where a connection list's header is among the first rows of a sheet, and its columns."""
    for position, row in enumerate(rows[:scan_rows]):
        columns = _columns(row)
        if {"origin_pin", "destination_pin"} & columns.keys() and len(columns) >= 3:
            return position, columns
    return None


def connection_records(
    path: str | Path,
    rows: Iterable[Row],
    header_at: int,
    columns: dict[str, int],
    sheet: str | None,
    locate: Locate | None = None,
) -> Iterator[ConnectionListInfo | Connection]:
    """The records of a connection list whose header is ``rows[header_at]``; ``sheet`` names
    the workbook sheet the rows come from (errors then name cells, ``Sheet!C7``), ``locate``
    how else to say where a row is. ``rows`` are read once, in order."""
    rows = iter(rows)
    preamble = list(islice(rows, header_at))
    header = next(rows)
    columns = {**_grouped(header, preamble[-1] if preamble else None), **columns}
    locate = locate or _Locator(path, sheet)
    missing = [name for key, name in _REQUIRED.items() if key not in columns]
    if missing:
        found = ", ".join(re.sub(r"\s+", " ", c.strip()) for c in header.cells if c.strip())
        raise IngestError(
            path,
            f"missing column {', '.join(repr(m) for m in missing)}",
            found=found[:200],
            expected="the connection list columns " + ", ".join(_REQUIRED.values()),
            **locate(header.line, 0),
        )
    header_names = {key: re.sub(r"\s+", " ", header.cells[i].strip()) for key, i in columns.items()}
    yield ConnectionListInfo(
        project=_preamble_value(preamble, "nome progetto:") or _preamble_value(preamble, "programma"),
        job=_preamble_value(preamble, "commessa:"),
        header_line=header.line,
    )
    convert = _RowConverter(path, columns, header_names, locate, sheet is not None)
    index = 0
    for row in rows:
        if row.is_blank:
            continue
        connection = convert(row, index + 1)
        if connection is None:
            continue
        index += 1
        yield connection
    if index == 0:
        raise IngestError(
            path,
            "no connections after the header",
            expected="at least one data row",
            **locate(header.line, 0),
        )


# What a spreadsheet shows in a cell whose formula failed: no value a row can be read from.
FORMULA_ERRORS = frozenset({"#NAME?", "#REF!", "#VALUE!", "#DIV/0!", "#N/A", "#NULL!", "#NUM!", "Err:502"})


Locate = Callable[[int, int], dict[str, Any]]


class _Locator:
    """``line=`` for a text file, ``cell=`` (``Sheet!C7``) for a sheet: where an error points."""

    def __init__(self, path: str | Path, sheet: str | None) -> None:
        self.path = path
        self.sheet = sheet

    def __call__(self, line: int, column: int) -> dict[str, Any]:
        if self.sheet is None:
            return {"line": line}
        return {"cell": cell_address(self.sheet, line, column)}


# Record fields taken as they stand in their column (stripped; empty → None).
_TEXT_FIELDS = (
    "colour",
    "potential_type",
    "potential_name",
    "origin_termination",
    "destination_termination",
    "origin_page",
    "origin_zone",
    "destination_page",
    "destination_zone",
    "cable_name",
    "job_key",
    "origin_direction",
    "destination_direction",
    "bundling_side",
)


class _RowConverter:
    """Turns data rows into :class:`Connection` records.

    Built once per file: column positions are looked up once, and the values that
    repeat down a list (sections, lengths, duct paths) are parsed once each.
    """

    def __init__(
        self, path: str | Path, columns: dict[str, int], names: dict[str, str], locate: Locate, sheet: bool
    ) -> None:
        self.path = path
        # A sheet's empty pin cell is a formula the spreadsheet evaluated to nothing (LibreOffice's
        # form of #NAME?); in a text list it is a wire without an end, an error.
        self.sheet = sheet
        self.columns = columns
        self.names = names
        self.locate = locate
        # A column the file lacks sits past every row's end, so its field reads as None.
        self.text_columns = [(name, columns.get(name, 1 << 30)) for name in _TEXT_FIELDS]
        self.length_key = "length_m" if "length_m" in columns else "length_mm"
        self.numbers: dict[tuple[str, str], Decimal] = {}
        self.ducts: dict[str, tuple[str, ...]] = {}
        absent = 1 << 30
        keys = ("wire_number", "origin_pin", "destination_pin", "section", self.length_key, "duct_path")
        self.at = tuple(columns.get(key, absent) for key in keys)

    def __call__(self, row: Row, index: int) -> Connection | None:
        cells = row.cells
        width = len(cells)
        # Each cell stripped once; a column past the row's end reads as empty.
        wire_number, origin, destination, section, length, ducts = (
            cells[at].strip() if at < width else "" for at in self.at
        )
        fields: dict[str, str | None] = {
            name: (cells[at].strip() or None) if at < width else None for name, at in self.text_columns
        }
        if not wire_number:
            raise self.empty(row, "wire_number", "a wire number such as 1500.51 or 0V")
        if fields["cable_name"] == "=":
            fields["cable_name"] = None  # EPLAN's empty function designation: no cable
        origin_ref = self.pin(row, "origin_pin", origin, destination)
        destination_ref = self.pin(row, "destination_pin", destination, origin)
        return Connection(
            index=index,
            line=row.line,
            origin=origin_ref,
            destination=destination_ref,
            wire_number=wire_number,
            section_mm2=self.number(row, "section", section) if section else None,
            length_m=self.number(row, self.length_key, length) if length else None,
            duct_path=self.duct_path(ducts) if ducts else (),
            **fields,
            duct_text=ducts or None,
        )

    def empty(self, row: Row, key: str, expected: str) -> IngestError:
        """The error for an empty required cell, or for the quote that emptied it."""
        if key in self.columns and self.columns[key] >= len(row.cells):
            for cell in row.cells:
                if "\t" in cell or "\n" in cell:
                    # A cell that starts with '"' runs on, delimiters and line ends included,
                    # to the next quote: the cells after it are missing, not empty.
                    return IngestError(
                        self.path,
                        "a cell opened with '\"' runs over the cells after it",
                        **self.locate(row.line, self.columns[key]),
                        found=cell[:40].split("\n", 1)[0] + " ...",
                        expected="no '\"' at the start of a cell, or its closing '\"' in the same cell",
                    )
        return IngestError(
            self.path,
            f"empty cell in column {self.names[key]!r}",
            expected=expected,
            **self.locate(row.line, self.columns.get(key, 0)),
        )

    def duct_path(self, text: str) -> tuple[str, ...]:
        path = self.ducts.get(text)
        if path is None:
            path = self.ducts[text] = duct_labels(text)
        return path

    def pin(self, row: Row, key: str, raw: str, other: str) -> PinRef:
        if raw in FORMULA_ERRORS or (self.sheet and not raw and other and other not in FORMULA_ERRORS):
            # The export lost this end's value: the wire keeps its place in the list with the
            # end unknown, and the derivation flags it (missing pin data), as the cell's software.
            shown = f"the formula error {raw}" if raw else "no pin reference"
            warnings.warn(
                IngestWarning(
                    self.path,
                    f"the cell shows {shown}; the wire is kept with this end unknown (?:?)",
                    **self.locate(row.line, self.columns[key]),
                ),
                stacklevel=5,
            )
            return UNKNOWN_END
        if not raw or raw == "-":
            raise self.empty(row, key, "a pin reference such as -F1500.1:14")
        try:
            return parse_pin_ref(raw)
        except PinSyntaxError as err:
            raise IngestError(
                self.path,
                f"unknown pin reference in column {self.names[key]!r}: {err}",
                **self.locate(row.line, self.columns[key]),
                found=raw,
                expected="DEVICE:PIN or DEVICE:TERMINAL:LEVEL, e.g. -F1500.1:14 or =-X1600:2:a",
            ) from None

    def number(self, row: Row, key: str, raw: str) -> Decimal:
        value = self.numbers.get((key, raw))
        if value is None:
            value = self.numbers[(key, raw)] = self._parse_number(row, key, raw)
        return value

    def _parse_number(self, row: Row, key: str, raw: str) -> Decimal:
        unit, units = ("mm²", _SECTION_UNITS) if key == "section" else (key[len("length_") :], _LENGTH_UNITS)
        try:
            value, found_unit = parse_decimal(raw)
        except ValueError:
            raise IngestError(
                self.path,
                f"not a number in column {self.names[key]!r}",
                **self.locate(row.line, self.columns[key]),
                found=raw,
                expected=f"a number in {unit}, e.g. 1,5 or 1.5 {unit}",
            ) from None
        if found_unit and found_unit.lower() not in units:
            raise IngestError(
                self.path,
                f"wrong unit in column {self.names[key]!r}",
                **self.locate(row.line, self.columns[key]),
                found=raw,
                expected=f"a number in {unit}",
            )
        if value <= 0:
            raise IngestError(
                self.path,
                f"non-positive value in column {self.names[key]!r}",
                **self.locate(row.line, self.columns[key]),
                found=raw,
                expected=f"a positive number in {unit}",
            )
        if key != "section" and (found_unit or unit) == "mm":
            return value / 1000
        return value


def looks_like_connection_list(head: bytes) -> bool:
    """Whether the first bytes hold a connection list's pin column (``Componente:pin`` ...)."""
    text = head.decode("utf-8", errors="replace").lower()
    return "componente:pin" in text or "component:pin" in text or "device:pin" in text
