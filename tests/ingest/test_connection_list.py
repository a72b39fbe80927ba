"""The connection-list reader: Figure 3, Lista cablaggio, machine exports and the malformed samples."""

from __future__ import annotations

import csv
import dataclasses
import io
from decimal import Decimal
from pathlib import Path

import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.eplan.connection_list import Connection, ConnectionListInfo, read_connection_list
from cadkg.ingest.eplan.labels import PinRef
from cadkg.ingest.text import decode_text

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "iema-switchgear"
FIG3 = EXAMPLE / "connections-fig3.tsv"
EXAMPLE_LISTA = EXAMPLE / "lista-cablaggio.csv"
# The example's list before it took gearbox_zero's shape: CRLF, a four-line preamble.
LISTA = REPO / "tests" / "data" / "iema-old-forms" / "lista-cablaggio.csv"
READERS = REPO / "tests" / "data" / "readers"

# Figure 3 in file order: wire number, section, potential type ('-' rows checked apart), length in m.
FIG3_WIRES = [
    ("1500.51", "0.75", "+", "0.746"),
    ("1500.53", "0.75", "+", "0.836"),
    ("1500.55", "0.75", "+", "0.926"),
    ("1500.50", "0.75", "+", "1.055"),
    ("1500.52", "0.75", "+", "1.005"),
    ("1500.54", "0.75", "+", "0.955"),
    ("1L+", "1", "+", None),
    ("0V", "1", "-", "0.32"),
    ("0V", "1", "-", "0.32"),
    ("1500.04", "1.5", "L", "0.394"),
    ("1500.05", "1.5", "L", "0.391"),
    ("1500.06", "1.5", "L", "0.387"),
    ("1500.10", "1.5", "L", "0.37"),
    ("1500.11", "1.5", "L", "0.366"),
    ("1500.12", "1.5", "L", "0.363"),
    ("1500.16", "1.5", "L", "0.345"),
    ("1500.17", "1.5", "L", "0.341"),
    ("1500.18", "1.5", "L", "0.338"),
    ("1500.01", "1.5", "L", "0.258"),
]
FIG3_HEADER = "\t".join(
    ["N. Pagina", "Zona", "Componente:pin"] * 2 + ["Numero filo", "Sezione", "Colore", "Tipo", "pot."]
)
LISTA_HEADER = (
    "N. Pagina\tZona\tComponente:pin\tN. Pagina\tZona\tComponente:pin\tNumero filo\tSezione\tColore\t"
    "Tipo pot.\tNome pot.\tL filo (m)\tTraccia collegamenti\tTerminazione Origine\tTerminazione Destinazione"
)


def split(records: list[ConnectionListInfo | Connection]) -> tuple[ConnectionListInfo, list[Connection]]:
    info, *rest = records
    assert isinstance(info, ConnectionListInfo)
    assert all(isinstance(c, Connection) for c in rest)
    return info, rest  # type: ignore[return-value]


@pytest.fixture(scope="module")
def fig3() -> tuple[ConnectionListInfo, list[Connection]]:
    return split(read_connection_list(FIG3))


@pytest.fixture(scope="module")
def lista() -> tuple[ConnectionListInfo, list[Connection]]:
    return split(read_connection_list(LISTA))


def pin(raw: str, component: str, name: str, level: str | None = None) -> PinRef:
    return PinRef(component=component, pin=name, level=level, raw=raw)


def at_line(connections: list[Connection], line: int) -> Connection:
    (found,) = [c for c in connections if c.line == line]
    return found


# --- Figure 3 ----------------------------------------------------------------------------------------


def test_fig3_info(fig3) -> None:
    info, connections = fig3
    assert info == ConnectionListInfo(project=None, job=None, header_line=1)
    assert len(connections) == 19


def test_fig3_first_row_exact(fig3) -> None:
    _, connections = fig3
    assert connections[0] == Connection(
        index=1,
        line=2,
        origin=pin("-F1500.1:14", "F1500.1", "14"),
        destination=pin("-Q1500.1:A1", "Q1500.1", "A1"),
        wire_number="1500.51",
        section_mm2=Decimal("0.75"),
        colour="BU",
        potential_type="+",
        potential_name=None,
        length_m=Decimal("0.746"),
        duct_path=(),
        origin_termination=None,
        destination_termination=None,
        origin_page="+1500/1.2",
        origin_zone="Q",
        destination_page="+1500/1.2",
        destination_zone="Q",
    )


def test_fig3_terminal_level_pin_and_missing_length(fig3) -> None:
    _, connections = fig3
    row = at_line(connections, 8)
    assert row.index == 7
    assert row.origin == pin("-X0030.1:1L+.2:a2", "X0030.1", "1L+.2", "a2")
    assert row.origin.key == "X0030.1:1L+.2:a2"
    assert row.destination == pin("-X1600:1:a", "X1600", "1", "a")
    assert row.wire_number == "1L+"
    assert row.section_mm2 == Decimal("1")
    assert row.length_m is None
    assert (row.origin_page, row.destination_page) == ("+0030/1.2", "+1600/1.1")


def test_fig3_order_is_file_order(fig3) -> None:
    _, connections = fig3
    assert [c.index for c in connections] == list(range(1, 20))
    assert [c.line for c in connections] == list(range(2, 21))
    lines = FIG3.read_text(encoding="utf-8").splitlines()
    assert [c.wire_number for c in connections] == [lines[c.line - 1].split("\t")[6] for c in connections]
    assert [c.wire_number for c in connections] == [w for w, *_ in FIG3_WIRES]


def test_fig3_values_of_every_row(fig3) -> None:
    _, connections = fig3
    got = [
        (c.wire_number, c.section_mm2, c.length_m, c.colour, c.origin_zone, c.destination_zone)
        for c in connections
    ]
    expected = [
        (w, Decimal(s), None if m is None else Decimal(m), "BU" if s != "1.5" else "BK", "Q", "Q")
        for w, s, _, m in FIG3_WIRES
    ]
    assert got == expected
    assert all(c.potential_name is None and c.duct_path == () for c in connections)


def test_fig3_potential_types_other_than_minus(fig3) -> None:
    _, connections = fig3
    assert [(c.line, c.potential_type) for c in connections if c.wire_number != "0V"] == [
        (i + 2, t) for i, (w, _, t, _) in enumerate(FIG3_WIRES) if w != "0V"
    ]


@pytest.mark.parametrize(
    ("path", "lines"),
    [
        (FIG3, [9, 10]),
        (
            LISTA,
            [13, 14, 37, 38, 40, 61, 63, 65, 66, 68, 70, 83, 84, 85, 98, 103, 104, 106, 108, 112, 113, 115],
        ),
    ],
    ids=["fig3", "lista"],
)
def test_minus_potential_type_is_kept(path: Path, lines: list[int]) -> None:
    _, connections = split(read_connection_list(path))
    assert [(c.line, c.potential_type) for c in connections if c.potential_type in {"-", None}] == [
        (line, "-") for line in lines
    ]


def test_fig3_daisy_chain_shares_a_pin(fig3) -> None:
    _, connections = fig3
    chain = [c for c in connections if c.wire_number == "0V"]
    assert [(c.line, c.origin.key, c.destination.key) for c in chain] == [
        (9, "Q1500.1:A2", "Q1500.2:A2"),
        (10, "Q1500.2:A2", "Q1500.3:A2"),
    ]


# --- Lista cablaggio ---------------------------------------------------------------------------------


def test_the_example_list_in_the_real_exports_shape(lista) -> None:
    data = EXAMPLE_LISTA.read_bytes()
    assert b"\r" not in data and data.startswith(b"\t\tNome Progetto:\tREMODEL_QE01\t")
    info, connections = split(read_connection_list(EXAMPLE_LISTA))
    assert info == ConnectionListInfo(project="REMODEL_QE01", job="24-0117", header_line=4)
    # The older form's wires, one line up, their duct paths written with gearbox_demo's ' for ;.
    old = [
        dataclasses.replace(c, line=c.line - 1, duct_text=c.duct_text and c.duct_text.replace(";", "'"))
        for c in lista[1]
    ]
    assert connections == old and [c.line for c in connections] == list(range(5, 115))
    assert at_line(connections, 8).duct_text == "=-CN2'=-CN5'=-CN3"


def test_lista_preamble_and_header(lista) -> None:
    info, connections = lista
    assert info == ConnectionListInfo(project="REMODEL_QE01", job="24-0117", header_line=5)
    assert len(connections) == 110
    assert [c.index for c in connections] == list(range(1, 111))
    assert [c.line for c in connections] == list(range(6, 116))


@pytest.mark.parametrize(
    ("line", "expected"),
    [
        (
            6,
            dict(
                index=1,
                origin=pin("=-F1500.1:14", "F1500.1", "14"),
                destination=pin("=-Q1500.1:A1", "Q1500.1", "A1"),
                wire_number="1500.51",
                section_mm2=Decimal("0.75"),
                colour="BU",
                potential_type="+",
                potential_name="24V",
                length_m=Decimal("0.746"),
                duct_path=("CN2",),
                origin_termination="PUNTALINO_vite",
                destination_termination="PUNTALINO_vite",
            ),
        ),
        (
            12,
            dict(
                index=7,
                origin=pin("=-X0030.1:1L+.2:a2", "X0030.1", "1L+.2", "a2"),
                destination=pin("=-X1600:1:a", "X1600", "1", "a"),
                wire_number="1L+",
                section_mm2=Decimal("1"),
                potential_name="24V",
                length_m=Decimal("1.112"),
                duct_path=("CN2", "CN5", "CN3"),
                origin_termination="ELETTROSALDATO_molla",
                destination_termination="ELETTROSALDATO_molla",
            ),
        ),
        (
            30,
            dict(
                index=25,
                origin=pin("=-Q0010:2", "Q0010", "2"),
                destination=pin("=-F0011.1:1", "F0011.1", "1"),
                wire_number="0010.01",
                section_mm2=Decimal("2.5"),
                colour="BK",
                potential_type="L",
                potential_name="L1",
                length_m=Decimal("0.412"),
                duct_path=("CN1",),
                origin_termination="CAPICORDA_vite",
                destination_termination="PUNTALINO_vite",
                origin_page="+0010/1.1",
                destination_page="+0011/1.1",
            ),
        ),
        (
            38,
            dict(
                index=33,
                origin=pin("=-X0030.2:1M.1:a2", "X0030.2", "1M.1", "a2"),
                destination=pin("=-Q1500.1:A2", "Q1500.1", "A2"),
                wire_number="0V",
                section_mm2=Decimal("1"),
                potential_name="0V",
                length_m=Decimal("0.474"),
                origin_termination="ELETTROSALDATO_molla",
                destination_termination="PUNTALINO_vite",
            ),
        ),
        (
            45,
            dict(
                index=40,
                wire_number="0040.02",
                section_mm2=Decimal("0.75"),
                colour="BU",
                potential_type="N",
                potential_name="N",
                length_m=Decimal("1.645"),
                duct_path=("CN1", "CN6", "CN4"),
                origin_termination="PUNTALINO_vite",
                destination_termination="ELETTROSALDATO_molla",
            ),
        ),
    ],
    ids=["line-6", "line-12", "line-30", "line-38", "line-45"],
)
def test_lista_rows_exact(lista, line: int, expected: dict[str, object]) -> None:
    _, connections = lista
    row = at_line(connections, line)
    assert {key: getattr(row, key) for key in expected} == expected


def test_lista_decimal_commas_and_units(lista) -> None:
    _, connections = lista
    sections = {c.section_mm2 for c in connections}
    assert sections == {Decimal("0.75"), Decimal("1"), Decimal("1.5"), Decimal("2.5")}
    assert all(isinstance(c.length_m, Decimal) and Decimal("0.1") < c.length_m < 2 for c in connections)
    assert at_line(connections, 34).length_m == Decimal("1.245")
    assert at_line(connections, 41).length_m == Decimal("1.480")


def test_lista_duct_paths_are_normalized_labels(lista) -> None:
    _, connections = lista
    assert at_line(connections, 9).duct_path == ("CN2", "CN5", "CN3")
    assert at_line(connections, 11).duct_path == ("CN2", "CN7", "CN3")
    assert at_line(connections, 42).duct_path == ("CN6", "CN2")
    ducts = {d for c in connections for d in c.duct_path}
    assert ducts == {f"CN{i}" for i in range(1, 10)}


def test_lista_terminations(lista) -> None:
    _, connections = lista
    pairs = {(c.origin_termination, c.destination_termination) for c in connections}
    assert pairs == {
        ("PUNTALINO_vite", "PUNTALINO_vite"),
        ("PUNTALINO_vite", "ELETTROSALDATO_molla"),
        ("ELETTROSALDATO_molla", "ELETTROSALDATO_molla"),
        ("ELETTROSALDATO_molla", "PUNTALINO_vite"),
        ("CAPICORDA_vite", "PUNTALINO_vite"),
        ("CAPICORDA_vite", "CAPICORDA_vite"),
    }


def test_lista_first_19_rows_are_figure_3(fig3, lista) -> None:
    _, f3 = fig3
    _, lc = lista

    def key(c: Connection) -> tuple[object, ...]:
        return (c.index, c.origin.key, c.destination.key, c.wire_number, c.section_mm2, c.colour)

    assert [key(c) for c in lc[:19]] == [key(c) for c in f3]
    # The README: L filo = pot./1000 for the Figure 3 rows (the 1L+ row has no pot.).
    assert [c.length_m for c in lc[:19] if c.wire_number != "1L+"] == [
        c.length_m for c in f3 if c.wire_number != "1L+"
    ]


# --- header matched by meaning -----------------------------------------------------------------------

# New position -> old column of Figure 3. Origin page/zone/pin stay before their destination twins.
SHUFFLE = [6, 10, 2, 8, 0, 5, 9, 1, 7, 3, 4]


def test_shuffled_columns_read_the_same_values(write, fig3) -> None:
    lines = FIG3.read_text(encoding="utf-8").splitlines()
    shuffled = ["\t".join(line.split("\t")[i] for i in SHUFFLE) for line in lines]
    assert shuffled[0].startswith("Numero filo\tpot.\tComponente:pin\tColore")
    path = write("shuffled.tsv", "\n".join(shuffled) + "\n")
    assert split(read_connection_list(path)) == fig3


def test_semicolon_delimited(write) -> None:
    text = (
        "Nome Progetto:;REMODEL_QE01\r\n"
        "commessa:;24-0117\r\n"
        "Componente:pin;Componente:pin;Numero filo;Sezione;Colore;L filo (m);Traccia collegamenti\r\n"
        '=-F1500.1:13;=-X1600:2:a;1500.50;0,75 mm²;BU;1,055 m;"=-U2;=-U5;=-U3"\r\n'
        "=-Q1500.1:2;=-X1500:1:a;1500.04;1,5 mm²;BK;0,394 m;=-U3\r\n"
    )
    info, connections = split(read_connection_list(write("semi.csv", text)))
    assert info == ConnectionListInfo(project="REMODEL_QE01", job="24-0117", header_line=3)
    assert [
        (
            c.index,
            c.line,
            c.origin.key,
            c.destination.key,
            c.wire_number,
            c.section_mm2,
            c.length_m,
            c.duct_path,
        )
        for c in connections
    ] == [
        (1, 4, "F1500.1:13", "X1600:2:a", "1500.50", Decimal("0.75"), Decimal("1.055"), ("U2", "U5", "U3")),
        (2, 5, "Q1500.1:2", "X1500:1:a", "1500.04", Decimal("1.5"), Decimal("0.394"), ("U3",)),
    ]


MACHINE_EXPORT = (
    '"Componente:\npin","N.\nPagina","Componente:\npin","Numero\nfilo","Sezione\n(mm²)","Colore",'
    '"Lunghezza\n(mm)"\n'
    '"-F1500.1:14","1","-Q1500.1:A1","1500.51","0,75","BU","746"\n'
    '"-F1500.2:14","1","-Q1500.2:A1","1500.53","0,75","BU","836"\n'
)


def test_machine_export_with_multi_line_header(write) -> None:
    info, connections = split(read_connection_list(write("export.csv", MACHINE_EXPORT)))
    # The header starts on line 1 and, with six quoted line breaks, ends on line 7.
    assert info.header_line == 1
    assert [(c.index, c.line) for c in connections] == [(1, 8), (2, 9)]
    first = connections[0]
    assert (first.origin.key, first.destination.key, first.wire_number) == (
        "F1500.1:14",
        "Q1500.1:A1",
        "1500.51",
    )
    assert (first.section_mm2, first.colour, first.length_m) == (Decimal("0.75"), "BU", Decimal("0.746"))
    assert first.origin_page == "1"
    assert connections[1].length_m == Decimal("0.836")


def test_machine_export_error_after_multi_line_header_is_located(write) -> None:
    text = MACHINE_EXPORT + '"-F1500.3:14","1","-Q1500.3:A1","1500.55","0,75","BU","zero"\n'
    with pytest.raises(IngestError) as info:
        read_connection_list(write("export-bad.csv", text))
    err = info.value
    assert (err.line, err.found) == (10, "zero")
    assert "not a number in column 'Lunghezza (mm)'" in err.reason


def test_quoted_line_break_in_a_data_cell_shifts_later_lines(write) -> None:
    text = (
        "Componente:pin\tComponente:pin\tNumero filo\tSezione\tColore\n"
        '-F1500.1:14\t-Q1500.1:A1\t1500.51\t0.75\t"BU\nsee note"\n'
        "-F1500.2:14\t-Q1500.2:A1\t1500.53\t0.75\tBU\n"
    )
    _, connections = split(read_connection_list(write("note.tsv", text)))
    assert [(c.line, c.colour) for c in connections] == [(2, "BU\nsee note"), (4, "BU")]


def test_a_stray_quote_that_swallows_the_row_is_named(write) -> None:
    text = (
        "Componente:pin\tComponente:pin\tNumero filo\tSezione\tColore\n"
        "-F1500.1:14\t-Q1500.1:A1\t1500.51\t0.75\tBU\n"
        '"-F1500.2:14\t-Q1500.2:A1\t1500.53\t0.75\tBU\n'
        "-F1500.3:14\t-Q1500.3:A1\t1500.55\t0.75\tBU\n"
    )
    with pytest.raises(IngestError) as info:
        read_connection_list(write("quote.tsv", text))
    err = info.value
    assert (err.line, err.reason) == (3, "a cell opened with '\"' runs over the cells after it")
    assert err.found == "-F1500.2:14\t-Q1500.2:A1\t1500.53\t0.75\tBU ..."
    # A row merely short of its wire number is still called what it is.
    with pytest.raises(IngestError, match="empty cell in column 'Numero filo'"):
        short = text.replace('"-F1500.2:14\t-Q1500.2:A1\t1500.53\t0.75\tBU', "a\tb")
        read_connection_list(write("short.tsv", short))


@pytest.mark.parametrize(
    ("cell", "column", "expected_m"),
    [("746", "L filo (mm)", "0.746"), ("746 mm", "L filo (m)", "0.746"), ("0,746 m", "L filo (mm)", "0.746")],
)
def test_length_units(write, cell: str, column: str, expected_m: str) -> None:
    text = (
        f"Componente:pin\tComponente:pin\tNumero filo\tSezione\tColore\t{column}\n"
        f"-F1500.1:14\t-Q1500.1:A1\t1500.51\t0.75\tBU\t{cell}\n"
    )
    _, (row,) = split(read_connection_list(write("len.tsv", text)))
    assert row.length_m == Decimal(expected_m)


# --- malformed samples -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "line", "reason", "found"),
    [
        (
            "conn-bad-pin.tsv",
            3,
            "unknown pin reference in column 'Componente:pin': no ':' between device and pin",
            "F1500.1-14",
        ),
        ("conn-bad-section.tsv", 4, "not a number in column 'Sezione'", "abc"),
        ("conn-binary.csv", 1, "binary content (NUL byte at offset 4)", None),
        ("conn-empty.tsv", 1, "no connections after the header", None),
        ("conn-missing-column.tsv", 1, "missing column 'Numero filo'", FIG3_HEADER.replace("\t", ", ")),
        ("conn-wrong-delimiter.csv", 1, "no header row found in the first lines", None),
    ],
)
def test_malformed_sample_is_a_located_error(name: str, line: int, reason: str, found: str | None) -> None:
    with pytest.raises(IngestError) as info:
        read_connection_list(READERS / name)
    err = info.value
    assert err.path is not None and err.path.endswith(name)
    assert err.line == line
    assert err.reason == reason
    if name == "conn-missing-column.tsv":
        assert err.found == found.replace("Numero filo, ", "")  # type: ignore[union-attr]
    else:
        assert err.found == found
    assert f"{name}:{line}: {reason}" in str(err)


def test_bom_sample_reads_like_figure_3(fig3) -> None:
    info, connections = split(read_connection_list(READERS / "conn-bom.tsv"))
    assert info == ConnectionListInfo(None, None, 1)
    assert connections == fig3[1][:3]


def test_latin1_sample_warns_and_reads_values() -> None:
    path = READERS / "conn-latin1.csv"
    with pytest.warns(
        IngestWarning, match=r"not UTF-8 \(first invalid byte 0xb2\); read as Windows-1252"
    ) as rec:
        info, connections = split(read_connection_list(path))
    warning = next(w.message for w in rec if isinstance(w.message, IngestWarning))
    assert warning.path is not None and warning.path.endswith("conn-latin1.csv")
    assert warning.line == 6
    assert info == ConnectionListInfo(project="REMODEL_QE01", job="24-0117", header_line=5)
    assert [(c.line, c.wire_number, c.section_mm2, c.length_m, c.potential_name) for c in connections] == [
        (6, "1500.51", Decimal("0.75"), Decimal("0.746"), "24V"),
        (7, "1500.53", Decimal("0.75"), Decimal("0.836"), "24V"),
        (8, "1500.55", Decimal("0.75"), Decimal("0.926"), "24V"),
    ]
    with pytest.warns(IngestWarning):
        text = decode_text(path, path.read_bytes(), expected="x")
    assert "\t0,75 mm²\t" in text


# --- inline row errors -------------------------------------------------------------------------------


def _one_row(cells: dict[str, str]) -> str:
    header = ["Componente:pin", "Componente:pin", "Numero filo", "Sezione", "Colore"]
    row = {"o": "-F1500.1:14", "d": "-Q1500.1:A1", "w": "1500.51", "s": "0.75", "c": "BU"} | cells
    good = "-F1500.2:14\t-Q1500.2:A1\t1500.53\t0.75\tBU"
    return "\t".join(header) + "\n" + good + "\n" + "\t".join(row[k] for k in "odwsc") + "\n"


@pytest.mark.parametrize(
    ("cells", "reason"),
    [
        ({"o": ""}, "empty cell in column 'Componente:pin'"),
        ({"d": "-"}, "empty cell in column 'Componente:pin'"),
        ({"w": ""}, "empty cell in column 'Numero filo'"),
        ({"s": "0"}, "non-positive value in column 'Sezione'"),
        ({"s": "-1,5"}, "non-positive value in column 'Sezione'"),
        ({"s": "nan"}, "not a number in column 'Sezione'"),
        (
            {"d": "-Q1500.1:A1:x:y"},
            "unknown pin reference in column 'Componente:pin': more than DEVICE:PIN:LEVEL",
        ),
    ],
    ids=[
        "empty-origin",
        "dash-destination",
        "empty-wire",
        "zero-section",
        "negative-section",
        "nan",
        "4-parts",
    ],
)
def test_bad_cell_is_located_on_its_line(write, cells: dict[str, str], reason: str) -> None:
    with pytest.raises(IngestError) as info:
        read_connection_list(write("row.tsv", _one_row(cells)))
    assert info.value.line == 3
    assert info.value.reason == reason


def test_header_after_40_rows_is_not_found(write) -> None:
    text = "x\n" * 40 + LISTA_HEADER + "\n" + "\t".join(["a"] * 15) + "\n"
    with pytest.raises(IngestError) as info:
        read_connection_list(write("late.tsv", text))
    assert info.value.reason == "no header row found in the first lines"


@pytest.mark.parametrize(
    ("length_column", "section", "length"),
    [
        ("L filo (mm)", "0,75", "746 mm²"),
        ("L filo (m)", "0,75", "0,746 mm2"),
        ("L filo (m)", "0,75 m", "0,746 m"),
    ],
    ids=["length-in-mm2", "length-in-mm2-ascii", "section-in-m"],
)
def test_unit_of_the_wrong_kind_is_an_error(write, length_column: str, section: str, length: str) -> None:
    text = (
        f"Componente:pin\tComponente:pin\tNumero filo\tSezione\tColore\t{length_column}\n"
        f"-F1500.1:14\t-Q1500.1:A1\t1500.51\t{section}\tBU\t{length}\n"
    )
    with pytest.raises(IngestError) as info:
        read_connection_list(write("unit.tsv", text))
    assert info.value.line == 2
    assert info.value.found in {section, length}


# --- Komax machine export ----------------------------------------------------------------------------

KOMAX = READERS / "komax-sample.csv"
KOMAX_PREAMBLE_LINES = 6  # five option rows and a blank line before the header
KOMAX_DEST_PIN = 17  # 0-based column of "Componente:pin\ndestinazione"


@pytest.fixture(scope="module")
def komax() -> tuple[ConnectionListInfo, list[Connection]]:
    return split(read_connection_list(KOMAX))


def _komax_table() -> tuple[str, list[list[str]]]:
    text = KOMAX.read_text(encoding="utf-8")
    preamble = "".join(text.splitlines(keepends=True)[:KOMAX_PREAMBLE_LINES])
    return preamble, list(csv.reader(io.StringIO(text[len(preamble) :], newline=""), delimiter=";"))


def _komax_text(preamble: str, rows: list[list[str]]) -> str:
    out = io.StringIO(newline="")
    csv.writer(out, delimiter=";", lineterminator="\r\n").writerows(rows)
    return preamble + out.getvalue()


def test_komax_header_spans_lines_and_rows_start_after_it(komax) -> None:
    info, connections = komax
    # 16 header cells hold a line break, so the header starting on line 7 ends on line 23.
    assert info == ConnectionListInfo(project="QE01_CABLAGGIO", job=None, header_line=7)
    assert [(c.index, c.line) for c in connections] == [(i, i + 23) for i in range(1, 11)]


def test_komax_first_row_exact(komax) -> None:
    _, connections = komax
    assert connections[0] == Connection(
        index=1,
        line=24,
        origin=pin("=-F1500.1:14", "F1500.1", "14"),
        destination=pin("=-Q1500.1:A1", "Q1500.1", "A1"),
        wire_number="1500.51",
        section_mm2=Decimal("0.75"),
        colour="BU",
        potential_type="+",
        potential_name="24V",
        length_m=Decimal("0.746"),
        duct_path=("U2",),
        origin_termination="PUNTALINO_vite",
        destination_termination="PUNTALINO_vite",
        origin_page="+1500/1.2",
        origin_zone="Q",
        destination_page="+1500/1.2",
        destination_zone="Q",
        cable_name="W001",
        job_key="QE01-0001",
        origin_direction="Verso l'alto",
        destination_direction="Verso l'alto",
        bundling_side="Origine",
        duct_text="=-U2",
    )


def test_komax_values_by_row(komax) -> None:
    _, connections = komax
    assert [c.job_key for c in connections] == [f"QE01-{i:04d}" for i in range(1, 11)]
    assert [c.length_m for c in connections] == [
        Decimal(m)
        for m in ("0.746", "0.836", "0.926", "1.055", "1.005", "0.955", "1.112", "0.32", "0.32", "0.394")
    ]
    assert [c.section_mm2 for c in connections] == [Decimal("0.75")] * 6 + [Decimal("1")] * 3 + [
        Decimal("1.5")
    ]
    assert [c.bundling_side for c in connections] == ["Origine"] * 3 + ["Destinazione"] * 3 + [None] * 3 + [
        "Origine"
    ]
    row = at_line(connections, 27)
    assert (row.origin_direction, row.destination_direction) == (
        "Verso l'alto, verso sinistra",
        "Verso il basso",
    )
    assert (row.origin.key, row.destination.key, row.duct_path) == (
        "F1500.1:13",
        "X1600:2:a",
        ("U2", "U5", "U3"),
    )
    assert (row.origin_termination, row.destination_termination) == ("PUNTALINO_vite", "ELETTROSALDATO_molla")
    assert at_line(connections, 30).origin.key == "X0030.1:1L+.2:a2"


def test_komax_columns_are_found_by_meaning(komax) -> None:
    shuffled = READERS / "komax-shuffled.csv"
    header = shuffled.read_text(encoding="utf-8").splitlines()[KOMAX_PREAMBLE_LINES]
    assert header.startswith("Marcatura destinazione;")
    assert split(read_connection_list(shuffled)) == komax


def test_komax_in_windows_1252_reads_the_same(write, komax) -> None:
    data = KOMAX.read_text(encoding="utf-8").encode("cp1252")
    with pytest.warns(IngestWarning, match="read as Windows-1252"):
        assert split(read_connection_list(write("komax-1252.csv", data))) == komax


def test_komax_bad_length_is_located_on_the_physical_line(write) -> None:
    preamble, rows = _komax_table()
    rows[1][-1] = "ritardo\nsul fascio"  # a note with a line break on line 24 shifts the rows after it
    rows[4][7] = "mille"
    with pytest.raises(IngestError) as info:
        read_connection_list(write("komax-bad.csv", _komax_text(preamble, rows)))
    err = info.value
    assert (err.line, err.found) == (28, "mille")
    assert err.reason == "not a number in column 'Lunghezza (mm)'"


def test_komax_missing_destination_pin_column_names_what_was_found(write) -> None:
    preamble, rows = _komax_table()
    for row in rows:
        del row[KOMAX_DEST_PIN]
    with pytest.raises(IngestError) as info:
        read_connection_list(write("komax-no-pin.csv", _komax_text(preamble, rows)))
    err = info.value
    assert (err.line, err.reason) == (7, "missing column 'Componente:pin (destination)'")
    assert err.found is not None
    # Line breaks inside header cells are folded so the message stays on one line.
    assert err.found.startswith("Chiave job, Nome cavo, Numero filo, Sezione (mm²), Colore")
    assert "Componente:pin origine, Terminazione origine" in err.found


def test_english_per_end_headers_in_any_order(write) -> None:
    text = (
        "Direction destination\tComponent:pin destination\tWire number\tSection\tColour\t"
        "Component:pin origin\tDirection origin\tLength (mm)\n"
        "down\t-Q1500.1:A1\t1500.51\t0.75\tBU\t-F1500.1:14\tup\t746\n"
    )
    _, (row,) = split(read_connection_list(write("english.tsv", text)))
    assert (row.origin.key, row.destination.key) == ("F1500.1:14", "Q1500.1:A1")
    assert (row.origin_direction, row.destination_direction, row.length_m) == ("up", "down", Decimal("0.746"))
