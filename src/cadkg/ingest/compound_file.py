"""An OLE2 compound file, the container of a legacy XLS, read through olefile without trusting it.

A compound file is a small file system: sectors of 512 or 4,096 bytes, a FAT chaining them, a
directory of named streams, and a mini stream of 64-byte sectors holding the streams under
4,096 bytes. olefile (https://olefile.readthedocs.io) reads the header, the FAT, the directory
and the streams. A damaged or hostile file points a chain past the file's end or back on
itself, or declares more than it holds, and olefile trusts it further than cadkg may, so what
it does not check is checked here, each before olefile acts on it:

- The header's sector sizes and mini-stream cutoff must be the standard ones: olefile notes
  others and goes on.
- The FAT may describe at most :data:`MAX_SECTORS` sectors: olefile joins the FAT one sector at
  a time, copying it each time, in time growing with its square (a 4 GiB file of 512-byte
  sectors, its FAT listed in full: 570 s).
- The directory may hold at most :data:`MAX_ENTRIES` entries: olefile builds its tree in time
  growing with their square (13,000 entries: 1 s).
- Every chain olefile is to follow is walked first in olefile's FAT (or mini FAT): every sector
  in the file, none passed twice. olefile follows a loop for as many sectors as the stream
  declares, and its errors do not say where.
- olefile reads a stream whole into memory (``OleStream`` is a ``BytesIO`` of it): a stream
  and the mini stream may declare no more than the file holds and :data:`MAX_STREAM` bytes.
- A stream is found as the workbook library finds it, the first entries of its name anywhere
  in the directory: olefile finds one by its path through the directory's tree. So the
  directory olefile holds is searched entry by entry here, and the stream read through
  olefile's reader of a stream at its first sector (``_open``, what ``openstream`` calls once
  it has found the entry); hence the pin on olefile 0.47.x, where that and the order in which
  ``open`` loads the FAT and the directory were read.

olefile is imported when a file is read, not with cadkg: most builds read no XLS.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence
from functools import cache
from pathlib import Path
from typing import Any, BinaryIO

from cadkg.errors import IngestError

__all__ = ["MAX_ENTRIES", "MAX_SECTORS", "MAX_STREAM", "CompoundFile", "DamagedWorkbookError", "Stream"]

_SIGNATURE = b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1"
_LAST_SECTOR = 0xFFFFFFFA  # numbers from here on mark a chain's end, a FAT sector or a free one
_MINI_SECTOR = 64
_MINI_CUTOFF = 4096  # streams shorter than this live in the mini stream
_ENTRY = 128
_SOURCE = "cadkg/ingest/compound_file.py"

# The bytes of one stream held in memory: what olefile reads of a stream at once. As the
# largest text export (cadkg.ingest.text.MAX_TEXT_FILE), it must fit the read limit of
# cadkg.limited (1 GiB): olefile holds about 2.6 times the stream while it joins its sectors
# (measured: a peak of 92 MB for an 18 MiB stream, 38 MB of it the process), the workbook
# library its own copy of the file after the scan.
MAX_STREAM = 256 << 20
# Directory entries: an XLS has a few (its Workbook, summaries, a VBA project, one storage of
# three or four for each embedded object); olefile takes 0.4 s over 8,192.
MAX_ENTRIES = 8192
# Sectors the FAT may describe: 1 GiB of 512-byte sectors (olefile loads that FAT in 2.5 s, and
# the read limit of cadkg.limited is 1 GiB), 8 GiB of 4,096-byte ones.
MAX_SECTORS = 1 << 21


class DamagedWorkbookError(ValueError):
    """The compound file or its records cannot be what an XLS is; the reader reports it as a
    corrupt workbook."""


class Stream:
    """A stream of the compound file, held whole as olefile reads it (at most :data:`MAX_STREAM`
    bytes)."""

    def __init__(self, data: bytes) -> None:
        self.data = data
        self.size = len(data)

    def read(self, offset: int, length: int) -> bytes:
        return self.data[offset : offset + max(0, length)]


def _chain(start: int, table: Sequence[int], length: int, limit: int, what: str) -> int:
    """How many sectors the chain from ``start`` has in the first ``length`` entries of
    ``table``, at most ``limit``; a chain that leaves them or comes back to a sector it passed
    is damaged. olefile follows a chain without either check."""
    seen = bytearray(length)
    sector, count = start, 0
    while sector < _LAST_SECTOR and count < limit:
        if sector >= length:
            raise DamagedWorkbookError(f"{what} points to sector {sector}, past the end of the file")
        if seen[sector]:
            raise DamagedWorkbookError(f"{what} loops back to sector {sector}")
        seen[sector] = 1
        count += 1
        sector = table[sector]
    return count


def _check_header(path: str | Path, header: bytes, file_size: int) -> None:
    """The header, refused before olefile reads it."""
    if len(header) < 512 or not header.startswith(_SIGNATURE):
        raise DamagedWorkbookError("the compound file's header is cut short")
    shift, mini_shift = struct.unpack_from("<HH", header, 0x1E)
    fat_count, cutoff = struct.unpack_from("<I", header, 0x2C)[0], struct.unpack_from("<I", header, 0x38)[0]
    # Any other sizes are no XLS, and another cutoff would place a stream where the library,
    # which takes the standard one, does not look for it. (olefile notes them and goes on, or
    # fails on a shift of thousands of bits.)
    if shift not in (9, 12) or mini_shift != 6 or cutoff != _MINI_CUTOFF:
        raise DamagedWorkbookError("the compound file's header gives sizes no workbook has")
    sector_size = 1 << shift
    count = max(0, -(-(file_size - sector_size) // sector_size))  # a cut last one counts
    for sector in struct.unpack_from("<109I", header, 0x4C)[:fat_count]:
        if sector >= _LAST_SECTOR:
            break
        if sector >= count:
            raise DamagedWorkbookError(f"the FAT points to sector {sector}, past the end of the file")
        if (sector + 2) * sector_size > file_size:  # olefile: "incomplete OLE sector"
            raise DamagedWorkbookError(f"the FAT's sector {sector} is cut short by the end of the file")
    # olefile reads the 109 FAT sectors the header lists whatever their count; past them, as
    # many as the count says, through the DIFAT.
    described = fat_count * (sector_size // 4)
    if struct.unpack_from("<I", header, 0x48)[0] and described > MAX_SECTORS:
        raise IngestError(
            path,
            f"the compound file's FAT describes {described:,} sectors, more than cadkg reads of a workbook",
            expected=f"at most {MAX_SECTORS:,} sectors (MAX_SECTORS in {_SOURCE})",
        )


@cache
def _checked_olefile() -> type[Any]:
    """olefile's reader of a compound file, with cadkg's check of the directory before it
    builds the directory's tree (``open`` loads the FAT and the directory in one call)."""
    import olefile  # type: ignore[import-untyped]  # deferred: most builds read no XLS

    class Checked(olefile.OleFileIO):  # type: ignore[misc]  # olefile has no type stubs
        path: str | Path = ""

        def loadfat(self, header: bytes) -> None:
            # A FAT of at most the header's 109 sectors needs no DIFAT: a count of DIFAT sectors
            # is then ignored, as the workbook library ignores one that starts nowhere (olefile
            # would refuse the file).
            if self.num_fat_sectors <= 109:
                self.num_difat_sectors = 0
            super().loadfat(header)

        def loaddirectory(self, sect: int) -> None:
            most = MAX_ENTRIES * _ENTRY // self.sector_size
            if _chain(sect, self.fat, len(self.fat), most + 1, "the directory") > most:
                raise IngestError(
                    self.path,
                    "the compound file's directory holds more entries than cadkg reads of a workbook",
                    expected=f"at most {MAX_ENTRIES:,} entries (MAX_ENTRIES in {_SOURCE})",
                )
            super().loaddirectory(sect)

    return Checked


def _olefile_call(call: Any, *args: object) -> Any:
    """``call(*args)``, olefile's failures on a damaged file (its ``OleFileError``, and the
    ``struct.error``, ``IndexError`` or ``RecursionError`` of a file it did not expect) as one
    damaged-workbook error."""
    try:
        return call(*args)
    except (DamagedWorkbookError, IngestError, MemoryError):
        raise
    except RecursionError:
        # olefile walks the directory's tree recursively, one level a sibling.
        raise DamagedWorkbookError("the compound file's directory tree is nested too deep") from None
    except Exception as err:
        found = str(err) if isinstance(err, OSError) else f"{type(err).__name__}: {err}"
        raise DamagedWorkbookError(f"the compound file cannot be read: {found}") from None


class CompoundFile:
    """The streams of a compound file: olefile's reading of them, checked."""

    def __init__(self, path: str | Path, handle: BinaryIO, file_size: int) -> None:
        self.path = path
        self.file_size = file_size
        _check_header(path, handle.read(512), file_size)
        handle.seek(0)
        self.ole = _checked_olefile()()
        self.ole.path = path
        _olefile_call(self.ole.open, handle)

    def _held(self, size: int, what: str) -> None:
        if size > self.file_size:
            raise DamagedWorkbookError(f"{what} declares {size:,} bytes, more than the file holds")
        if size > MAX_STREAM:
            raise IngestError(
                self.path,
                f"{what} declares {size / (1 << 20):,.0f} MiB, more than cadkg holds of a workbook",
                expected=f"at most {MAX_STREAM >> 20} MiB a stream (MAX_STREAM in {_SOURCE})",
            )

    def streams(self, names: frozenset[str], most: int) -> list[Stream]:
        """The first ``most`` streams named one of ``names`` (lower case), in directory order.

        A reader may take the first entry of a name in any case, whatever its type and wherever
        it stands in the tree (the workbook library does: tried on crafted files), so that is
        how they are found; a reader choosing otherwise still finds one of the first few.
        """
        fat, sector_size = self.ole.fat, self.ole.sector_size
        # A sector cut short at the file's end reads as 0xFF bytes, as the library reads it.
        directory = self.ole.directory_fp.getvalue()
        directory = directory.ljust(-(-len(directory) // sector_size) * sector_size, b"\xff")
        root = (_LAST_SECTOR, 0)
        found: list[tuple[int, int]] = []
        for at in range(0, len(directory) - _ENTRY + 1, _ENTRY):
            entry = directory[at : at + _ENTRY]
            length = struct.unpack_from("<H", entry, 64)[0]
            start, size = struct.unpack_from("<IQ", entry, 116)
            if at == 0:
                root = (start, size)
            # By its length or up to its first NUL: a damaged length must not hide it.
            text = entry[:64].decode("utf-16-le", "replace").lower()
            found_names = {text[: max(0, min(length, 64) // 2 - 1)], text.partition("\x00")[0]}
            if found_names & names and (start, size) not in found and len(found) < most:
                found.append((start, size))
        streams = []
        for start, size in found:
            self._held(size, "a stream")
            if size >= _MINI_CUTOFF:
                _chain(start, fat, len(fat), -(-size // sector_size), "a stream")
            else:
                self._mini_chain(root, start, size)
            streams.append(Stream(_olefile_call(self.ole._open, start, size).getvalue()))
        return streams

    def _mini_chain(self, root: tuple[int, int], start: int, size: int) -> None:
        """Check the chains olefile follows to read a small stream: the mini FAT's, the mini
        stream's (the root entry's stream, which olefile reads whole) and the stream's own."""
        fat, sector_size = self.ole.fat, self.ole.sector_size
        _chain(self.ole.first_mini_fat_sector, fat, len(fat), len(fat) + 1, "the mini FAT")
        root_start, root_size = root
        held = _chain(root_start, fat, len(fat), -(-root_size // sector_size), "the mini stream")
        # What olefile reads of it: the chain stops it short of a size the root entry overstates.
        self._held(min(self.ole.root.size, held * sector_size), "the mini stream")
        if self.ole.minifat is None:
            _olefile_call(self.ole.loadminifat)
        # The mini sectors the mini stream holds, though its root entry may declare more.
        length = min(len(self.ole.minifat), -(-min(root_size, held * sector_size) // _MINI_SECTOR))
        _chain(start, self.ole.minifat, length, -(-size // _MINI_SECTOR), "a stream")
