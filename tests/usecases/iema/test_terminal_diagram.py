"""EPLAN's terminal diagram (Schema Morsetti) in both layouts, the QR-marker table, and the
cross-check of the diagram's wire ends against the connection list in ``cadkg validate``."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import pytest

import cadkg
from cadkg.errors import IngestError, IngestWarning
from cadkg.registry import sniff_kind
from cadkg.usecases.iema.derive.strip_items import items_along
from cadkg.usecases.iema.marker_table import QrMarker, read_marker_table
from cadkg.usecases.iema.terminal_diagram import DiagramRow, read_terminal_diagram
from tests.conftest import IEMA
from tests.ingest.workbooks import write_ods, write_xlsx

HEADER = [
    "Morsettiera",
    "Zona",
    "Pin",
    "Comp. Destinazione 1",
    None,
    "Comp. Destinazione 2",
    None,
    "Testo funzionale",
]
PREAMBLE = [
    [],
    [None, "Nome Progetto: ", "PROGETTO DEMO"],
    [None, "Descrizione macchina: ", "99 DEMO"],
    [None, "Cliente: ", "ACME"],
    [None, "Commessa: ", "commessa"],
    [],
]
ONE_SHEET = [
    ["=-X1600", "Q", "0", None, None, None, None, "FERMO MORSETTO"],
    ["=-X1600"],  # EPLAN's placeholder: the strip's label alone
    ["=-X1600", "Q", "1", "=-Q1500.1:A1", "Q", "=-S1600.01:13", "B", "COMANDO MOTORE 1"],
    ["=-X1600", "Q", "2", "=-Q1500.2:A1", "Q"],
    ["=-X1600", "Q"],  # a zone and no pin: a division
    ["=-X1600", "Q", "999999", None, None, None, None, "FERMO MORSETTO"],
    ["=-X1500.1", "B", "1", "=-M1500.1:U1", "B"],
]


def _kinds(rows: list[DiagramRow]) -> list[tuple[str, int, str, str | None]]:
    return [(r.strip, r.position, r.kind, r.terminal) for r in rows]


@pytest.mark.parametrize("form", ["ods", "xlsx-with-preamble"])
def test_one_sheet_layout(tmp_path: Path, form: str) -> None:
    if form == "ods":
        path = write_ods(tmp_path / "SCHEMA_MORSETTI.ods", [("Schema_Morsetti_00", [HEADER, *ONE_SHEET])])
        first = 2
    else:
        sheets = [("Schema_Morsetti_00", [*PREAMBLE, HEADER, *ONE_SHEET]), ("Foglio2", []), ("Foglio3", [])]
        path = write_xlsx(tmp_path / "Schema_Morsetti.xlsx", sheets)
        first = 8
    assert sniff_kind(path) == "terminal-diagram"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", IngestWarning)
        rows = read_terminal_diagram(path)
    assert _kinds(rows) == [
        ("X1600", 1, "start", None),
        ("X1600", 2, "placeholder", None),
        ("X1600", 3, "terminal", "1"),
        ("X1600", 4, "terminal", "2"),
        ("X1600", 5, "division", None),
        ("X1600", 6, "end", None),
        ("X1500.1", 1, "terminal", "1"),
    ]
    one = rows[2]
    assert one.destinations == (("=-Q1500.1:A1", "Q"), ("=-S1600.01:13", "B"))
    assert (one.zone, one.function, one.line, one.raw_strip) == (
        "Q",
        "COMANDO MOTORE 1",
        first + 2,
        "=-X1600",
    )
    warned = [str(w.message) for w in caught]
    assert warned == (
        [] if form == "ods" else [f"{path}: sheets without a terminal diagram skipped: Foglio2, Foglio3"]
    )


# One sheet per strip, the cells beside their headers: the terminal under 'Tipo Morsetto', the
# destinations under 'Sezione 1' and right of 'Comp. Destinazione 1', the type right of 'Comp.
# Destinazione 2', the floor under 'PIANO'.
PER_STRIP_HEADER = ["Morsettiera", "Pin", "Ponte", "Tipo Morsetto", "Sezione 1", "Comp. Destinazione 1", None]
PER_STRIP_HEADER += ["Sezione 2", "Comp. Destinazione 2", None, "PIANO"]
PER_STRIP = [
    ["=SSB-XC", None, None, None, None, None, None, None, None, "WEIDMULLER ZEW 35"],
    [
        "=SSB-XC",
        None,
        None,
        "1.1",
        "=SSB-05U2:-",
        "QE",
        "=SSB-20B1:3:L-",
        "QE",
        ".",
        "WEIDMULLER ZDK 2.5",
        "1",
    ],
    ["=SSB-XC", None, None, "1.2", "=SSB-XC:2.2:a2", None, None, None, None, None, "2"],
    ["=SSB-XC", None, None, None, None, None, None, None, None, None, "2"],  # an empty floor: nothing
    ["=SSB-XC", None, None, None, None, None, None, None, None, "WEIDMULLER ZAP/TW 3"],
]


def test_per_strip_layout_reads_cells_beside_their_headers(tmp_path: Path) -> None:
    sheet = [[None, "Nome Progetto: ", None, "TEST1"], [], PER_STRIP_HEADER, *PER_STRIP]
    path = write_xlsx(tmp_path / "Schema Morsetti.xlsx", [("=SSB-XC", sheet)]).rename(
        tmp_path / "Schema.xlsm"
    )
    rows = read_terminal_diagram(path)
    assert _kinds(rows) == [
        ("XC", 1, "accessory", None),
        ("XC", 2, "terminal", "1.1"),
        ("XC", 3, "floor", "1.2"),
        ("XC", 4, "accessory", None),
    ]
    terminal = rows[1]
    assert terminal.destinations == (("=SSB-05U2:-", "QE"), ("=SSB-20B1:3:L-", "QE"))
    assert (terminal.terminal_type, terminal.level, terminal.function) == ("WEIDMULLER ZDK 2.5", "1", ".")
    assert rows[2].destinations == (("=SSB-XC:2.2:a2", None),)


def test_the_summary_of_strips(tmp_path: Path) -> None:
    rows = [
        [None, "Nome Progetto: ", "P"],
        [],
        ["Morsettiera", "Ubicazione", "Funzione"],
        ["X0V", "  ", "ALIMENTAZIONE"],
    ]
    (row,) = read_terminal_diagram(write_xlsx(tmp_path / "Sommario.xlsx", [("Sommario", rows)]))
    assert (row.strip, row.kind, row.function) == ("X0V", "summary", "ALIMENTAZIONE")


def test_a_workbook_without_a_diagram(tmp_path: Path) -> None:
    with pytest.raises(IngestError) as info:
        read_terminal_diagram(write_xlsx(tmp_path / "x.xlsx", [("Foglio1", [["a", "b"]])]))
    assert info.value.reason == "no sheet holds a terminal diagram"


def test_rows_take_the_strips_items_in_order() -> None:
    rows = [(1, "start", None), (2, "placeholder", None), (3, "terminal", "1"), (4, "floor", "1.2")]
    rows += [(5, "division", None), (6, "terminal", "2"), (7, "end", None)]
    # The end row takes an item only when the strip has one left (its second end stop).
    assert items_along(rows, ["I1", "I2", "I3", "I4", "I5"]) == [
        (1, "I1", None),
        (2, "I2", "1"),
        (2, "I2", "1.2"),
        (3, "I3", None),
        (4, "I4", "2"),
        (5, "I5", None),
    ]
    assert items_along(rows, ["I1", "I2"]) == [(1, "I1", None), (2, "I2", "1"), (2, "I2", "1.2")]


# --- the QR-code marker table -------------------------------------------------------------------------

MARKERS = [
    [],
    [None, "ORIENTATIONS OF QR CODES"],
    [None, "Product", "Commercial", "ID", None, "X (m)", "Y (m)", "Z (m)"],
    [None, "3RV2011-0JA10", 6503372.0, "F1500.1", "ID000045", 0.0382, 0.0601, 0.1845],
    [None, None, None, "F1500.2", "ID000049", 0.0382, 0.0601, 0.1845],  # merged cells read empty
    [],  # the separator between blocks
    [None, "6EP1334-3BA10", 6032224.0, "T0030", "ID000062", 0.06, 0.1194, 0.2205],
]


def test_marker_table_fills_merged_cells_down_within_a_block(tmp_path: Path) -> None:
    path = write_ods(tmp_path / "components_ids_marker_table.ods", [("Sheet1", MARKERS)])
    assert sniff_kind(path) == "marker-table"
    first, second, third = read_marker_table(path)
    assert first == QrMarker(
        "3RV2011-0JA10", "6503372", "F1500.1", "ID000045", (0.0382, 0.0601, 0.1845), 4, "Sheet1"
    )
    assert (second.product, second.commercial, second.cad_id) == ("3RV2011-0JA10", "6503372", "ID000049")
    assert (third.product, third.label, third.position) == ("6EP1334-3BA10", "T0030", (0.06, 0.1194, 0.2205))


@pytest.mark.parametrize(("row", "cell"), [(4, "Sheet1!E5"), (5, "Sheet1!F5")], ids=["cad-id", "coordinate"])
def test_marker_table_errors_name_the_cell(tmp_path: Path, row: int, cell: str) -> None:
    rows = [list(r) for r in MARKERS]
    rows[4][row] = "?" if row == 4 else "alto"
    with pytest.raises(IngestError) as info:
        read_marker_table(write_ods(tmp_path / "m.ods", [("Sheet1", rows)]))
    assert info.value.cell == cell


# --- the cross-check in cadkg validate -------------------------------------------------------------------


def test_validate_finds_a_diagram_destination_no_list_wires(tmp_path: Path) -> None:
    cell = shutil.copytree(IEMA.parent, tmp_path / "cell")
    kg = cadkg.build(cell / "manifest.toml")
    try:
        assert [f for f in cadkg.validate(kg, shacl=False) if f.check == "diagram-vs-list"] == []
    finally:
        kg.close()
    # Terminal X1500:1 of the example's diagram: another end than the list's.
    from cadkg.ingest.sheet import read_sheet

    name, rows = read_sheet(cell / "schema-morsetti.ods")
    table = [[c for c in r.cells] for r in rows]
    row = next(i for i, r in enumerate(table) if r[:3] == ["=-X1500", "Q", "1"])
    original = table[row][3]
    table[row][3] = "=-Q1500.3:6"
    write_ods(cell / "schema-morsetti.ods", [(name, table)])
    kg = cadkg.build(cell / "manifest.toml")
    try:
        found = [f for f in cadkg.validate(kg, shacl=False) if f.check == "diagram-vs-list"]
    finally:
        kg.close()
    assert [(f.location, f.severity, f.message) for f in found] == [
        (
            f"schema-morsetti.ods:{row + 1}",
            "warning",
            "the terminal diagram puts =-Q1500.3:6 on X1500:1; no connection list has that wire",
        )
    ]
    assert original != "=-Q1500.3:6"
