"""An OLE2 compound file, the container of a legacy XLS, read without trusting it.

A compound file is a small file system: sectors of 512 or 4,096 bytes, a FAT chaining them, a
directory of named streams, and a mini stream of 64-byte sectors holding the streams under
4,096 bytes. A damaged or hostile one points a chain past the file's end or back on itself, or
declares more than it holds; the workbook library follows a looping directory forever. Here
every sector number, chain and count is checked against the file's size before it is used,
the FAT is the only table held whole (4 bytes a sector of the file), and a stream is read in
pieces at any offset, so reading one costs what is read of it.
"""

from __future__ import annotations

import struct
import sys
from array import array
from typing import BinaryIO

__all__ = ["CompoundFile", "DamagedWorkbookError", "Stream"]

_SIGNATURE = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"
_LAST_SECTOR = 0xFFFFFFFA  # numbers from here on mark a chain's end, a FAT sector or a free one
_MINI_SECTOR = 64
_MINI_CUTOFF = 4096  # streams shorter than this live in the mini stream
_ENTRY = 128


class DamagedWorkbookError(ValueError):
    """The compound file or its records cannot be what an XLS is; the reader reports it as a
    corrupt workbook."""


class Stream:
    """A stream of the compound file, read at any offset from its sectors (or held, when small)."""

    def __init__(self, handle: BinaryIO, sectors: array[int], sector_size: int, size: int) -> None:
        self.handle = handle
        self.sectors = sectors
        self.sector_size = sector_size
        self.size = min(size, len(sectors) * sector_size)
        self.data: bytes | None = None

    @classmethod
    def held(cls, data: bytes) -> Stream:
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


class CompoundFile:
    """The parts of a compound file its streams are read through."""

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

    def streams(self, names: frozenset[str], most: int) -> list[Stream]:
        """The first ``most`` streams named one of ``names`` (lower case), in directory order.

        A reader may take the first entry of a name in any case, whatever its type and wherever
        it stands in the tree (the workbook library does: tried on crafted files), so that is
        how they are found; a reader choosing otherwise still finds one of the first few.
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
                found_names = {text[: max(0, min(length, 64) // 2 - 1)], text.partition("\x00")[0]}
                if found_names & names and (start, size) not in found and len(found) < most:
                    found.append((start, size))
        streams = []
        for start, size in found:
            if size > self.file_size:
                raise DamagedWorkbookError(f"a stream declares {size:,} bytes, more than the file holds")
            if size >= _MINI_CUTOFF:
                sectors = self.chain(start, self.fat, -(-size // self.sector_size), "a stream")
                streams.append(Stream(self.handle, sectors, self.sector_size, size))
            else:
                streams.append(Stream.held(self._mini(root, start, size)))
        return streams

    def _mini(self, root: tuple[int, int], start: int, size: int) -> bytes:
        """A small stream, gathered from the mini stream (the root entry's stream)."""
        mini_fat_sectors = self.chain(self.mini_fat_start, self.fat, self.count, "the mini FAT")
        mini_fat = array("I", b"".join(self._sector(s) for s in mini_fat_sectors))
        if sys.byteorder == "big":
            mini_fat.byteswap()
        root_start, root_size = root
        holder = self.chain(root_start, self.fat, -(-root_size // self.sector_size), "the mini stream")
        mini_stream = Stream(self.handle, holder, self.sector_size, root_size)
        del mini_fat[-(-mini_stream.size // _MINI_SECTOR) :]
        sectors = self.chain(start, mini_fat, -(-size // _MINI_SECTOR), "a stream")
        data = b"".join(mini_stream.read(s * _MINI_SECTOR, _MINI_SECTOR) for s in sectors)
        return data[:size]
