"""Writing small legacy XLS workbooks (BIFF8 records in an OLE2 compound file) for the reader
tests, including damaged and oversized ones no spreadsheet program would write.

A sheet is given as its cells, ``(row, column, value)`` with a 0-based row and column, so a
test can put a cell anywhere; :func:`biff_workbook` lays out the records and :func:`cfb`
wraps a stream in the container (the mini stream below 4,096 bytes, as Excel does).
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path

Cell = tuple[int, int, object]

SECTOR = 512
END = 0xFFFFFFFE
FREE = 0xFFFFFFFF
FAT_SECTOR = 0xFFFFFFFD
_MAX_DATA = 8224  # the most data bytes a BIFF8 record holds
_ERRORS = {"#NULL!": 0x00, "#DIV/0!": 0x07, "#VALUE!": 0x0F, "#REF!": 0x17, "#NAME?": 0x1D, "#N/A": 0x2A}


@dataclass(frozen=True)
class Error:
    """A cell showing a formula error; ``formula`` writes it as a FORMULA record's result."""

    code: str
    formula: bool = False


def record(kind: int, data: bytes) -> bytes:
    return struct.pack("<HH", kind, len(data)) + data


def _bof(kind: int) -> bytes:
    return record(0x0809, struct.pack("<HHHHII", 0x0600, kind, 0x0DBB, 0x07CC, 0, 0x06))


def unicode_string(text: str, length_bytes: int = 2) -> bytes:
    """An XLUnicodeString: compressed (one byte a character) when every character allows it."""
    size = struct.pack("<H" if length_bytes == 2 else "<B", len(text))
    if all(ord(c) < 256 for c in text):
        return size + b"\x00" + text.encode("latin-1")
    return size + b"\x01" + text.encode("utf-16-le")


def sst(strings: Sequence[str], total: int | None = None, unique: int | None = None) -> bytes:
    """The SST record and its CONTINUE records; a string cut by a record boundary goes on after a
    new flags byte, as the format has it."""
    head = struct.pack(
        "<II", len(strings) if total is None else total, len(strings) if unique is None else unique
    )
    records: list[bytes] = []
    current = bytearray(head)
    for text in strings:
        wide = any(ord(c) > 255 for c in text)
        width = 2 if wide else 1
        if len(current) + 3 + width > _MAX_DATA:
            records.append(bytes(current))
            current = bytearray()
        current += struct.pack("<HB", len(text), int(wide))
        rest = text
        while rest:
            room = (_MAX_DATA - len(current)) // width
            if room <= 0:
                records.append(bytes(current))
                current = bytearray([int(wide)])
                continue
            part, rest = rest[:room], rest[room:]
            current += part.encode("utf-16-le" if wide else "latin-1")
    records.append(bytes(current))
    return record(0x00FC, records[0]) + b"".join(record(0x003C, r) for r in records[1:])


def cell_record(row: int, column: int, value: object, strings: dict[str, int]) -> bytes:
    xf = 15
    if value is None:
        return record(0x0201, struct.pack("<HHH", row, column, xf))
    if isinstance(value, Error):
        code = _ERRORS[value.code]
        if value.formula:
            result = struct.pack("<BBBBHH", 2, 0, code, 0, 0, 0xFFFF)
            # The formula =#NAME? itself (PtgErr), enough for a reader that parses it.
            return record(
                0x0006,
                struct.pack("<HHH", row, column, xf)
                + result
                + struct.pack("<HIH", 0, 0, 2)
                + bytes([0x1C, code]),
            )
        return record(0x0205, struct.pack("<HHHBB", row, column, xf, code, 1))
    if isinstance(value, bool):
        return record(0x0205, struct.pack("<HHHBB", row, column, xf, int(value), 0))
    if isinstance(value, int | float):
        return record(0x0203, struct.pack("<HHHd", row, column, xf, float(value)))
    if isinstance(value, str):
        index = strings.setdefault(value, len(strings))
        return record(0x00FD, struct.pack("<HHHI", row, column, xf, index))
    raise TypeError(value)


def biff_workbook(
    sheets: Sequence[tuple[str, Iterable[Cell]]],
    *,
    dimensions: tuple[int, int, int, int] | None = None,
    extra_globals: bytes = b"",
    strings: Sequence[str] = (),
    sst_record: bytes | None = None,
) -> bytes:
    """The Workbook stream: globals (with one SST of every text cell), then one substream a sheet.

    ``dimensions`` (first row, last row + 1, first column, last column + 1) replaces what each
    sheet's DIMENSIONS record would say of its cells; ``sst_record`` replaces the SST.
    """
    table: dict[str, int] = {s: i for i, s in enumerate(strings)}
    bodies = []
    for _, cells in sheets:
        rows, columns, records = [0], [0], []
        for row, column, value in cells:
            records.append(cell_record(row, column, value, table))
            rows.append(row + 1)
            columns.append(column + 1)
        extent = dimensions or (0, max(rows), 0, min(max(columns), 0xFFFF))
        body = _bof(0x0010) + record(0x0200, struct.pack("<IIHHH", *extent, 0))
        bodies.append(body + b"".join(records) + record(0x000A, b""))
    names = [unicode_string(name, 1) for name, _ in sheets]
    shared = sst(list(table)) if sst_record is None else sst_record
    fixed = _bof(0x0005) + record(0x0042, struct.pack("<H", 1200)) + extra_globals
    size = len(fixed) + sum(4 + 6 + len(n) for n in names) + len(shared) + 4
    globals_, offset = bytearray(fixed), size
    for name, body in zip(names, bodies, strict=True):
        globals_ += record(0x0085, struct.pack("<IBB", offset, 0, 0) + name)
        offset += len(body)
    globals_ += shared + record(0x000A, b"")
    return bytes(globals_) + b"".join(bodies)


def _entry(name: str, kind: int, start: int, size: int, child: int = FREE) -> bytes:
    encoded = (name + "\x00").encode("utf-16-le") if name else b""
    return (
        encoded.ljust(64, b"\x00")
        + struct.pack("<HBB", len(encoded), kind, 1)
        + struct.pack("<III", FREE, FREE, child)
        + bytes(16 + 4 + 16)
        + struct.pack("<IQ", start, size)
    )


def cfb(stream: bytes, name: str = "Workbook", sector: int = SECTOR) -> bytes:
    """An OLE2 compound file holding one stream: version 3 with 512-byte sectors, or version 4
    with 4,096-byte ones.

    Sectors: the FAT from sector 0, then the directory, then (for a small stream) the mini FAT
    and the mini stream, then the stream's own sectors.
    """
    small = len(stream) < 4096

    def sectors(size: int) -> int:
        return -(-size // sector)

    mini = stream.ljust(-(-len(stream) // 64) * 64, b"\x00") if small else b""
    mini_fat = b"".join(
        struct.pack("<I", i + 1 if i + 1 < len(mini) // 64 else END) for i in range(len(mini) // 64)
    )
    chains = [1, sectors(len(mini_fat)), sectors(len(mini)), 0 if small else sectors(len(stream))]
    fat_sectors = 1
    while fat_sectors * (sector // 4) < fat_sectors + sum(chains):
        fat_sectors += 1
    assert fat_sectors <= 109, "the writer keeps the FAT in the header's list"
    fat = [FAT_SECTOR] * fat_sectors
    starts = []
    for count in chains:
        starts.append(len(fat) if count else END)
        fat += [len(fat) + i + 1 for i in range(count - 1)] + ([END] if count else [])
    fat += [FREE] * (fat_sectors * (sector // 4) - len(fat))
    directory, mini_fat_start, mini_start, stream_start = starts
    root = _entry("Root Entry", 5, mini_start if small else END, len(mini), child=1)
    book = _entry(name, 2, 0 if small else stream_start, len(stream))
    version, shift = (3, 9) if sector == 512 else (4, 12)
    header = (
        bytes.fromhex("d0cf11e0a1b11ae1")
        + bytes(16)
        + struct.pack("<HHHHH", 0x3E, version, 0xFFFE, shift, 6)
        + bytes(6)
        + struct.pack(
            "<IIIIIIIII",
            int(version == 4),
            fat_sectors,
            directory,
            0,
            4096,
            mini_fat_start,
            chains[1],
            END,
            0,
        )
        + struct.pack(f"<{fat_sectors}I", *range(fat_sectors))
        + b"\xff" * 4 * (109 - fat_sectors)
    )
    body = (
        struct.pack(f"<{len(fat)}I", *fat)
        + (root + book).ljust(sector, b"\x00")
        + mini_fat.ljust(chains[1] * sector, b"\xff")
        + mini.ljust(chains[2] * sector, b"\x00")
        + (b"" if small else stream.ljust(chains[3] * sector, b"\x00"))
    )
    return header.ljust(sector, b"\x00") + body


def write_xls(path: Path, sheets: Sequence[tuple[str, Iterable[Cell]]], **options: object) -> Path:
    path.write_bytes(cfb(biff_workbook(sheets, **options)))  # type: ignore[arg-type]
    return path


def grid(rows: Sequence[Sequence[object]]) -> list[Cell]:
    """Cells of rows from A1; ``None`` leaves a cell out."""
    return [(r, c, v) for r, row in enumerate(rows) for c, v in enumerate(row) if v is not None]
