"""Limits a legacy XLS workbook must keep: checked on its BIFF records before the library reads it.

An XLS is a stream of BIFF records inside an OLE2 compound file. The workbook library trusts
both: it reserves 40 bytes for every cell of a sheet's declared DIMENSIONS range, builds each
sheet as a dense block from A1 to its last cell, takes a column number up to 65,535 although a
sheet has 256 columns, and follows a sector chain wherever it leads. Measured with
python-calamine 0.9: two cells, at A1 and IV65536 (a 2.5 KB file), take 1 GB; a cell in
column 65,536 or a declared range of 65,536 × 16,384 makes it ask for 40 GB to 11 PB and abort
the process; a directory whose sector chain loops keeps it busy forever.

So the compound file is walked here first, with every sector number, chain and count checked
against the file's size (the FAT is the only table held whole, 4 bytes a sector), and the
Workbook stream is read in 1 MiB chunks: its shared strings (counts and each string's length),
then each sheet's declared range and cells, refused at the cell that crosses a limit of
:mod:`cadkg.ingest.sheet_bounds`. The scan also notes the formula errors (``#NAME?``) the
library reads as empty cells, as the XLSX scan does.
"""

from __future__ import annotations

import os
import struct
import sys
from array import array
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

from cadkg.errors import IngestError
from cadkg.ingest.sheet_bounds import MAX_CELLS, MAX_COLUMNS, MAX_ROWS, MAX_TEXT, cell_address

__all__ = ["DamagedWorkbookError", "scan_xls"]

_SIGNATURE = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"
_LAST_SECTOR = 0xFFFFFFFA  # numbers from here on mark a chain's end, a FAT sector or a free one
_MINI_SECTOR = 64
_MINI_CUTOFF = 4096  # streams shorter than this live in the mini stream
_ENTRY = 128
_STREAMS = {"workbook", "book"}  # BIFF8 and BIFF5 (an Excel 97/95 file may hold both)
_MAX_STREAMS = 4
_CHUNK = 1 << 20
_MAX_STRINGS = MAX_CELLS
_EXTENT = f"at most {MAX_ROWS:,} rows, {MAX_COLUMNS:,} columns and {MAX_CELLS:,} cells from A1"

_BOF, _EOF, _CONTINUE = 0x0809, 0x000A, 0x003C
_BOUNDSHEET, _SST, _DIMENSIONS, _MERGECELLS = 0x0085, 0x00FC, 0x0200, 0x00E5
_FORMULA, _STRING, _BOOLERR, _LABEL, _RSTRING = 0x0006, 0x0207, 0x0205, 0x0204, 0x00D6
_MULRK, _MULBLANK = 0x00BD, 0x00BE
# The records the library makes a cell of (checked by trying every record type on it); blanks
# it leaves out, so they are held to the sheet's size but do not widen the block.
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


class DamagedWorkbookError(ValueError):
    """The compound file or its records cannot be what an XLS is; the reader reports it as a
    corrupt workbook."""


class _Stream:
    """A stream of the compound file, read at any offset from its sectors (or held, when small)."""

    def __init__(self, handle: BinaryIO, sectors: array[int], sector_size: int, size: int) -> None:
        self.handle = handle
        self.sectors = sectors
        self.sector_size = sector_size
        self.size = min(size, len(sectors) * sector_size)
        self.data: bytes | None = None

    @classmethod
    def held(cls, data: bytes) -> _Stream:
        stream = cls.__new__(cls)
        stream.data, stream.size = data, len(data)
        return stream

    def read(self, offset: int, length: int) -> bytes:
        length = max(0, min(length, self.size - offset))
        if self.data is not None or not length:
            return (self.data or b"")[offset : offset + length]
        parts = []
        first, last = offset // self.sector_size, (offset + length - 1) // self.sector_size
        index = first
        while index <= last:
            # Consecutive sectors are read at once: a stream written in one go is mostly one run.
            run = 1
            while index + run <= last and self.sectors[index + run] == self.sectors[index] + run:
                run += 1
            self.handle.seek((self.sectors[index] + 1) * self.sector_size)
            parts.append(self.handle.read(run * self.sector_size))
            index += run
        skip = offset - first * self.sector_size
        return b"".join(parts)[skip : skip + length]


class _Container:
    """The parts of an OLE2 compound file the workbook streams are read through."""

    def __init__(self, handle: BinaryIO, file_size: int) -> None:
        self.handle = handle
        header = handle.read(512)
        if len(header) < 512 or not header.startswith(_SIGNATURE):
            raise DamagedWorkbookError("the compound file's header is cut short")
        shift, mini_shift = struct.unpack_from("<HH", header, 0x1E)
        fat_count, self.directory, _, cutoff = struct.unpack_from("<IIII", header, 0x2C)
        self.mini_fat_start, _, difat_start, difat_count = struct.unpack_from("<IIII", header, 0x3C)
        # Any other sizes are no XLS, and another cutoff would place a stream where the
        # library, which takes the standard one, does not look for it.
        if shift not in (9, 12) or mini_shift != 6 or cutoff != _MINI_CUTOFF:
            raise DamagedWorkbookError("the compound file's header gives sizes no workbook has")
        self.sector_size = 1 << shift
        self.file_size = file_size
        self.count = max(0, -(-(file_size - self.sector_size) // self.sector_size))  # a cut last one counts
        needed = -(-self.count * 4 // self.sector_size)
        ids = list(struct.unpack_from("<109I", header, 0x4C))
        if needed > len(ids):
            ids += self._difat(difat_start, difat_count, needed)
        fat_ids = []
        for sector in ids[: min(fat_count, needed)]:
            if sector >= _LAST_SECTOR:
                break
            fat_ids.append(self._check(sector, "the FAT"))
        self.fat = array("I")
        for sector in fat_ids:
            self.fat.frombytes(self._sector(sector))
        if sys.byteorder == "big":
            self.fat.byteswap()
        del self.fat[self.count :]

    def _check(self, sector: int, what: str) -> int:
        if sector >= self.count:
            raise DamagedWorkbookError(f"{what} points to sector {sector}, past the end of the file")
        return sector

    def _sector(self, sector: int) -> bytes:
        self.handle.seek((sector + 1) * self.sector_size)
        return self.handle.read(self.sector_size).ljust(self.sector_size, b"\xff")

    def _difat(self, sector: int, count: int, needed: int) -> list[int]:
        ids: list[int] = []
        seen: set[int] = set()
        per = self.sector_size // 4 - 1
        while sector < _LAST_SECTOR and len(seen) < count and len(ids) < needed:
            if self._check(sector, "the FAT list") in seen:
                raise DamagedWorkbookError("the compound file's list of FAT sectors loops")
            seen.add(sector)
            *entries, sector = struct.unpack(f"<{per + 1}I", self._sector(sector))
            ids += entries
        return ids

    def chain(self, start: int, table: array[int], limit: int, what: str) -> array[int]:
        """The sectors of a chain from ``start``, at most ``limit`` of them; a chain that leaves
        the table or comes back to a sector it passed is damaged."""
        sectors = array("I")
        seen = bytearray(len(table))
        sector = start
        while sector < _LAST_SECTOR and len(sectors) < limit:
            if sector >= len(table):
                raise DamagedWorkbookError(f"{what} points to sector {sector}, past the end of the file")
            if seen[sector]:
                raise DamagedWorkbookError(f"{what} loops back to sector {sector}")
            seen[sector] = 1
            sectors.append(sector)
            sector = table[sector]
        return sectors

    def workbook_streams(self) -> list[_Stream]:
        """The first Workbook and Book streams of the directory.

        The library reads the first entry of either name, in any case, whatever its type and
        wherever it stands in the tree (tried on crafted files); the next few are scanned too,
        so that a reader choosing otherwise still reads a scanned stream.
        """
        directory = self.chain(self.directory, self.fat, self.count, "the directory")
        root = (_LAST_SECTOR, 0)
        found: list[tuple[int, int]] = []
        for index, sector in enumerate(directory):
            block = self._sector(sector)
            for at in range(0, self.sector_size, _ENTRY):
                entry = block[at : at + _ENTRY]
                length = struct.unpack_from("<H", entry, 64)[0]
                start, size = struct.unpack_from("<IQ", entry, 116)
                if index == at == 0:
                    root = (start, size)
                # By its length or up to its first NUL: a damaged length must not hide it.
                text = entry[:64].decode("utf-16-le", "replace").lower()
                names = {text[: max(0, min(length, 64) // 2 - 1)], text.partition("\x00")[0]}
                if names & _STREAMS and (start, size) not in found and len(found) < _MAX_STREAMS:
                    found.append((start, size))
        streams = []
        for start, size in found:
            if size > self.file_size:
                raise DamagedWorkbookError(
                    f"a workbook stream declares {size:,} bytes, more than the file holds"
                )
            if size >= _MINI_CUTOFF:
                sectors = self.chain(start, self.fat, -(-size // self.sector_size), "the workbook stream")
                streams.append(_Stream(self.handle, sectors, self.sector_size, size))
            else:
                streams.append(_Stream.held(self._mini(root, start, size)))
        return streams

    def _mini(self, root: tuple[int, int], start: int, size: int) -> bytes:
        """A small stream, gathered from the mini stream (the root entry's stream)."""
        mini_fat_sectors = self.chain(self.mini_fat_start, self.fat, self.count, "the mini FAT")
        mini_fat = array("I", b"".join(self._sector(s) for s in mini_fat_sectors))
        if sys.byteorder == "big":
            mini_fat.byteswap()
        root_start, root_size = root
        holder = self.chain(root_start, self.fat, -(-root_size // self.sector_size), "the mini stream")
        mini_stream = _Stream(self.handle, holder, self.sector_size, root_size)
        del mini_fat[-(-mini_stream.size // _MINI_SECTOR) :]
        sectors = self.chain(start, mini_fat, -(-size // _MINI_SECTOR), "the workbook stream")
        data = b"".join(mini_stream.read(s * _MINI_SECTOR, _MINI_SECTOR) for s in sectors)
        return data[:size]


def _records(stream: _Stream, offset: int, position: list[int]) -> Iterator[tuple[int, bytes]]:
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
    data: bytes, records: Iterator[tuple[int, bytes]], path: str | Path
) -> tuple[int, bytes] | None:
    """Count the shared strings and measure each; the record after them, already read."""
    number = 0

    def refuse(reason: str) -> IngestError:
        return IngestError(
            path,
            f"{reason} (shared string {number})",
            expected=f"at most {_MAX_STRINGS:,} shared strings of at most {MAX_TEXT:,} characters",
        )

    if len(data) >= 8 and struct.unpack_from("<I", data, 4)[0] > _MAX_STRINGS:
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

    def __init__(self, path: str | Path, name: str) -> None:
        self.path, self.name = path, name

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
            if len(data) < 6:
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
            if kind == _BOOLERR and len(data) >= 8 and data[7]:
                errors[(row, column)] = _ERRORS.get(data[6], "#VALUE!")
            elif kind == _FORMULA and len(data) >= 14 and data[6] == 2 and data[12:14] == b"\xff\xff":
                errors[(row, column)] = _ERRORS.get(data[8], "#VALUE!")
            elif kind in (_LABEL, _RSTRING) and int.from_bytes(data[6:8], "little") > MAX_TEXT:
                raise sheet.refuse("a cell's text is longer than a cell can hold", row, column, text)
        elif kind == _STRING:
            # A formula's text result, for the FORMULA cell just before it.
            if len(data) >= 2 and struct.unpack_from("<H", data)[0] > MAX_TEXT:
                raise sheet.refuse("a cell's text is longer than a cell can hold", row, column, text)
        elif kind in (_BLANK, _MULBLANK):
            if len(data) >= 4:
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


def _scan_stream(stream: _Stream, path: str | Path) -> dict[str, dict[tuple[int, int], str]]:
    position = [0]
    records = _records(stream, 0, position)
    sheets: list[tuple[str, int]] = []
    biff8 = True
    item = next(records, None)
    while item is not None:
        kind, data = item
        item = None
        if kind == _BOF and len(data) >= 2:
            biff8 = struct.unpack_from("<H", data)[0] == 0x0600
        elif kind == _BOUNDSHEET and len(data) >= 7:
            sheets.append((_sheet_name(data, biff8), struct.unpack_from("<I", data)[0]))
        elif kind == _SST:
            item = _check_strings(data, records, path)
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
        found = _scan_sheet(_records(stream, offset, position), _Sheet(path, name))
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
        At the cell (or shared string) over a limit.
    DamagedWorkbookError
        When the compound file or a record cannot be read safely, which the caller reports as
        a corrupt workbook.
    """
    with Path(path).open("rb") as handle:
        container = _Container(handle, os.fstat(handle.fileno()).st_size)
        errors: dict[str, dict[tuple[int, int], str]] = {}
        for stream in container.workbook_streams():
            for name, found in _scan_stream(stream, path).items():
                errors.setdefault(name, {}).update(found)
        return errors
