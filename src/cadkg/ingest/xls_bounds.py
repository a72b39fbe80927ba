"""Limits a legacy XLS workbook must keep: checked on its BIFF records before the library reads it.

An XLS is a stream of BIFF records inside an OLE2 compound file, and the workbook library
trusts both: it reserves 40 bytes for every cell of a sheet's declared DIMENSIONS range
(counting inverted rows round to four billion), builds each sheet as a dense block from A1 to
its last cell, and takes column numbers up to 65,535 although a sheet has 256. Measured with
python-calamine 0.9: two cells, at A1 and IV65536 (a 2.5 KB file), take 1.1 GB; a cell in
column 65,536 or a declared range of 65,536 × 16,384 makes it ask for 137 or 43 GB and abort
the process.

So the Workbook stream is read first, through olefile as :mod:`cadkg.ingest.compound_file`
checks it (held whole, at most 256 MiB), its records taken in 1 MiB chunks: its shared
strings (counts and each string's length), then each sheet's declared range and cells,
refused at the cell that crosses a limit of :mod:`cadkg.ingest.sheet_bounds`. The scan also
notes the formula errors (``#NAME?``) the library reads as empty cells, as the XLSX scan does,
and refuses as damaged the few records on which the library would panic instead of failing.
"""

from __future__ import annotations

import os
import struct
from array import array
from collections.abc import Iterator
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.compound_file import CompoundFile, DamagedWorkbookError, Stream
from cadkg.ingest.sheet_bounds import (
    MAX_CELLS,
    MAX_COLUMNS,
    MAX_ROWS,
    MAX_TEXT,
    TextBudget,
    cell_address,
    shared_string_error,
)

__all__ = ["DamagedWorkbookError", "scan_xls"]

_STREAMS = frozenset({"workbook", "book"})  # BIFF8 and BIFF5 (an Excel 97/95 file may hold both)
_MAX_STREAMS = 4
_CHUNK = 1 << 20
_MAX_STRINGS = MAX_CELLS
_EXTENT = f"at most {MAX_ROWS:,} rows, {MAX_COLUMNS:,} columns and {MAX_CELLS:,} cells from A1"

_BOF, _EOF, _CONTINUE = 0x0809, 0x000A, 0x003C
_BOUNDSHEET, _SST, _DIMENSIONS, _MERGECELLS = 0x0085, 0x00FC, 0x0200, 0x00E5
_FORMULA, _STRING, _BOOLERR, _LABEL, _RSTRING, _LABELSST = 0x0006, 0x0207, 0x0205, 0x0204, 0x00D6, 0x00FD
_MULRK, _MULBLANK = 0x00BD, 0x00BE
# The records the library makes a cell of (checked by trying every record type on it); blanks
# it leaves out, so they are held to the sheet's size but do not widen the block. ROW records
# (a row's height and the columns it spans) are not read: the library builds nothing from them.
_VALUES = frozenset({_FORMULA, _RSTRING, 0x00FD, 0x0203, _LABEL, _BOOLERR, 0x027E})
_BLANK = 0x0201
_ERRORS = {
    0x00: "#NULL!",
    0x07: "#DIV/0!",
    0x0F: "#VALUE!",
    0x17: "#REF!",
    0x1D: "#NAME?",
    0x24: "#NUM!",
    0x2A: "#N/A",
    0x2B: "#GETTING_DATA",
}


# The fixed part of the records the library reads, in bytes (the shorter of BIFF5's and
# BIFF8's): it indexes into them without checking their length and panics on a shorter one.
# The scan below reads these records' fixed fields without checking their length either.
_FIXED = {
    _BOF: 4,
    0x0042: 2,  # CODEPAGE
    0x0022: 2,  # DATEMODE
    0x0018: 14,  # NAME
    0x0017: 2,  # EXTERNSHEET
    0x00E0: 16,  # XF
    0x041E: 3,  # FORMAT
    _BOUNDSHEET: 7,
    _SST: 8,
    _DIMENSIONS: 10,
    0x0208: 16,  # ROW
    0x0203: 14,  # NUMBER
    0x027E: 10,  # RK
    0x00FD: 10,  # LABELSST
    _BLANK: 6,
    _BOOLERR: 8,
    _LABEL: 8,
    _FORMULA: 20,
    _MULRK: 6,
    _MULBLANK: 6,
}
_NAMES = {
    0x0042: "CODEPAGE",
    0x0022: "DATEMODE",
    0x0018: "NAME",
    0x0017: "EXTERNSHEET",
    0x00E0: "XF",
    0x041E: "FORMAT",
    0x0208: "ROW",
}


def _records(stream: Stream, offset: int, position: list[int]) -> Iterator[tuple[int, bytes]]:
    """(type, data) of each record from ``offset`` to the stream's end or a record cut short;
    ``position[0]`` follows the offset of the next record."""
    buffer, pos, at = b"", 0, offset
    while True:
        left = len(buffer) - pos
        if left < 4 or left < 4 + int.from_bytes(buffer[pos + 2 : pos + 4], "little"):
            more = stream.read(at, _CHUNK)
            at += len(more)
            buffer, pos = buffer[pos:] + more, 0
            if len(buffer) < 4:
                return
            if len(buffer) < 4 + int.from_bytes(buffer[2:4], "little"):
                return
        kind, size = struct.unpack_from("<HH", buffer, pos)
        if size < _FIXED.get(kind, 0):
            name = _NAMES.get(kind, f"0x{kind:04X}")
            raise DamagedWorkbookError(
                f"a {name} record of {size} bytes at {at - len(buffer) + pos} is cut short"
            )
        data = buffer[pos + 4 : pos + 4 + size]
        pos += 4 + size
        position[0] = at - len(buffer) + pos
        yield kind, data


class _Continued:
    """A record's data and the CONTINUE records after it, read as one, but for the flags byte
    that starts each continuation of a string's characters."""

    def __init__(self, data: bytes, records: Iterator[tuple[int, bytes]]) -> None:
        self.data, self.pos, self.records = data, 0, records
        self.after: tuple[int, bytes] | None = None

    def advance(self) -> bool:
        while self.after is None:
            item = next(self.records, None)
            if item is None or item[0] != _CONTINUE:
                self.after = item
                return False
            if item[1]:
                self.data, self.pos = item[1], 0
                return True
        return False

    def take(self, length: int) -> bytes | None:
        taken = b""
        while len(taken) < length:
            if self.pos >= len(self.data) and not self.advance():
                return None
            piece = self.data[self.pos : self.pos + length - len(taken)]
            taken += piece
            self.pos += len(piece)
        return taken

    def skip(self, length: int) -> bool:
        while length > 0:
            if self.pos >= len(self.data) and not self.advance():
                return False
            step = min(length, len(self.data) - self.pos)
            self.pos += step
            length -= step
        return True

    def characters(self, count: int, wide: bool) -> bool:
        width = 2 if wide else 1
        while True:
            room = (len(self.data) - self.pos) // width
            if room >= count:
                self.pos += count * width
                return True
            count -= room
            if not self.advance():
                return False
            width = 2 if self.data[0] & 1 else 1
            self.pos = 1


def _check_strings(
    data: bytes, records: Iterator[tuple[int, bytes]], path: str | Path, lengths: array[int]
) -> tuple[int, bytes] | None:
    """Count the shared strings and measure each (its length goes on ``lengths``); the record
    after them, already read."""
    number = 0

    def refuse(reason: str) -> IngestError:
        return shared_string_error(path, reason, number)

    if struct.unpack_from("<I", data, 4)[0] > _MAX_STRINGS:
        raise refuse("the workbook declares more shared strings than cadkg reads")
    cursor = _Continued(data, records)
    cursor.pos = 8
    # Past the declared count too: the strings the records hold are what the library keeps.
    while (head := cursor.take(3)) is not None:
        number += 1
        if number > _MAX_STRINGS:
            raise refuse("more shared strings than cadkg reads of a workbook")
        length, flags = struct.unpack("<HB", head)
        if length > MAX_TEXT:
            raise refuse("a cell's text is longer than a cell can hold")
        lengths.append(length)
        runs = cursor.take(2) if flags & 0x08 else b"\x00\x00"
        extra = cursor.take(4) if flags & 0x04 else bytes(4)
        if runs is None or extra is None or not cursor.characters(length, bool(flags & 1)):
            break
        if not cursor.skip(4 * int.from_bytes(runs, "little") + int.from_bytes(extra, "little")):
            break
    while cursor.after is None and cursor.advance():
        pass  # CONTINUE records the strings did not reach
    return cursor.after


class _Sheet:
    """Raises the located error of a sheet over a limit."""

    def __init__(self, path: str | Path, name: str, strings: array[int], budget: TextBudget) -> None:
        self.path, self.name = path, name
        self.strings, self.budget = strings, budget

    def spend(self, size: int, row: int, column: int) -> None:
        if not self.budget.spend(size):
            reason, expected = TextBudget.refusal()
            raise self.refuse(reason, row, column, expected)

    def refuse(self, reason: str, row: int, column: int, expected: str = _EXTENT) -> IngestError:
        row, column = min(max(row, 1), MAX_ROWS + 1), min(max(column, 0), MAX_COLUMNS)
        return IngestError(self.path, reason, cell=cell_address(self.name, row, column), expected=expected)

    def check_range(self, data: bytes) -> None:
        # The library reserves (last row + 1 - first row) x (last column + 1) cells, 40 bytes
        # each, with 32-bit rows from a 14-byte record (BIFF8) and 16-bit ones from a 10-byte
        # one (BIFF5), the subtraction wrapping round when the rows are inverted. Unlike an
        # XLSX dimension the declared range is therefore held to the cells a sheet may span.
        ranges = []
        if len(data) >= 12:
            ranges.append(struct.unpack_from("<IIHH", data))
        if 8 <= len(data) < 14:
            ranges.append(struct.unpack_from("<HHHH", data))
        for first_row, rows, first_column, columns in ranges:
            if rows > MAX_ROWS or columns > MAX_COLUMNS or first_row > rows or first_column > columns:
                raise self.refuse(
                    "the sheet declares a range beyond the last row or column a sheet can have,"
                    " or inverted (a damaged workbook)",
                    rows,
                    columns - 1,
                )
            if rows * columns > MAX_CELLS:
                raise self.refuse(
                    "the sheet declares a range larger than cadkg reads of a sheet", rows, columns - 1
                )

    def beyond(self, row: int, column: int) -> IngestError:
        return self.refuse(
            "a cell lies beyond the last row or column a sheet can have (a damaged workbook)", row, column
        )


def _scan_sheet(records: Iterator[tuple[int, bytes]], sheet: _Sheet) -> dict[tuple[int, int], str]:
    """Check one sheet's records; the formula errors it holds, by (1-based row, 0-based column)."""
    errors: dict[tuple[int, int], str] = {}
    depth = last_row = last_column = cells = row = column = 0
    text = f"at most {MAX_TEXT:,} characters a cell"
    for kind, data in records:
        if kind in _VALUES or kind == _MULRK:
            if len(data) < 6:  # an RSTRING, whose fixed part _records does not check
                continue
            row, column = struct.unpack_from("<HH", data)
            row += 1
            count = (len(data) - 6) // 6 if kind == _MULRK else 1
            last = column + count - 1
            if kind == _MULRK:
                last = max(last, struct.unpack_from("<H", data, len(data) - 2)[0])
            if last >= MAX_COLUMNS:
                raise sheet.beyond(row, last)
            if count < 1:
                continue
            cells += count
            last_row, last_column = max(last_row, row), max(last_column, column + count - 1)
            if last_row * (last_column + 1) > MAX_CELLS or cells > MAX_CELLS:
                raise sheet.refuse(
                    "the sheet's cells span more than cadkg reads of a sheet", row, column + count - 1
                )
            if kind == _BOOLERR and data[7]:
                errors[(row, column)] = _ERRORS.get(data[6], "#VALUE!")
            elif kind == _FORMULA and data[6] == 2 and data[12:14] == b"\xff\xff":
                errors[(row, column)] = _ERRORS.get(data[8], "#VALUE!")
            elif kind in (_LABEL, _RSTRING):
                length = int.from_bytes(data[6:8], "little")
                if length > MAX_TEXT:
                    raise sheet.refuse("a cell's text is longer than a cell can hold", row, column, text)
                sheet.spend(length, row, column)
            elif kind == _LABELSST:
                index = struct.unpack_from("<I", data, 6)[0]
                sheet.spend(sheet.strings[index] if index < len(sheet.strings) else 0, row, column)
        elif kind == _STRING:
            # A formula's text result, for the FORMULA cell just before it.
            length = struct.unpack_from("<H", data)[0] if len(data) >= 2 else 0
            if length > MAX_TEXT:
                raise sheet.refuse("a cell's text is longer than a cell can hold", row, column, text)
            sheet.spend(length, row, column)
        elif kind in (_BLANK, _MULBLANK):
            blank_row, first = struct.unpack_from("<HH", data)
            last = first + (len(data) - 6) // 2 - 1 if kind == _MULBLANK else first
            if max(first, last) >= MAX_COLUMNS:
                raise sheet.beyond(blank_row + 1, max(first, last))
        elif kind == _DIMENSIONS:
            sheet.check_range(data)
        elif kind == _MERGECELLS:
            # The library reads the declared number of ranges without looking at the length.
            if len(data) < 2 or len(data) < 2 + 8 * struct.unpack_from("<H", data)[0]:
                raise DamagedWorkbookError(f"a list of merged cells of sheet {sheet.name} is cut short")
        elif kind == _BOF:
            depth += 1
        elif kind == _EOF:
            depth -= 1
            if depth <= 0:
                break
    return errors


def _sheet_name(data: bytes, biff8: bool) -> str:
    length = data[6]
    if not biff8:
        return data[7 : 7 + length].decode("cp1252", "replace")
    if len(data) > 7 and data[7] & 1:
        return data[8 : 8 + 2 * length].decode("utf-16-le", "replace")
    return data[8 : 8 + length].decode("latin-1")


def _scan_stream(
    stream: Stream, path: str | Path, budget: TextBudget
) -> dict[str, dict[tuple[int, int], str]]:
    position = [0]
    records = _records(stream, 0, position)
    sheets: list[tuple[str, int]] = []
    strings = array("Q")  # the length of each shared string, as the XLSX scan keeps them
    biff8 = True
    item = next(records, None)
    while item is not None:
        kind, data = item
        item = None
        if kind == _BOF:
            biff8 = struct.unpack_from("<H", data)[0] == 0x0600
        elif kind == 0x0017 and biff8 and len(data) < 2 + 6 * struct.unpack_from("<H", data)[0]:
            # The library slices every reference the count announces out of this one record.
            raise DamagedWorkbookError(f"an EXTERNSHEET record of {len(data)} bytes is cut short")
        elif kind == _BOUNDSHEET:
            sheets.append((_sheet_name(data, biff8), struct.unpack_from("<I", data)[0]))
        elif kind == _SST:
            item = _check_strings(data, records, path, strings)
            continue
        elif kind == _EOF:
            break
        item = next(records, None)
    errors: dict[str, dict[tuple[int, int], str]] = {}
    spans: list[tuple[int, int]] = []
    for name, offset in sheets:
        if offset >= stream.size:
            # The library would slice its stream there and panic.
            raise DamagedWorkbookError(f"sheet {name} starts past the end of the workbook stream")
        # Two sheets reading the same records would be built (and scanned) twice from one
        # file's bytes: checked before the scan and, for a sheet starting further on, after it.
        if any(start <= offset < end for start, end in spans):
            raise DamagedWorkbookError(f"sheet {name} starts within another sheet's records")
        found = _scan_sheet(_records(stream, offset, position), _Sheet(path, name, strings, budget))
        if any(offset <= start < position[0] for start, _ in spans):
            raise DamagedWorkbookError(f"sheet {name} holds another sheet's records")
        spans.append((offset, position[0]))
        if found:
            errors.setdefault(name, {}).update(found)
    return errors


def scan_xls(path: str | Path) -> dict[str, dict[tuple[int, int], str]]:
    """Check a legacy XLS workbook against the limits; per sheet name, its formula error cells.

    Raises
    ------
    IngestError
        At the cell (or shared string) over a limit, or naming the limit of the compound file
        (:data:`~cadkg.ingest.compound_file.MAX_STREAM` and its neighbours) it is over.
    DamagedWorkbookError
        When the compound file or a record cannot be read safely, which the caller reports as
        a corrupt workbook.
    """
    with Path(path).open("rb") as handle:
        container = CompoundFile(path, handle, os.fstat(handle.fileno()).st_size)
        errors: dict[str, dict[tuple[int, int], str]] = {}
        budget = TextBudget()
        for stream in container.streams(_STREAMS, _MAX_STREAMS):
            for name, found in _scan_stream(stream, path, budget).items():
                errors.setdefault(name, {}).update(found)
        return errors
