"""Legacy XLS workbooks: read like the other formats, and refused (at the cell, in bounded memory
and time) when their records or their compound file break a sheet's limits."""

from __future__ import annotations

import struct
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.ingest.sheet import CellError, read_workbook
from tests.ingest.biff import Error, biff_workbook, cfb, grid, record, sst, write_xls
from tests.ingest.workbooks import read_in_child, write_xlsx

ROWS: list[list[object]] = [
    ["Block", "Position", "Note"],
    [None],
    ["X1600", 2.5, "è€ ünï — 日本"],
    [None, None, None, "far"],
    ["=-X1", 0.125, True],
]


def _values(path: Path) -> list[tuple[str, list[tuple[int, tuple[object, ...]]]]]:
    return [(s.name, [(r.number, r.cells) for r in s.rows]) for s in read_workbook(path).sheets]


@pytest.mark.parametrize(
    ("rows", "sector"), [(0, 512), (400, 512), (0, 4096)], ids=["mini-stream", "own-sectors", "version-4"]
)
def test_xls_reads_as_the_same_workbook_in_xlsx_does(tmp_path: Path, rows: int, sector: int) -> None:
    # 400 more rows put the Workbook stream past 4,096 bytes, out of the mini stream.
    more = [[f"W{n}", n + 0.5] for n in range(rows)]
    sheets = [("Schema", [*ROWS, *more]), ("Other sheet", [[None, "z"]])]
    stream = biff_workbook([(name, grid(r)) for name, r in sheets])
    assert (len(stream) >= 4096) == bool(rows)
    xls = tmp_path / "book.xls"
    xls.write_bytes(cfb(stream, sector=sector))
    assert _values(xls) == _values(write_xlsx(tmp_path / "book.xlsx", sheets))


def test_shared_strings_over_continue_records_read(tmp_path: Path) -> None:
    # Over 8,224 bytes of strings: the SST goes on in CONTINUE records, some strings cut
    # in the middle of their characters (compressed and UTF-16 alike).
    texts = [f"{'Ω' if n % 3 else 'w'}-{n}-" + "x" * (n % 40) for n in range(1500)]
    path = write_xls(tmp_path / "strings.xls", [("S", [(n, 0, t) for n, t in enumerate(texts)])])
    assert len(sst(texts)) > 2 * 8224
    (_, rows), *_ = _values(path)
    assert [cells[0] for _, cells in rows] == texts


def test_xls_formula_errors_read_as_errors(tmp_path: Path) -> None:
    cells = [(0, 0, "h"), (1, 1, Error("#NAME?")), (1, 2, Error("#REF!", formula=True)), (2, 0, 1.5)]
    (_, rows), *_ = _values(write_xls(tmp_path / "errors.xls", [("S", cells)]))
    assert rows[1] == (2, (None, CellError("#NAME?"), CellError("#REF!")))
    assert rows[2] == (3, (1.5,))


def _refused(path: Path) -> IngestError:
    with pytest.raises(IngestError) as info:
        read_workbook(path)
    assert "\n" not in str(info.value)
    assert info.value.path == str(path)
    return info.value


_CELLS = "the sheet's cells span more than cadkg reads of a sheet"
_RANGE = "the sheet declares a range larger than cadkg reads of a sheet"
_BEYOND = "a cell lies beyond the last row or column a sheet can have"
_INVERTED = "the sheet declares a range beyond the last row or column a sheet can have, or inverted"


@pytest.mark.parametrize(
    ("cells", "dimensions", "cell", "reason"),
    [
        # A number in column IV on every row, under a declared range of one cell: the library
        # would build 65,536 x 256 cells (1 GB measured).
        ([(0, 0, "a"), *((r, 255, 1.0) for r in range(1, 65536))], (0, 1, 0, 1), "S!IV8193", _CELLS),
        # Two cells, A1 and IV65536, and the range they declare.
        ([(0, 0, "a"), (65535, 255, 1.0)], None, "S!IV65536", _RANGE),
        # A column the format does not have, which the library takes (it asks for 171 GB).
        ([(0, 0, "a"), (65535, 65535, 1.0)], (0, 1, 0, 1), "S!XFE65536", _BEYOND),
        # A declared range only: the library reserves it (40 bytes a cell) and aborts on 40 GB.
        ([(0, 0, "a")], (0, 65536, 0, 16384), "S!XFD65536", _RANGE),
        # Rows 6 to 2: the library's count of them wraps round to 4 billion (it asks for 515 GB).
        ([(0, 0, "a")], (5, 2, 0, 3), "S!C2", _INVERTED),
    ],
    ids=["column-IV", "corners", "column-65536", "declared-range", "inverted-range"],
)
def test_xls_bombs_are_refused_in_bounded_memory(
    tmp_path: Path,
    cells: list[tuple[int, int, object]],
    dimensions: tuple[int, ...] | None,
    cell: str,
    reason: str,
) -> None:
    path = write_xls(tmp_path / "bomb.xls", [("S", cells)], dimensions=dimensions)
    assert path.stat().st_size < 1_300_000
    message, seconds, megabytes = read_in_child(path, timeout=60)
    assert message.startswith(f"{path}:{cell}: {reason}")
    assert megabytes < 300, f"peak RSS {megabytes} MB"
    assert seconds < 5  # measured 0.02 s at most; the machine may be loaded


def _with_sheet_records(tmp_path: Path, records: bytes) -> Path:
    """A one-sheet workbook (``S``, A1 holding ``a``) with ``records`` before the sheet's end."""
    stream = biff_workbook([("S", [(0, 0, "a")])])
    end = stream.rfind(record(0x000A, b""))
    path = tmp_path / "book.xls"
    path.write_bytes(cfb(stream[:end] + records + stream[end:]))
    return path


def test_oversized_cell_text_is_refused_at_its_cell(tmp_path: Path) -> None:
    label = record(0x0204, struct.pack("<HHHHB", 3, 1, 15, 40_000, 0) + b"x" * 8000)
    error = _refused(_with_sheet_records(tmp_path, label))
    assert error.cell == "S!B4"
    assert error.reason == "a cell's text is longer than a cell can hold"


@pytest.mark.parametrize(
    ("table", "reason"),
    [
        (sst(["a"], unique=0xFFFFFFFF), "the workbook declares more shared strings than cadkg reads"),
        (sst(["a", "b" * 40_000]), "a cell's text is longer than a cell can hold (shared string 2)"),
    ],
    ids=["declared-count", "long-string"],
)
def test_shared_strings_over_the_limits_are_refused(tmp_path: Path, table: bytes, reason: str) -> None:
    error = _refused(write_xls(tmp_path / "strings.xls", [("S", [(0, 0, "a")])], sst_record=table))
    assert error.reason.startswith(reason)
    assert error.cell is None


def test_merged_cells_cut_short_are_a_corrupt_workbook(tmp_path: Path) -> None:
    # The library would index past the record and panic.
    error = _refused(_with_sheet_records(tmp_path, record(0x00E5, struct.pack("<H", 3))))
    assert error.reason == "corrupt workbook (a list of merged cells of sheet S is cut short)"


@pytest.mark.parametrize(
    ("kind", "data", "reason"),
    [
        (0x0042, b"\xb0", "a CODEPAGE record of 1 bytes at 26 is cut short"),
        (0x0018, b"\x00\x00", "a NAME record of 2 bytes at 26 is cut short"),
        (0x0017, b"\x01\x00\x00\x00", "an EXTERNSHEET record of 4 bytes is cut short"),
    ],
    ids=["codepage", "name", "externsheet"],
)
def test_records_the_library_would_index_past_are_a_corrupt_workbook(
    tmp_path: Path, capfd: pytest.CaptureFixture[str], kind: int, data: bytes, reason: str
) -> None:
    # Each makes the library panic, which prints its own message (and a backtrace) to standard
    # error: refused before it reads them, with nothing else said.
    path = write_xls(tmp_path / "short.xls", [("S", [(0, 0, "a")])], extra_globals=record(kind, data))
    assert _refused(path).reason == f"corrupt workbook ({reason})"
    assert capfd.readouterr().err == ""


def test_a_panic_of_the_library_is_a_corrupt_workbook(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    # Any other panic of the library (a BaseException, not an Exception) is still the reader's
    # one-line error; the panic is raised here in its place, since no known file makes one.
    class PanicException(BaseException):
        pass

    def panic(*args: object, **kwargs: object) -> None:
        raise PanicException("index out of bounds")

    import python_calamine

    monkeypatch.setattr(python_calamine.CalamineWorkbook, "from_filelike", panic)
    path = write_xls(tmp_path / "panic.xls", [("S", [(0, 0, "a")])])
    assert _refused(path).reason == "corrupt workbook (PanicException: index out of bounds)"


@pytest.mark.parametrize(
    ("offset", "reason"),
    [
        (None, "sheet T starts within another sheet's records"),
        # The library would slice its stream there and panic.
        (0xFFFFFF00, "sheet T starts past the end of the workbook stream"),
    ],
    ids=["same-records", "past-the-end"],
)
def test_sheets_on_records_they_cannot_have_are_a_corrupt_workbook(
    tmp_path: Path, offset: int | None, reason: str
) -> None:
    stream = bytearray(biff_workbook([("S", [(0, 0, "a")]), ("T", [(0, 0, "b")])]))
    first = stream.find(struct.pack("<H", 0x0085))
    second = stream.find(struct.pack("<H", 0x0085), first + 1)
    if offset is None:
        stream[second + 4 : second + 8] = stream[first + 4 : first + 8]
    else:
        struct.pack_into("<I", stream, second + 4, offset)
    path = tmp_path / "sheets.xls"
    path.write_bytes(cfb(bytes(stream)))
    assert _refused(path).reason == f"corrupt workbook ({reason})"


def _container(tmp_path: Path) -> bytearray:
    """A workbook in its own sectors: the FAT in sector 0, the directory in 1, the stream from 2."""
    stream = biff_workbook([("S", [(r, 0, float(r)) for r in range(400)])])
    return bytearray(cfb(stream))


def _fat(data: bytearray, sector: int, value: int) -> bytearray:
    struct.pack_into("<I", data, 512 + 4 * sector, value)
    return data


@pytest.mark.parametrize(
    ("damage", "reason"),
    [
        (lambda d: _fat(d, 4, 2), "a stream loops back to sector 2"),
        (
            lambda d: _fat(d, 3, 0xFFFFFF),
            "a stream points to sector 16777215, past the end of the file",
        ),
        (lambda d: d[: len(d) // 2], "a stream declares"),
        (lambda d: _fat(d, 1, 1), "the directory loops back to sector 1"),
        (lambda d: d[:300], "the compound file's header is cut short"),
        (lambda d: d[:0x1E] + b"\x10" + d[0x1F:], "the compound file's header gives sizes no workbook has"),
    ],
    ids=["chain-loop", "sector-out-of-range", "truncated", "directory-loop", "header-cut", "sector-size"],
)
def test_damaged_compound_files_are_one_line(tmp_path: Path, damage: object, reason: str) -> None:
    path = tmp_path / "damaged.xls"
    path.write_bytes(bytes(damage(_container(tmp_path))))  # type: ignore[operator]
    # In a child: the library, given a looping directory, never returns.
    message, seconds, _ = read_in_child(path, timeout=60)
    assert message.startswith(f"{path}: corrupt workbook ({reason}")
    assert seconds < 5


@pytest.mark.parametrize("damage", ["upper-case", "name-length"])
def test_the_stream_is_found_as_the_library_finds_it(tmp_path: Path, damage: str) -> None:
    # The library finds "WORKBOOK" as it finds "Workbook", and a name whose length is damaged
    # by its terminating NUL: so does the scan.
    path = write_xls(tmp_path / "found.xls", [("S", [(0, 0, "a"), (65535, 255, 1.0)])])
    data = bytearray(path.read_bytes())
    name = "Workbook".encode("utf-16-le")
    at = data.find(name)
    assert data.count(name) == 1 and at % 128 == 0
    if damage == "upper-case":
        data[at : at + len(name)] = "WORKBOOK".encode("utf-16-le")
    else:
        struct.pack_into("<H", data, at + 64, 0xFFFF)
    path.write_bytes(bytes(data))
    error = _refused(path)
    assert (error.cell, error.reason) == ("S!IV65536", _RANGE)  # by the scan, before the library
