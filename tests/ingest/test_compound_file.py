"""The OLE2 container of an XLS, read through olefile: a damaged or oversized one is one located
line, never an olefile exception, and refused before olefile reads more than the limits allow."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.ingest import compound_file
from cadkg.ingest.sheet import read_workbook
from tests.ingest.biff import biff_workbook, cfb
from tests.ingest.workbooks import read_in_child

SECTOR = 512
END = 0xFFFFFFFE


def _large() -> bytes:
    """A workbook in its own sectors: the FAT in sector 0, the directory in 1, the stream from 2."""
    return cfb(biff_workbook([("S", [(r, 0, float(r)) for r in range(400)])]))


def _small() -> bytes:
    """A workbook in the mini stream: the FAT in sector 0, the directory in 1, the mini FAT in
    2, the mini stream from 3."""
    stream = biff_workbook([("S", [(r, 0, float(r)) for r in range(150)])])
    assert 2 * SECTOR < len(stream) < 4096
    data = cfb(stream)
    assert struct.unpack_from("<I", data, 0x3C)[0] == 2
    return data


def _chain(data: bytes, start: int) -> list[int]:
    fat = struct.unpack_from(f"<{SECTOR // 4}I", data, SECTOR)
    sectors = []
    while start < len(fat):
        sectors.append(start)
        start = fat[start]
    return sectors


def _set(data: bytes, at: int, value: int) -> bytes:
    damaged = bytearray(data)
    struct.pack_into("<I", damaged, at, value)
    return bytes(damaged)


def _refused(tmp_path: Path, data: bytes) -> IngestError:
    path = tmp_path / "damaged.xls"
    path.write_bytes(data)
    with pytest.raises(IngestError) as info:
        read_workbook(path)
    error = info.value
    assert "\n" not in str(error)
    assert error.path == str(path)
    assert str(error).startswith(f"{path}: ")
    return error


def _truncations() -> list[tuple[int, str]]:
    size = len(_large())
    cut = [
        (8, "the compound file's header is cut short"),
        (100, "the compound file's header is cut short"),
        (511, "the compound file's header is cut short"),
        (SECTOR + 100, "the FAT's sector 0 is cut short by the end of the file"),
        (2 * SECTOR - 1, "the FAT's sector 0 is cut short by the end of the file"),
        # Not even the root entry: olefile's own message, as one line.
        (2 * SECTOR + 100, "the compound file cannot be read: OLE directory index out of range"),
    ]
    # Anywhere in the stream: it declares more than the file holds, or its chain leaves it.
    cut += [(at, "a stream ") for at in range(3 * SECTOR, size, size // 7)]
    return cut


@pytest.mark.parametrize(("length", "reason"), _truncations())
def test_a_container_cut_short_anywhere_is_one_line(tmp_path: Path, length: int, reason: str) -> None:
    error = _refused(tmp_path, _large()[:length])
    assert error.reason.startswith(f"corrupt workbook ({reason}")


def _bad_chains() -> list[tuple[str, bytes, str]]:
    large, small = _large(), _small()
    stream = _chain(large, 2)
    cases = []
    for index, sector in enumerate(stream[:-1]):
        # Each link of the stream's chain back onto its first sector, and out of the file.
        cases.append(
            (f"loop-{index}", _set(large, SECTOR + 4 * sector, 2), "a stream loops back to sector 2")
        )
        past = 1000 + index
        cases.append(
            (
                f"past-{index}",
                _set(large, SECTOR + 4 * sector, past),
                f"a stream points to sector {past}, past the end of the file",
            )
        )
    cases.append(("directory-past", _set(large, SECTOR + 4, 999), "the directory points to sector 999"))
    cases.append(("directory-start", _set(large, 0x30, 999), "the directory points to sector 999"))
    # The chains olefile follows for a stream in the mini stream: the mini FAT's, the mini
    # stream's, and the stream's own in the mini FAT.
    cases.append(("mini-fat-loop", _set(small, SECTOR + 4 * 2, 2), "the mini FAT loops back to sector 2"))
    cases.append(("mini-fat-start", _set(small, 0x3C, 700), "the mini FAT points to sector 700"))
    mini = _chain(small, 3)
    assert len(mini) > 1
    mini_fat = 3 * SECTOR  # sector 2
    cases.append(
        ("mini-stream-loop", _set(small, SECTOR + 4 * mini[1], 3), "the mini stream loops back to sector 3")
    )
    cases.append(("mini-chain-loop", _set(small, mini_fat + 4 * 1, 0), "a stream loops back to sector 0"))
    cases.append(("mini-chain-past", _set(small, mini_fat + 4 * 1, 5000), "a stream points to sector 5000"))
    return cases


@pytest.mark.parametrize(
    ("data", "reason"), [c[1:] for c in _bad_chains()], ids=[c[0] for c in _bad_chains()]
)
def test_bad_sector_chains_are_one_line(tmp_path: Path, data: bytes, reason: str) -> None:
    assert _refused(tmp_path, data).reason.startswith(f"corrupt workbook ({reason}")


def _workbook_entry(data: bytes) -> int:
    at = data.find("Workbook".encode("utf-16-le"))
    assert at % 128 == 0
    return at


def test_a_stream_past_the_limit_is_refused_before_it_is_read(tmp_path: Path) -> None:
    # A sparse file larger than the limit, its Workbook stream declaring just over it: olefile
    # would read it whole into memory.
    data = bytearray(_large())
    declared = compound_file.MAX_STREAM + 1
    struct.pack_into("<Q", data, _workbook_entry(bytes(data)) + 120, declared)
    path = tmp_path / "large.xls"
    with path.open("wb") as handle:
        handle.write(data)
        handle.truncate(declared + (1 << 20))
    message, seconds, megabytes = read_in_child(path, timeout=60)
    assert message == (
        f"{path}: a stream declares 256 MiB, more than cadkg holds of a workbook"
        " (expected at most 256 MiB a stream (MAX_STREAM in cadkg/ingest/compound_file.py))"
    )
    assert megabytes < 200, f"peak RSS {megabytes} MB"
    assert seconds < 5


@pytest.mark.parametrize("fat_sectors", [16_385, 100_000, 0xFFFFFFFF])
def test_a_fat_past_the_limit_is_refused_before_olefile_loads_it(tmp_path: Path, fat_sectors: int) -> None:
    # olefile's time to load a FAT through the DIFAT grows with its square (minutes at 4 GiB).
    data = _set(_set(_large(), 0x2C, fat_sectors), 0x48, 1)
    error = _refused(tmp_path, data)
    described = f"{fat_sectors * 128:,} sectors"
    assert (
        error.reason == f"the compound file's FAT describes {described}, more than cadkg reads of a workbook"
    )
    assert error.expected == "at most 2,097,152 sectors (MAX_SECTORS in cadkg/ingest/compound_file.py)"


def test_a_directory_past_the_limit_is_refused_before_olefile_builds_its_tree(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # olefile's time to build the tree grows with the square of the entries; here the directory
    # runs on through the stream's sectors, over a limit of one sector of entries.
    monkeypatch.setattr(compound_file, "MAX_ENTRIES", SECTOR // 128)
    error = _refused(tmp_path, _set(_large(), SECTOR + 4, 2))
    assert error.reason == "the compound file's directory holds more entries than cadkg reads of a workbook"
    assert error.expected == "at most 4 entries (MAX_ENTRIES in cadkg/ingest/compound_file.py)"


@pytest.mark.parametrize("count", [1, 2, 0xFFFFFFFE])
def test_a_difat_count_a_small_fat_has_no_use_for_is_ignored(tmp_path: Path, count: int) -> None:
    # As the workbook library ignores it, its DIFAT starting nowhere; olefile would refuse it.
    path = tmp_path / "book.xls"
    path.write_bytes(_set(_set(_large(), 0x44, END), 0x48, count))
    assert [s.name for s in read_workbook(path).sheets] == ["S"]
