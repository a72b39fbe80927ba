"""The spreadsheet layer: addresses, cell text, the first non-empty sheet, and broken workbooks."""

from __future__ import annotations

import datetime
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.ingest.sheet import (
    CellError,
    SheetRow,
    cell_address,
    cell_text,
    column_letter,
    read_sheet,
    read_workbook,
)
from tests.ingest.biff import grid, write_xls
from tests.ingest.workbooks import (
    SHEET_HEAD,
    SHEET_TAIL,
    read_in_child,
    replace_in_member,
    write_ods,
    write_raw_xlsx,
    write_xlsx,
)

ROWS = [["Block", "Position"], [None, None], [None, None], ["X1600", 2.5], [None, "x"]]


@pytest.mark.parametrize(
    ("index", "letters"), [(0, "A"), (2, "C"), (25, "Z"), (26, "AA"), (51, "AZ"), (701, "ZZ"), (702, "AAA")]
)
def test_column_letter(index: int, letters: str) -> None:
    assert column_letter(index) == letters


@pytest.mark.parametrize(
    ("sheet", "row", "column", "address"),
    [
        ("Sheet1", 7, 2, "Sheet1!C7"),
        ("Morsetti_2", 1, 27, "Morsetti_2!AB1"),
        ("My sheet", 1, 0, "'My sheet'!A1"),
        ("O'Brien", 12, 1, "'O''Brien'!B12"),
        ("2024", 3, 0, "'2024'!A3"),
    ],
)
def test_cell_address(sheet: str, row: int, column: int, address: str) -> None:
    assert cell_address(sheet, row, column) == address


@pytest.mark.parametrize(
    ("value", "text"),
    [
        (None, ""),
        (2.0, "2"),
        (2.5, "2.5"),
        (7, "7"),
        ("  a;b \n", "a;b"),
        (datetime.date(2026, 11, 21), "2026-11-21"),
    ],
)
def test_cell_text(value: object, text: str) -> None:
    assert cell_text(value) == text


def _write(kind: str, path: Path, sheets: list[tuple[str, list[list[object]]]]) -> Path:
    if kind == "xls":
        return write_xls(path, [(name, grid(rows)) for name, rows in sheets])
    return write_xlsx(path, sheets) if kind == "xlsx" else write_ods(path, sheets)


@pytest.mark.parametrize("kind", ["xlsx", "ods", "xls"])
def test_first_non_empty_sheet_with_row_numbers(tmp_path: Path, kind: str) -> None:
    path = _write(kind, tmp_path / f"book.{kind}", [("Cover", []), ("Schema", ROWS), ("Later", [["z"]])])
    name, rows = read_sheet(path)
    assert name == "Schema"
    assert [r.number for r in rows] == [1, 2, 3, 4, 5]
    assert [r.is_blank for r in rows] == [False, True, True, False, False]
    assert rows[0].cells[:2] == ("Block", "Position")
    assert rows[3].cell(0) == "X1600" and rows[3].cell(1) == 2.5
    assert rows[4].cell(1) == "x" and rows[4].cell(9) is None


@pytest.mark.parametrize("kind", ["xlsx", "ods", "xls"])
def test_leading_blank_rows_and_columns_keep_addresses(tmp_path: Path, kind: str) -> None:
    path = _write(kind, tmp_path / f"book.{kind}", [("S", [[None], [None, None, "h"], [None, None, 3]])])
    _, rows = read_sheet(path)
    assert [(r.number, cell_text(r.cell(2))) for r in rows] == [(1, ""), (2, "h"), (3, "3")]


def test_sheet_row_helpers() -> None:
    row = SheetRow(4, (None, " ", 0))
    assert not row.is_blank  # a zero is a value
    assert SheetRow(5, (None, "  ")).is_blank


@pytest.mark.parametrize("kind", ["xlsx", "ods", "xls"])
def test_workbook_without_values(tmp_path: Path, kind: str) -> None:
    path = _write(kind, tmp_path / f"empty.{kind}", [("A", []), ("B", [[None, None]])])
    with pytest.raises(IngestError) as info:
        read_sheet(path)
    assert info.value.reason == "no sheet holds any value"


def _truncated(tmp_path: Path) -> bytes:
    return write_xlsx(tmp_path / "good.xlsx", [("S", ROWS)]).read_bytes()[:300]


@pytest.mark.parametrize(
    ("content", "reason"),
    [
        (b"", "the file is empty"),
        (b"Block;Position\nX1;1\n", "not a workbook (not a ZIP archive)"),
        (b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1" + bytes(500), "corrupt workbook (the compound file's header"),
        (
            b"\xd0\xcf\x11\xe0\xa1\xb1\x1a\xe1" + bytes(500) + "EncryptedPackage".encode("utf-16-le"),
            "an encrypted workbook",
        ),
        (None, "corrupt workbook (BadZipFile"),
    ],
    ids=["empty", "text", "ole2", "encrypted", "truncated"],
)
@pytest.mark.parametrize("suffix", [".xlsx", ".ods"])
def test_broken_workbook_is_an_ingest_error(
    tmp_path: Path, suffix: str, content: bytes | None, reason: str
) -> None:
    path = tmp_path / f"bad{suffix}"
    path.write_bytes(_truncated(tmp_path) if content is None else content)
    with pytest.raises(IngestError) as info:
        read_sheet(path)
    assert info.value.path == str(path)
    assert info.value.reason.startswith(reason)


def test_zip_that_is_not_a_workbook(tmp_path: Path) -> None:
    import zipfile

    path = tmp_path / "notes.xlsx"
    with zipfile.ZipFile(path, "w") as archive:
        archive.writestr("notes.txt", "hello")
    with pytest.raises(IngestError) as info:
        read_sheet(path)
    assert info.value.reason.startswith("corrupt workbook (KeyError")


def test_missing_file(tmp_path: Path) -> None:
    with pytest.raises(IngestError, match="cannot read the file"):
        read_sheet(tmp_path / "gone.xlsx")


@pytest.mark.parametrize(("kind", "suffix"), [("xlsx", ".ods"), ("ods", ".xlsx")])
def test_content_decides_the_workbook_format_not_the_suffix(tmp_path: Path, kind: str, suffix: str) -> None:
    path = _write(kind, tmp_path / f"book.{kind}", [("S", [["a", 1]])])
    renamed = path.rename(tmp_path / f"renamed{suffix}")
    assert read_sheet(renamed) == ("S", [SheetRow(1, ("a", 1))])


def test_xlsx_row_numbered_past_the_last_row_is_refused(tmp_path: Path) -> None:
    # A damaged file: openpyxl would pad every row up to this number and fill memory.
    path = write_xlsx(tmp_path / "book.xlsx", [("S", [["a", 1], ["b", 2]])])
    replace_in_member(path, "xl/worksheets/sheet1.xml", b'<row r="2">', b'<row r="99999999999">')
    with pytest.raises(IngestError) as info:
        read_sheet(path)
    assert info.value.cell == "S!A1048577"
    assert "beyond the last row" in info.value.reason


_ROW = b"<table:table-row><table:table-cell "


@pytest.mark.parametrize(
    ("repeat", "cell"),
    [
        (b'<table:table-row table:number-rows-repeated="100000000"><table:table-cell ', "S!B1048577"),
        (b'<table:table-row><table:table-cell table:number-columns-repeated="20000" ', "S!XFE1"),
        # Within both limits, but a million rows of 16,000 values would not fit in memory.
        (
            b'<table:table-row table:number-rows-repeated="1000000">'
            b'<table:table-cell table:number-columns-repeated="16000" ',
            "S!WQK1000000",
        ),
    ],
    ids=["rows", "columns", "cells"],
)
def test_ods_repeats_past_the_sheet_size_are_refused(tmp_path: Path, repeat: bytes, cell: str) -> None:
    path = write_ods(tmp_path / "book.ods", [("S", [["a", 1], ["b", 2]])])
    replace_in_member(path, "content.xml", _ROW, repeat)
    with pytest.raises(IngestError) as info:
        read_sheet(path)
    assert info.value.cell == cell
    assert "repeated rows or cells" in info.value.reason


def test_ods_trailing_empty_repeats_as_calc_writes_them_still_read(tmp_path: Path) -> None:
    path = write_ods(tmp_path / "book.ods", [("S", [["a", 1], ["b", 2]])])
    empty = (
        b'<table:table-row table:number-rows-repeated="1048574">'
        b'<table:table-cell table:number-columns-repeated="16384"/></table:table-row></table:table>'
    )
    replace_in_member(path, "content.xml", b"</table:table>", empty)
    assert read_sheet(path) == ("S", [SheetRow(1, ("a", 1)), SheetRow(2, ("b", 2))])


def test_an_ods_cell_of_many_attributes_is_scanned_in_time_linear_in_them(tmp_path: Path) -> None:
    import time

    # Namespaced, as a cell's are: lxml took about 11 s to clear such rows from the scan's tree.
    many = b" ".join(b'table:x%d="1"' % i for i in range(20_000))
    path = write_ods(tmp_path / "book.ods", [("S", [["a", 1], ["b", 2]])])
    replace_in_member(path, "content.xml", b"<table:table-cell ", b"<table:table-cell " + many + b" ")
    started = time.process_time()
    assert read_sheet(path) == ("S", [SheetRow(1, ("a", 1)), SheetRow(2, ("b", 2))])
    assert time.process_time() - started < 3


def _column_xfd_rows() -> bytes:
    rows = (b'<row r="%d"><c r="XFD%d"><v>1</v></c></row>' % (n, n) for n in range(2, 60_002))
    return SHEET_HEAD + b"".join(rows) + SHEET_TAIL


@pytest.mark.parametrize(
    ("sheet", "cell", "reason"),
    [
        # 60,000 rows of one cell in the last column: the library would build 983M cells (30 GB).
        ([(_column_xfd_rows(), 1)], "S!XFD129", "the sheet's cells span more than cadkg reads"),
        # One inline string of a gigabyte, a megabyte compressed.
        (
            [(SHEET_HEAD + b'<row r="2"><c r="A2" t="inlineStr"><is><t>', 1), (b"a" * (1 << 20), 1024)],
            "S!A2",
            "a cell's text is longer than a cell can hold",
        ),
    ],
    ids=["column-XFD", "gigabyte-string"],
)
def test_workbook_bombs_are_refused_in_bounded_memory(
    tmp_path: Path, sheet: list[tuple[bytes, int]], cell: str, reason: str
) -> None:
    path = write_raw_xlsx(tmp_path / "bomb.xlsx", sheet)
    assert path.stat().st_size < 1_100_000
    message, seconds, megabytes = read_in_child(path)
    assert message.startswith(f"{path}:{cell}: {reason}")
    assert megabytes < 300, f"peak RSS {megabytes} MB"
    assert seconds < 30  # measured well under 1 s; the machine may be loaded


def test_formula_errors_read_as_errors_not_as_empty_cells(tmp_path: Path) -> None:
    sheet = SHEET_HEAD + b'<row r="2"><c r="B2" t="e"><f>-basta</f><v>#NAME?</v></c></row>' + SHEET_TAIL
    _, rows = read_sheet(write_raw_xlsx(tmp_path / "error.xlsx", [(sheet, 1)]))
    assert rows[1].cells == (None, CellError("#NAME?"))
    assert cell_text(rows[1].cell(1)) == "#NAME?"


@pytest.mark.parametrize(
    ("cells", "cell"),
    [(b'<c r="XFE2"><v>1</v></c>', "S!XFE2"), (b'<c r="AAAAAA2"><v>1</v></c>', "S!XFE2")],
    ids=["XFE", "six-letters"],
)
def test_cell_past_the_last_column_is_refused(tmp_path: Path, cells: bytes, cell: str) -> None:
    sheet = SHEET_HEAD + b'<row r="2">' + cells + b"</row>" + SHEET_TAIL
    with pytest.raises(IngestError) as info:
        read_sheet(write_raw_xlsx(tmp_path / "wide.xlsx", [(sheet, 1)]))
    assert info.value.cell == cell


def test_merged_ranges_and_every_sheet(tmp_path: Path) -> None:
    sheets = [("Foglio1", [["ORIENTATIONS", None], ["a", "b"]]), ("Foglio2", [])]
    path = write_xlsx(tmp_path / "book.xlsx", sheets)
    import openpyxl

    book = openpyxl.load_workbook(path)
    book["Foglio1"].merge_cells("A1:B1")
    book.save(path)
    workbook = read_workbook(path)
    assert [s.name for s in workbook.sheets] == ["Foglio1", "Foglio2"]
    assert workbook.sheets[0].merged == ((1, 0, 1, 1),)
    assert workbook.sheets[1].is_empty
    assert workbook.sheets[0].address(2, 1) == "Foglio1!B2"
