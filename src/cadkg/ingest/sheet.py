"""Spreadsheets (XLSX, ODS) as rows of cell values with Excel-style addresses.

Readers of tabular formats that also arrive as workbooks read the first sheet that
holds any value, so a workbook whose first tab was left blank still reads. Errors
name cells as Excel does (``Sheet1!C7``: column letters, 1-based rows), which is
what a user can find in the spreadsheet program.
"""

from __future__ import annotations

import datetime
import math
import re
import struct
import warnings
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from cadkg.errors import IngestError

__all__ = [
    "SHEET_SUFFIXES",
    "SheetRow",
    "cell_address",
    "cell_text",
    "column_letter",
    "read_sheet",
    "workbook_strings",
]

SHEET_SUFFIXES = (".xlsx", ".xlsm", ".ods")
_ZIP = b"PK\x03\x04"
_WORKBOOK_PARTS = re.compile(rb"^xl/(sharedStrings|worksheets/sheet\d*)\.xml$")
_XML_TEXT = re.compile(rb"<(?:\w+:)?t(?:\s[^>]*)?>([^<]*)</(?:\w+:)?t>")
_OLE2 = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"
_PLAIN_SHEET_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_.]*$")
# The most rows and columns a sheet can hold, in Excel and in LibreOffice Calc. A cell
# numbered beyond them comes from a damaged file; reading on would pad up to it.
_MAX_ROWS = 1_048_576
_MAX_COLUMNS = 16_384
# Cells an ODS sheet may expand to, up to its last value: far above any cable list, far
# below what fills memory when a damaged file repeats a row or a cell a billion times.
_MAX_CELLS = 1 << 25
_TABLE = "{urn:oasis:names:tc:opendocument:xmlns:table:1.0}"
_OFFICE = "{urn:oasis:names:tc:opendocument:xmlns:office:1.0}"
_CELLS = (_TABLE + "table-cell", _TABLE + "covered-table-cell")


@dataclass(frozen=True, slots=True)
class SheetRow:
    """One spreadsheet row: its 1-based number and its values (``None`` for an empty cell)."""

    number: int
    cells: tuple[object, ...]

    def cell(self, index: int) -> object:
        """The value at 0-based column ``index``; ``None`` past the row's end."""
        return self.cells[index] if index < len(self.cells) else None

    @property
    def is_blank(self) -> bool:
        return not any(cell_text(c) for c in self.cells)


def column_letter(index: int) -> str:
    """``0`` → ``'A'``, ``25`` → ``'Z'``, ``26`` → ``'AA'`` (0-based column index)."""
    letters = ""
    index += 1
    while index:
        index, rest = divmod(index - 1, 26)
        letters = chr(ord("A") + rest) + letters
    return letters


def cell_address(sheet: str, row: int, column: int) -> str:
    """``'Sheet1!C7'`` for 1-based ``row`` 7 and 0-based ``column`` 2; odd sheet names are quoted."""
    name = sheet if _PLAIN_SHEET_NAME.match(sheet) else "'" + sheet.replace("'", "''") + "'"
    return f"{name}!{column_letter(column)}{row}"


def cell_text(value: object) -> str:
    """A cell as the text a user sees: stripped, whole floats without ``.0``, empty for no value."""
    if value is None:
        return ""
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    if isinstance(value, datetime.datetime | datetime.date | datetime.time):
        return value.isoformat()
    return str(value).strip()


def read_sheet(path: str | Path) -> tuple[str, list[SheetRow]]:
    """The name and rows of the first non-empty sheet of an XLSX or ODS workbook.

    Rows are numbered as the spreadsheet numbers them; blank rows in between are
    kept (as rows without values) so numbering never drifts, trailing ones dropped.

    Raises
    ------
    IngestError
        When the file cannot be read, is empty, is not a workbook (not a ZIP
        archive, an encrypted or legacy ``.xls`` file), is corrupt, or has no value
        in any sheet.
    """
    expected = "an XLSX or ODS workbook"
    try:
        with Path(path).open("rb") as handle:
            magic = handle.read(8)
    except OSError as err:
        raise IngestError(path, f"cannot read the file: {err.strerror}") from err
    if not magic:
        raise IngestError(path, "the file is empty", expected=expected)
    if magic.startswith(_OLE2):
        raise IngestError(
            path,
            "an encrypted workbook or a legacy .xls file (OLE2 compound file)",
            expected="an unencrypted XLSX or ODS workbook",
        )
    if not magic.startswith(_ZIP):
        raise IngestError(path, "not a workbook (not a ZIP archive)", found=magic[:4], expected=expected)
    # The content decides, not the suffix: an ODS archive starts with its mimetype entry.
    is_ods = _zip_mimetype(path) == "application/vnd.oasis.opendocument.spreadsheet"
    try:
        sheets = _ods_sheets(path) if is_ods else _xlsx_sheets(path)
    except IngestError:
        raise
    except Exception as err:
        # openpyxl, odfpy and zipfile fail on a damaged archive in many unrelated ways.
        raise IngestError(
            path, f"corrupt workbook ({type(err).__name__}: {err})"[:300], expected=expected
        ) from None
    for name, rows in sheets:
        while rows and rows[-1].is_blank:
            rows.pop()
        if rows:
            return name, rows
    raise IngestError(path, "no sheet holds any value", expected="a sheet with a header row")


def _zip_mimetype(path: str | Path) -> str:
    try:
        with zipfile.ZipFile(path) as archive:
            return archive.read("mimetype").decode("ascii", "replace")
    except (KeyError, zipfile.BadZipFile, OSError, RuntimeError):
        return ""


def _xlsx_sheets(path: str | Path) -> list[tuple[str, list[SheetRow]]]:
    import openpyxl  # deferred: a second or so of import for files that are mostly CSV

    # A handle rather than the path: openpyxl refuses names not ending in .xlsx or .xlsm,
    # while the content has already been checked to be a ZIP archive.
    with warnings.catch_warnings(), Path(path).open("rb") as handle:
        # openpyxl warns about styles and extensions it drops; none of them carry data.
        warnings.simplefilter("ignore")
        book = openpyxl.load_workbook(handle, read_only=True, data_only=True)
        try:
            sheets = []
            for sheet in book.worksheets:
                # Without this a file declaring a huge used range pads every row to it.
                sheet.reset_dimensions()
                rows = []
                for number, values in enumerate(sheet.iter_rows(values_only=True), start=1):
                    if number > _MAX_ROWS:
                        raise _beyond_last_row(path, str(sheet.title))
                    rows.append(SheetRow(number, tuple(values)))
                sheets.append((str(sheet.title), rows))
            return sheets
        finally:
            book.close()


def _beyond_last_row(path: str | Path, sheet: str) -> IngestError:
    return IngestError(
        path,
        "a row is numbered beyond the last row a sheet can have (a damaged workbook)",
        cell=cell_address(sheet, _MAX_ROWS + 1, 0),
        expected=f"at most {_MAX_ROWS:,} rows",
    )


def _check_ods_extent(path: str | Path) -> None:
    """Refuse repeat counts that expand a sheet past its size: pandas expands every one."""
    with zipfile.ZipFile(path) as archive, archive.open("content.xml") as content:
        rows = last = width = 0
        events = etree.iterparse(
            content, events=("end",), resolve_entities=False, no_network=True, load_dtd=False
        )
        for _, element in events:
            if element.tag == _TABLE + "table":
                rows = last = width = 0
                element.clear()
            elif element.tag == _TABLE + "table-row":
                columns = filled = 0
                for cell in element:
                    if cell.tag in _CELLS:
                        columns += int(cell.get(_TABLE + "number-columns-repeated", "1"))
                        if cell.get(_OFFICE + "value-type") is not None or len(cell):
                            filled = columns
                rows += int(element.get(_TABLE + "number-rows-repeated", "1"))
                if filled:
                    last, width = rows, max(width, filled)
                if rows > _MAX_ROWS or columns > _MAX_COLUMNS or last * width > _MAX_CELLS:
                    raise _oversized(path, _table_name(element), rows, columns)
                element.clear()


def _table_name(row: etree._Element) -> str:
    table = next(row.iterancestors(_TABLE + "table"), None)
    return "Sheet" if table is None else str(table.get(_TABLE + "name", "Sheet"))


def _oversized(path: str | Path, sheet: str, rows: int, columns: int) -> IngestError:
    return IngestError(
        path,
        "repeated rows or cells expand the sheet beyond what a sheet can hold (a damaged workbook)",
        cell=cell_address(sheet, min(rows, _MAX_ROWS + 1), min(columns, _MAX_COLUMNS + 1) - 1),
        expected=f"at most {_MAX_ROWS:,} rows, {_MAX_COLUMNS:,} columns"
        f" and {_MAX_CELLS:,} cells up to the last value",
    )


def _ods_sheets(path: str | Path) -> list[tuple[str, list[SheetRow]]]:
    import pandas as pd

    _check_ods_extent(path)

    frames = pd.read_excel(path, engine="odf", header=None, dtype=object, sheet_name=None)
    sheets = []
    for name, frame in frames.items():
        rows = [
            SheetRow(number, tuple(_ods_value(v) for v in values))
            for number, values in enumerate(frame.itertuples(index=False, name=None), start=1)
        ]
        sheets.append((str(name), rows))
    return sheets


def _ods_value(value: object) -> object:
    # pandas marks empty cells with NaN; a real cell cannot hold NaN.
    if isinstance(value, float) and math.isnan(value):
        return None
    return value


def workbook_strings(head: bytes) -> list[str]:
    """The cell texts of the XLSX sheet and shared-string parts found in the first bytes of a file.

    Content sniffing sees only the head of a file and a workbook is a ZIP archive, so the
    parts that start within ``head`` are inflated as far as they go. Strings come in
    part order; a part cut off by the end of ``head`` gives the strings before the cut.
    """
    strings: list[str] = []
    start = head.find(_ZIP)
    while start >= 0 and start + 30 <= len(head):
        (_, _, flags, method, _, _, _, size, _, name_length, extra_length) = struct.unpack(
            "<4sHHHHHIIIHH", head[start : start + 30]
        )
        name = head[start + 30 : start + 30 + name_length]
        data_start = start + 30 + name_length + extra_length
        if _WORKBOOK_PARTS.match(name) and not flags & 0x1:
            data = head[data_start : data_start + size] if size and not flags & 0x8 else head[data_start:]
            strings += [
                _unescape(m.decode("utf-8", "replace")) for m in _XML_TEXT.findall(_inflate(data, method))
            ]
        start = head.find(_ZIP, data_start if flags & 0x8 or not size else data_start + size)
    return strings


def _inflate(data: bytes, method: int) -> bytes:
    if method == 0:
        return data
    if method != 8:
        return b""
    try:
        return zlib.decompressobj(-15).decompress(data, 1 << 20)
    except zlib.error:
        return b""


def _unescape(text: str) -> str:
    return text.replace("&lt;", "<").replace("&gt;", ">").replace("&quot;", '"').replace("&amp;", "&")
