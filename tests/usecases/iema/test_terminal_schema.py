"""The terminal block schema reader: CSV sample, the same rows as XLSX and ODS, and located errors."""

from __future__ import annotations

import csv
import dataclasses
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.ingest.sheet import read_sheet
from cadkg.usecases.iema.terminal_schema import TerminalSlot, looks_like_terminal_schema, read_terminal_schema
from tests.conftest import ROOT
from tests.ingest.workbooks import replace_in_member, write_ods, write_xlsx

SAMPLE = ROOT / "tests" / "data" / "readers" / "terminal-schema.csv"
HEADER = ["Terminal block", "Position", "Terminal", "Cad ID", "Commercial", "Levels"]


@pytest.fixture(scope="module")
def sample() -> list[TerminalSlot]:
    return read_terminal_schema(SAMPLE)


def _sample_rows() -> list[list[object]]:
    """The sample's data rows as a spreadsheet holds them: numbers as numbers, blanks as None."""
    with SAMPLE.open(encoding="utf-8", newline="") as handle:
        _, *rows = csv.reader(handle, delimiter=";")
    return [[int(c) if c.isdigit() else (c or None) for c in row] for row in rows]


def test_csv_sample_exact_rows(sample: list[TerminalSlot]) -> None:
    assert len(sample) == 19
    assert sample[1] == TerminalSlot(
        block="X0030.1",
        position=2,
        terminal="1L+.2",
        cad_id="ID000022",
        commercial="6013280",
        levels=("a1", "a2", "b1", "b2"),
        line=3,
        sheet=None,
    )
    assert sample[-1] == TerminalSlot("X1600", 5, None, "ID000085", None, (), 20, None)


def test_csv_sample_order_and_blocks(sample: list[TerminalSlot]) -> None:
    assert [s.line for s in sample] == list(range(2, 21))
    x1500 = [s for s in sample if s.block == "X1500"]
    assert [s.position for s in x1500] == list(range(1, 13))
    assert [s.terminal for s in x1500] == [str(i) for i in range(1, 13)]
    assert [s.position for s in x1500 if s.commercial == "6013298"] == [4, 8, 12]
    assert {s.levels for s in x1500} == {("a", "b")}
    assert [(s.position, s.terminal) for s in sample if s.block == "X1600"] == [
        (1, "1"),
        (2, "2"),
        (3, "3"),
        (4, "4"),
        (5, None),
    ]


@pytest.mark.parametrize("kind", ["xlsx", "ods"])
def test_workbook_reads_like_the_csv(tmp_path: Path, sample: list[TerminalSlot], kind: str) -> None:
    rows = [HEADER, *_sample_rows()]
    sheets = [("Cover", []), ("Morsetti", rows)]
    path = (write_xlsx if kind == "xlsx" else write_ods)(tmp_path / f"schema.{kind}", sheets)
    slots = read_terminal_schema(path)
    assert {s.sheet for s in slots} == {"Morsetti"}
    assert [dataclasses.replace(s, sheet=None) for s in slots] == sample


def test_integral_float_position_is_accepted(tmp_path: Path) -> None:
    path = write_xlsx(
        tmp_path / "f.xlsx", [("S", [HEADER, ["X1", 1, "1", "ID1", None, "a"], ["X1", 2, "2", "ID2"]])]
    )
    # openpyxl writes 2 for 2.0; store the float as some spreadsheet programs do.
    replace_in_member(
        path, "xl/worksheets/sheet1.xml", b'<c r="B3" t="n"><v>2</v>', b'<c r="B3" t="n"><v>2.0</v>'
    )
    _, rows = read_sheet(path)
    assert rows[2].cells[1] == 2.0 and isinstance(rows[2].cells[1], float)
    with pytest.raises(IngestError) as info:
        read_terminal_schema(path)
    # Row 3 got past its position and failed on the next check: its empty levels.
    assert info.value.cell == "S!F3"
    assert info.value.reason == "bad levels of terminal '2'"


@pytest.mark.parametrize(
    ("position", "found"), [(2.5, "2.5"), (3.4e39, "3.4e+39"), (10**12, "1000000000000")]
)
def test_non_integral_or_huge_position_names_the_cell(tmp_path: Path, position: float, found: str) -> None:
    rows = [HEADER, ["-X1", 1, 1, "ID1", None, "a"], ["-X1", position, 2, "ID2", None, "a"]]
    path = write_xlsx(tmp_path / "bad.xlsx", [("Sheet 1", rows)])
    with pytest.raises(IngestError) as info:
        read_terminal_schema(path)
    err = info.value
    assert (err.cell, err.line, err.found, err.reason) == ("'Sheet 1'!B3", None, found, "not a position")
    assert str(err).startswith(f"{path}:'Sheet 1'!B3: not a position (found '{found}'")


def test_gap_in_a_workbook_names_the_position_cell(tmp_path: Path) -> None:
    rows = [HEADER, None, ["X1", 1, 1, "ID1", None, "a"], ["X1", 3, 3, "ID3", None, "a"]]
    path = write_ods(tmp_path / "gap.ods", [("S", [r or [] for r in rows])])
    with pytest.raises(IngestError) as info:
        read_terminal_schema(path)
    assert info.value.cell == "S!B4"
    assert info.value.reason == "terminal block X1 has no position 2: positions must run 1..n without gaps"


# --- CSV errors ---------------------------------------------------------------------------------------

CSV_HEADER = "Terminal block;Position;Terminal;Cad ID;Commercial;Levels\n"
GOOD = ["X1600;1;1;ID000081;6013290;a,b", "X1600;2;2;ID000082;6013290;a,b"]


@pytest.mark.parametrize(
    ("bad_row", "reason", "found"),
    [
        (
            "X1600;4;3;ID000083;;a",
            "terminal block X1600 has no position 3: positions must run 1..n without gaps",
            "4",
        ),
        # Found at once, not by counting up to the huge position.
        (
            "X1600;999999999;3;ID000083;;a",
            "terminal block X1600 has no position 3: positions must run 1..n without gaps",
            "999999999",
        ),
        ("X1600;2;3;ID000083;;a", "position 2 of terminal block X1600 given twice (first on line 3)", None),
        (
            "=-X1600;3;2;ID000083;;a",
            "terminal '2' of terminal block X1600 given twice (first on line 3)",
            None,
        ),
        ("X1600;3;3;id000081;;a", "CAD item ID id000081 given twice (first on line 2)", None),
        ("X1600;3;3;83;;a", "malformed CAD item ID", "83"),
        ("X1600;3;3;;;a", "malformed CAD item ID", ""),
        ("=-;3;3;ID000083;;a", "empty terminal block label", None),
        ("X1600;three;3;ID000083;;a", "not a position", "three"),
        ("X1600;0;3;ID000083;;a", "not a position", "0"),
        ("X1600;2.0;3;ID000083;;a", "not a position", "2.0"),
        ("X1600;3;3;ID000083;;", "bad levels of terminal '3'", ""),
        ("X1600;3;3;ID000083;;a,,b", "bad levels of terminal '3'", "a,,b"),
        ("X1600;3;3;ID000083;;a,a", "bad levels of terminal '3'", "a,a"),
        ("X1600;3;;ID000083;;a", "levels on a row without a terminal (an end plate has none)", "a"),
    ],
    ids=[
        "gap",
        "gap-after-a-huge-position",
        "duplicate-position",
        "duplicate-terminal",
        "duplicate-cad-id",
        "malformed-cad-id",
        "empty-cad-id",
        "empty-block",
        "position-text",
        "position-zero",
        "position-float-text",
        "no-levels",
        "empty-level",
        "repeated-level",
        "levels-on-end-plate",
    ],
)
def test_bad_row_is_located_on_its_line(write, bad_row: str, reason: str, found: str | None) -> None:
    path = write("schema.csv", CSV_HEADER + "\n".join([*GOOD, bad_row, "X2;1;1;ID000099;;a"]) + "\n")
    with pytest.raises(IngestError) as info:
        read_terminal_schema(path)
    err = info.value
    assert (err.line, err.cell, err.reason, err.found) == (4, None, reason, found)
    assert str(err).startswith(f"{path}:4: {reason}")


def test_missing_column_names_what_was_found(write) -> None:
    path = write("schema.tsv", "Morsettiera\tPosizione\tMorsetto\tLivelli\nX1\t1\t1\ta\n")
    with pytest.raises(IngestError) as info:
        read_terminal_schema(path)
    err = info.value
    assert (err.line, err.reason, err.found) == (
        1,
        "missing column 'Cad ID'",
        "Morsettiera, Posizione, Morsetto, Livelli",
    )


@pytest.mark.parametrize(
    ("text", "line", "reason"),
    [
        ("\n\n" + CSV_HEADER, 3, "no terminal rows after the header"),
        (
            "Block,Pos.,Terminal name,Item ID,Pins,Terminal\nX1,1,1,ID1,a,1\n",
            1,
            "two 'Terminal' columns",
        ),
        ("Schema morsetti QE01\n" + CSV_HEADER, 1, "missing column 'Terminal block', 'Position'"),
    ],
    ids=["no-rows", "duplicate-column", "title-above-header"],
)
def test_structure_errors(write, text: str, line: int, reason: str) -> None:
    with pytest.raises(IngestError) as info:
        read_terminal_schema(write("schema.csv", text))
    assert info.value.line == line
    assert info.value.reason.startswith(reason)


def test_english_aliases_and_comma_delimiter(write) -> None:
    text = 'Block,Pos.,Terminal name,Item ID,Part number,Pins\n-X9,1,A,ID7,P-1,"x;y"\n-X9,2,,ID8,,\n'
    assert read_terminal_schema(write("schema.csv", text)) == [
        TerminalSlot("X9", 1, "A", "ID7", "P-1", ("x", "y"), 2, None),
        TerminalSlot("X9", 2, None, "ID8", None, (), 3, None),
    ]


def test_sniff() -> None:
    assert looks_like_terminal_schema(SAMPLE.read_bytes())
    assert looks_like_terminal_schema(b'\xef\xbb\xbf"Block"\t"Item ID"\n')
    assert not looks_like_terminal_schema(b"Block;Position;Terminal\n")
    assert not looks_like_terminal_schema(b"PK\x03\x04" + bytes(100))
