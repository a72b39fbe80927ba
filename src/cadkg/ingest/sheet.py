"""Workbooks (XLSX, XLSM, XLS, ODS) as sheets of rows with Excel-style cell addresses.

One library reads all four formats: python-calamine (the Rust calamine reader). Before it
builds a sheet, :mod:`cadkg.ingest.sheet_bounds` checks the XML (and
:mod:`cadkg.ingest.xls_bounds` the BIFF records of an XLS) against the limits a sheet must
keep, so a damaged or hostile file is refused at the offending cell instead of filling
memory. Readers pick the sheets whose header says what they are; :func:`read_sheet` keeps
the older rule (the first sheet holding a value) for formats that take one table. Errors
name cells as a spreadsheet program shows them (``Sheet1!C7``: column letters, 1-based rows).

A workbook is told by its content, not its suffix: a ZIP archive is ODS when its
``mimetype`` says so and XLSX/XLSM otherwise; an OLE2 compound file is a legacy XLS.
"""

from __future__ import annotations

import datetime
import re
import struct
import warnings
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.sheet_bounds import (
    MAX_CELLS,
    MAX_ROWS,
    cell_address,
    check_ods_extent,
    column_letter,
    scan_xlsx,
)
from cadkg.ingest.xls_bounds import DamagedWorkbookError, scan_xls
from cadkg.limited import read_limited

__all__ = [
    "SHEET_SUFFIXES",
    "CellError",
    "Sheet",
    "SheetRow",
    "Workbook",
    "cell_address",
    "cell_text",
    "column_letter",
    "is_workbook",
    "read_sheet",
    "read_workbook",
    "settle_sheets",
    "sheet_text",
    "sniff_head",
    "workbook_strings",
]

SHEET_SUFFIXES = (".xlsx", ".xlsm", ".xls", ".ods")
_ZIP = b"PK\x03\x04"
_OLE2 = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"
_ODS = "application/vnd.oasis.opendocument.spreadsheet"
_WORKBOOK_PARTS = re.compile(rb"^xl/(sharedStrings|worksheets/sheet\d*)\.xml$")
_XML_TEXT = re.compile(rb"<(?:\w+:)?t(?:\s[^>]*)?>([^<]*)</(?:\w+:)?t>")
# What sniffers see of a workbook after its first bytes: the text of its first rows.
_SHEET_TEXT = b"\n\x00cadkg-sheet-text\x00\n"
_SNIFF_ROWS = 60
_SNIFF_CELL = 100


@dataclass(frozen=True, slots=True)
class CellError:
    """A cell showing a formula error (``#NAME?``, ``#REF!``) instead of a value."""

    code: str

    def __str__(self) -> str:
        return self.code


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


@dataclass(frozen=True, slots=True)
class Sheet:
    """A sheet: its name, its rows from row 1 (blank ones kept, trailing ones dropped) and the
    ranges of merged cells (1-based first row, 0-based first column, last row, last column) where
    the format states them (XLSX, XLS; not ODS)."""

    name: str
    rows: tuple[SheetRow, ...]
    merged: tuple[tuple[int, int, int, int], ...] = ()

    def address(self, row: int, column: int) -> str:
        """``Sheet!C7`` for 1-based ``row`` and 0-based ``column``."""
        return cell_address(self.name, row, column)

    @property
    def is_empty(self) -> bool:
        return not self.rows


@dataclass(frozen=True, slots=True)
class Workbook:
    """Every sheet of a workbook, in tab order."""

    path: str
    sheets: tuple[Sheet, ...]


def cell_text(value: object) -> str:
    """A cell as the text a user sees: stripped, whole floats without ``.0``, empty for no value."""
    if value is None:
        return ""
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    if isinstance(value, datetime.datetime | datetime.date | datetime.time):
        return value.isoformat()
    return str(value).strip()


def _magic(path: str | Path, expected: str) -> bytes:
    try:
        with Path(path).open("rb") as handle:
            magic = handle.read(4097)
    except OSError as err:
        raise IngestError(path, f"cannot read the file: {err.strerror}") from err
    # Blank, or byte-order marks and white space alone (in UTF-8 or UTF-16): nothing to read.
    bare = magic.replace(b"\xef\xbb\xbf", b"").replace(b"\xff\xfe", b"").replace(b"\xfe\xff", b"")
    if len(magic) <= 4096 and not bare.replace(b"\x00", b"").strip():
        raise IngestError(path, "the file is empty", expected=expected)
    if not magic.startswith((_ZIP, _OLE2)):
        raise IngestError(path, "not a workbook (not a ZIP archive)", found=magic[:4], expected=expected)
    return magic


def read_workbook(path: str | Path) -> Workbook:
    """Every sheet of an XLSX, XLSM, XLS or ODS workbook.

    Raises
    ------
    IngestError
        When the file cannot be read, is empty, is not a workbook, is encrypted or corrupt,
        or a sheet is over the limits of :mod:`cadkg.ingest.sheet_bounds` (at its cell).
    """
    expected = "an XLSX, XLSM, XLS or ODS workbook"
    magic = _magic(path, expected)
    try:
        if magic.startswith(_OLE2):
            errors = scan_xls(path)
        elif _zip_mimetype(path) == _ODS:
            check_ods_extent(path)
            errors = {}
        else:
            errors = scan_xlsx(path)
        sheets = _read(path, errors)
    except IngestError:
        raise
    except BaseException as err:
        # zipfile, lxml and the library fail on a damaged archive in many unrelated ways; the
        # library's own panics (a record it indexes past its end) derive from BaseException.
        if not isinstance(err, Exception) and type(err).__name__ != "PanicException":
            raise
        found = str(err) if isinstance(err, DamagedWorkbookError) else f"{type(err).__name__}: {err}"
        reason = f"corrupt workbook ({found})"
        if magic.startswith(_OLE2) and _encrypted(path):
            reason = "an encrypted workbook (a password-protected XLSX is an OLE2 file holding it)"
        raise IngestError(path, reason[:300], expected=expected) from None
    return Workbook(str(path), tuple(sheets))


def _encrypted(path: str | Path) -> bool:
    with Path(path).open("rb") as handle:
        return "EncryptedPackage".encode("utf-16-le") in handle.read(16 << 20)


def _read(path: str | Path, errors: dict[str, dict[tuple[int, int], str]]) -> list[Sheet]:
    import python_calamine  # deferred: most builds read no workbook

    sheets = []
    with Path(path).open("rb") as handle:
        book = python_calamine.CalamineWorkbook.from_filelike(handle)
        for name in book.sheet_names:
            sheet = book.get_sheet_by_name(name)
            end = sheet.end
            # The bounds scans checked this already (ODS: its repeats); kept as the last word.
            if end is not None and (end[0] + 1) * (end[1] + 1) > MAX_CELLS:
                raise IngestError(
                    path,
                    "the sheet's cells span more than cadkg reads of a sheet",
                    cell=cell_address(name, min(end[0] + 1, MAX_ROWS + 1), end[1]),
                    expected=f"at most {MAX_CELLS:,} cells from A1",
                )
            found: dict[int, list[tuple[int, str]]] = {}
            for (row, column), code in errors.get(name, {}).items():
                found.setdefault(row, []).append((column, code))
            values = sheet.to_python(skip_empty_area=False) if end is not None else []
            rows = []
            for number, row_values in enumerate(values, start=1):
                cells: list[object] = [None if v == "" else v for v in row_values]
                for column, code in found.get(number, ()):
                    if column < len(cells):
                        cells[column] = CellError(code)
                while cells and cells[-1] is None:
                    cells.pop()
                rows.append(SheetRow(number, tuple(cells)))
            del values
            while rows and rows[-1].is_blank:
                rows.pop()
            merged = tuple(
                (r0 + 1, c0, r1 + 1, c1) for (r0, c0), (r1, c1) in (sheet.merged_cell_ranges or ())
            )
            sheets.append(Sheet(str(name), tuple(rows), merged))
    return sheets


def read_sheet(path: str | Path) -> tuple[str, list[SheetRow]]:
    """The name and rows of the first sheet of a workbook that holds any value.

    Rows are numbered as the spreadsheet numbers them; blank rows in between are kept (as
    rows without values) so numbering never drifts, trailing ones dropped.

    Raises
    ------
    IngestError
        As :func:`read_workbook`, and when no sheet holds any value.
    """
    for sheet in read_workbook(path).sheets:
        if sheet.rows:
            return sheet.name, list(sheet.rows)
    raise IngestError(path, "no sheet holds any value", expected="a sheet with a header row")


def settle_sheets(path: str | Path, what: str, found: bool, skipped: list[str], expected: str) -> None:
    """After picking the sheets that hold ``what`` by their header: refuse a workbook without
    one, and warn once, naming them, of the sheets left out.

    Raises
    ------
    IngestError
        When no sheet holds ``what``.
    """
    if not found:
        raise IngestError(path, f"no sheet holds {what}", found=", ".join(skipped)[:200], expected=expected)
    if skipped:
        reason = f"sheets without {what} skipped: {', '.join(skipped)}"
        warnings.warn(IngestWarning(path, reason), stacklevel=3)


def _zip_mimetype(path: str | Path) -> str:
    try:
        with zipfile.ZipFile(path) as archive:
            return archive.read("mimetype")[:100].decode("ascii", "replace")
    except (KeyError, zipfile.BadZipFile, OSError, RuntimeError):
        return ""


def is_workbook(head: bytes) -> bool:
    """Whether a file's first bytes are a ZIP archive or an OLE2 compound file (a legacy XLS)."""
    return head.startswith((_ZIP, _OLE2))


def sniff_head(path: str | Path, head: bytes) -> bytes:
    """What content sniffers see of a file: its first bytes, and for a workbook the text of
    the first rows of each sheet after them (:func:`sheet_text` gives it back).

    A workbook keeps its text compressed or in binary records, and the header of a real
    export often lies beyond the first bytes. A workbook that does not read gives its head
    alone: its reader reports the error when the file is read.
    """
    if not is_workbook(head):
        return head
    try:
        # Read as the readers read it: in a child process under the read limit.
        lines = [str(line) for line in read_limited(path, _first_rows, path)]
    except (IngestError, OSError, ValueError):
        return head
    return head + _SHEET_TEXT + "\n".join(lines).encode("utf-8", "replace")


def _first_rows(path: str | Path) -> list[str]:
    lines = []
    for sheet in read_workbook(path).sheets:
        for row in sheet.rows[:_SNIFF_ROWS]:
            cells = (re.sub(r"\s+", " ", cell_text(c)[:_SNIFF_CELL]) for c in row.cells)
            lines.append("\t".join(cells))
    return lines


def sheet_text(head: bytes) -> str | None:
    """The sheets' text that :func:`sniff_head` put after a workbook's first bytes; None for
    a file that is no workbook or did not read."""
    at = head.find(_SHEET_TEXT)
    if not is_workbook(head) or at < 0:
        return None
    return head[at + len(_SHEET_TEXT) :].decode("utf-8", "replace")


def workbook_strings(head: bytes) -> list[str]:
    """The cell texts of the XLSX sheet and shared-string parts found in the first bytes of a file.

    Content sniffing sees only the head of a file and a workbook is a ZIP archive, so the
    parts that start within ``head`` are inflated as far as they go. Strings come in
    part order; a part cut off by the end of ``head`` gives the strings before the cut.
    """
    end = head.find(_SHEET_TEXT)
    if end >= 0:
        head = head[:end]
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
