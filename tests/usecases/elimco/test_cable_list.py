"""The ELIMCO cable list (D3.1 Figure 11): rows merged into wires and shield terminations."""

from __future__ import annotations

import importlib.util
import warnings
from decimal import Decimal
from pathlib import Path
from types import ModuleType

import openpyxl
import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.registry import sniff_kind
from cadkg.usecases.elimco.cable_list import (
    CableListEnd,
    CableListHarness,
    CableListWire,
    ShieldTermination,
    looks_like_cable_list,
    read_elimco_cable_list,
)
from tests.conftest import EXAMPLES
from tests.ingest.workbooks import write_ods, write_xlsx

BENCH = EXAMPLES / "elimco-bench"
WORKBOOK = BENCH / "cable-list.xlsx"


def _script() -> ModuleType:
    spec = importlib.util.spec_from_file_location("make_cable_list", BENCH / "make_cable_list.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


FIG11 = _script()


def _by_name(records: list[object]) -> dict[str, object]:
    return {r.name: r for r in records if isinstance(r, CableListWire | ShieldTermination)}


def test_the_example_workbook_is_what_the_script_writes(tmp_path: Path) -> None:
    fresh = FIG11.write(tmp_path / "fresh.xlsx", FIG11.rows())
    stored = openpyxl.load_workbook(WORKBOOK, read_only=True).active
    written = openpyxl.load_workbook(fresh, read_only=True).active
    assert stored.title == "Hoja1"
    assert list(stored.iter_rows(values_only=True)) == list(written.iter_rows(values_only=True))


def test_figure_11_reads_to_six_wires_and_six_shield_terminations() -> None:
    records = read_elimco_cable_list(WORKBOOK)
    assert records[0] == CableListHarness("F929A", "A", "2", 2, "Hoja1!A2")
    wires = [r for r in records if isinstance(r, CableListWire)]
    shields = [r for r in records if isinstance(r, ShieldTermination)]
    assert len(records) == 13
    assert [w.name for w in wires] == [
        "A4351-1669B", "A4351-1669W", "A4351-2401W", "A4351-2401B", "A4351-1677B", "A4351-1677W",
    ]  # fmt: skip
    assert [(s.name, s.cable, s.connector, s.contact) for s in shields] == [
        ("A4351-1687SH", "A4351-1669", "A918VC1A", "B"),
        ("A4351-2279SH", "A4351-2401", "A350VC-A", "BS1"),
        ("A4351-1740SH", "A4351-2401", "A1UZ3C", "BS1"),
        ("A4351-1691SH", "A4351-1669", "A1UZ3B", "BS1"),
        ("A4351-1692SH", "A4351-1677", "A1UZ3B", "BS1"),
        ("A4351-1698SH", "A4351-1677", "7RN4A", "C"),
    ]
    # 23 rows: each wire on two rows (once from each end), one shield on one row, five on two.
    assert sum(len(r.rows) for r in wires + shields) == 23


def test_a_wire_and_its_repeat_from_the_other_end_are_one_wire() -> None:
    wires = _by_name(read_elimco_cable_list(WORKBOOK))
    white = wires["A4351-2401W"]
    assert isinstance(white, CableListWire)
    # Row 7 (REP 0) lists it from A350VC-A; row 12 (REP 1) repeats it from A1UZ3C.
    assert white.rows == (7, 12)
    assert white.origin == CableListEnd("A350VC-A", "A", "M39029/56-351")
    assert white.destination == CableListEnd("A1UZ3C", "14", None)
    assert (white.cable, white.length_m, white.wire_type) == (
        "A4351-2401",
        Decimal("1.057"),
        "CAN68576B22 (AX2B22)",
    )
    assert (white.symbol, white.order, white.construction, white.check) == ("B2", "2", "1X5", "0")
    # The REP 0 row gives the direction even when it is not the first: A4351-1677B is listed
    # from A1UZ3B on row 18 (REP 0) and from 7RN4A on row 24 (REP 1).
    blue = wires["A4351-1677B"]
    assert isinstance(blue, CableListWire)
    assert (blue.origin.connector, blue.origin.contact, blue.destination.connector, blue.rows) == (
        "A1UZ3B", "24", "7RN4A", (18, 24),
    )  # fmt: skip
    assert blue.location == "Hoja1!K18"


def test_a_contact_part_left_empty_on_one_row_is_taken_from_the_other(tmp_path: Path) -> None:
    table = FIG11.rows()
    # Row 3's A4351-1669B gives the EN3155 contact part at A918VC1A:A; row 19 repeats it.
    assert table[2][10] == "A4351-1669B" and table[18][10] == "A4351-1669B"
    table[2][8] = "-"
    wire = _by_name(read_elimco_cable_list(FIG11.write(tmp_path / "l.xlsx", table)))["A4351-1669B"]
    assert isinstance(wire, CableListWire)
    assert wire.origin == CableListEnd("A918VC1A", "A", "EN3155-019F2020")


def test_the_rows_as_printed_contradict_themselves(tmp_path: Path) -> None:
    # Without the corrections, row 7 runs A4351-2401W from A350VC-A:A to A350VC-A:14 while
    # its repeat on row 12 runs A1U23C:14 to A350VC-A:A.
    path = FIG11.write(tmp_path / "printed.xlsx", FIG11.rows(corrected=False))
    with pytest.raises(IngestError) as info:
        read_elimco_cable_list(path)
    err = info.value
    assert err.cell == "Hoja1!G12"
    assert err.reason == "wire A4351-2401W does not repeat the ends of row 7 the other way round"
    assert (err.found, err.expected) == ("A1U23C:14 to A350VC-A:A", "A350VC-A:14 to A350VC-A:A")
    assert str(err).startswith(f"{path}:Hoja1!G12: wire A4351-2401W")


def test_a_misspelt_wire_name_is_a_warning(tmp_path: Path) -> None:
    table = FIG11.rows()
    table[2][10], table[2][11] = "A4351-1689B", "A4351-1689"  # as Figure 11 prints row 2
    path = FIG11.write(tmp_path / "l.xlsx", table)
    with pytest.warns(IngestWarning) as caught:
        records = read_elimco_cable_list(path)
    message = str(caught[0].message)
    assert message.startswith(f"{path}:Hoja1!K19: wires A4351-1689B (row 3) and A4351-1669B join the same")
    assert {"A4351-1689B", "A4351-1669B"} <= set(_by_name(records))


def test_a_csv_export_reads_like_the_workbook(tmp_path: Path) -> None:
    table = FIG11.rows()
    text = "\n".join(";".join("-" if v is None else str(v) for v in row) for row in table) + "\n"
    path = tmp_path / "cable-list.csv"
    path.write_text(text, encoding="utf-8")
    from_csv = read_elimco_cable_list(path)
    from_book = read_elimco_cable_list(WORKBOOK)
    strip = [(type(r).__name__, getattr(r, "name", None), getattr(r, "rows", None)) for r in from_csv]
    assert strip == [
        (type(r).__name__, getattr(r, "name", None), getattr(r, "rows", None)) for r in from_book
    ]
    wire = _by_name(from_csv)["A4351-2401W"]
    assert isinstance(wire, CableListWire) and wire.location == "line 7"
    assert sniff_kind(path) == "elimco-cable-list"


def test_sniffing_tells_the_cable_list_from_the_terminal_schema() -> None:
    assert sniff_kind(WORKBOOK) == "elimco-cable-list"
    assert looks_like_cable_list(WORKBOOK.read_bytes()[:16384])
    terminals = EXAMPLES / "iema-switchgear" / "terminals.xlsx"
    assert not looks_like_cable_list(terminals.read_bytes()[:16384])
    assert sniff_kind(terminals) == "terminal-schema"
    assert sniff_kind(EXAMPLES / "iema-switchgear" / "terminals.csv") == "terminal-schema"
    assert not looks_like_cable_list(b"PK\x03\x04" + bytes(100))
    assert looks_like_cable_list(b"PN\tREP\tZONA_A\tBORNIA_A\tHILO\tCABLE\n")
    assert not looks_like_cable_list(b"Component:pin;Component:pin;HILO\n")


# --- bad input ------------------------------------------------------------------------------------


def _rows_with(change: dict[tuple[int, str], object]) -> list[list[object]]:
    table = FIG11.rows()
    for (row, column), value in change.items():
        table[row - 1][FIG11.HEADER.index(column)] = value
    return table


@pytest.mark.parametrize(
    ("change", "cell", "reason"),
    [
        ({(3, "REP"): 2}, "Hoja1!E3", "not a repeat mark"),
        ({(3, "LONGITUD"): "1,5 m"}, "Hoja1!P3", "not a length"),
        ({(3, "LONGITUD"): 0}, "Hoja1!P3", "not a length"),
        ({(5, "PN"): "F930B"}, "Hoja1!A5", "a second harness (the list is of F929A, from row 2)"),
        ({(4, "HILO"): "-"}, "Hoja1!K4", "no wire name"),
        ({(4, "ZONA_B"): "-"}, "Hoja1!S4", "no connector at the B end of wire A4351-1669W"),
        ({(4, "BORNIA_B"): None}, "Hoja1!T4", "no contact at the B end of wire A4351-1669W"),
        ({(17, "LONGITUD"): 1500}, "Hoja1!P17", "wire A4351-1669W is given another length than on row 4"),
        ({(17, "CABLE"): "A4351-1670"}, "Hoja1!L17", "wire A4351-1669W is given another cable than on row 4"),
        (
            {(17, "CNX_B"): "EN9999"},
            "Hoja1!U17",
            "wire A4351-1669W is given another contact part at A918VC1A:H",
        ),
        ({(6, "BORNIA_A"): "BS2"}, "Hoja1!H6", "shield A4351-2279SH ends elsewhere than on row 5"),
        ({(5, "BORNIA_A"): "BS2"}, "Hoja1!T5", "shield A4351-2279SH ends at two contacts"),
        (
            {(6, "BORNIA_A"): None, (6, "BORNIA_B"): None},
            "Hoja1!H6",
            "shield A4351-2279SH ends at no contact",
        ),
        ({(6, "SH"): "A4351-9999/1"}, "Hoja1!J6", "shield A4351-2279SH is given two shield groups"),
    ],
)
def test_bad_rows_name_their_cell(
    tmp_path: Path, change: dict[tuple[int, str], object], cell: str, reason: str
) -> None:
    path = FIG11.write(tmp_path / "bad.xlsx", _rows_with(change))
    with pytest.raises(IngestError) as info:
        read_elimco_cable_list(path)
    assert (info.value.cell, info.value.reason) == (cell, reason)
    assert str(info.value).startswith(f"{path}:{cell}: {reason}")


def test_a_wire_listed_three_times(tmp_path: Path) -> None:
    table = FIG11.rows()
    table.append(list(table[3]))
    path = FIG11.write(tmp_path / "bad.xlsx", table)
    with pytest.raises(IngestError, match="wire A4351-1669W listed a third time") as info:
        read_elimco_cable_list(path)
    assert info.value.cell == "Hoja1!K25"


def test_a_missing_column(tmp_path: Path) -> None:
    table = [row[:15] + row[16:] for row in FIG11.rows()]  # without LONGITUD
    path = FIG11.write(tmp_path / "bad.xlsx", table)
    with pytest.raises(IngestError) as info:
        read_elimco_cable_list(path)
    assert info.value.cell == "Hoja1!A1"
    assert info.value.reason == "missing column LONGITUD"


def test_a_workbook_whose_sheet_holds_no_cable_list(tmp_path: Path) -> None:
    # The first sheet with values is a cover sheet: the list's sheet is not where it belongs.
    path = write_xlsx(
        tmp_path / "cover.xlsx",
        [("Empty", []), ("Portada", [["Harness F929A"], ["rev A"]]), ("Hoja1", FIG11.rows())],
    )
    with pytest.raises(IngestError) as info:
        read_elimco_cable_list(path)
    err = info.value
    assert err.cell == "Portada!A1"
    assert err.reason.startswith("sheet 'Portada' holds no cable list")
    assert err.found == "Harness F929A"


def test_a_workbook_without_values(tmp_path: Path) -> None:
    path = write_xlsx(tmp_path / "empty.xlsx", [("Hoja1", [])])
    with pytest.raises(IngestError, match="no sheet holds any value"):
        read_elimco_cable_list(path)


def test_a_corrupt_workbook(tmp_path: Path) -> None:
    whole = WORKBOOK.read_bytes()
    path = tmp_path / "cut.xlsx"
    path.write_bytes(whole[: len(whole) // 2])
    with pytest.raises(IngestError) as info:
        read_elimco_cable_list(path)
    assert info.value.path == str(path)
    assert info.value.reason.startswith("corrupt workbook")


def test_only_a_header(tmp_path: Path) -> None:
    path = FIG11.write(tmp_path / "bad.xlsx", FIG11.rows()[:1])
    with pytest.raises(IngestError, match="no rows after the header") as info:
        read_elimco_cable_list(path)
    assert info.value.cell == "Hoja1!A1"


def test_a_header_repeated_down_the_sheet_is_skipped(tmp_path: Path) -> None:
    table = FIG11.rows()
    table.insert(12, list(table[0]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        records = read_elimco_cable_list(FIG11.write(tmp_path / "pages.xlsx", table))
    assert len(records) == 13


def test_an_ods_workbook_reads_like_the_xlsx(tmp_path: Path) -> None:
    table = [["-" if v is None else v for v in row] for row in FIG11.rows()]
    path = write_ods(tmp_path / "cable-list.ods", [("Hoja1", table)])
    records = read_elimco_cable_list(path)
    assert [getattr(r, "name", None) for r in records] == [
        getattr(r, "name", None) for r in read_elimco_cable_list(WORKBOOK)
    ]
    wire = _by_name(records)["A4351-2401W"]
    assert isinstance(wire, CableListWire) and wire.location == "Hoja1!K7"
