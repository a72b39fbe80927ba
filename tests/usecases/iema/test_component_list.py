"""The component list reader: Figure 4's rows, the embedded XML, and located errors."""

from __future__ import annotations

from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.ingest.placement import Placement
from cadkg.registry import sniff_kind
from cadkg.usecases.iema.component_list import (
    ComponentListEntry,
    looks_like_component_list,
    read_component_list,
)
from tests.conftest import ROOT

REPO = ROOT
READERS = REPO / "tests" / "data" / "readers"
FIG4 = READERS / "component-list-fig4.tsv"
EXAMPLE = REPO / "examples" / "iema-switchgear"

HEADER = "Component ID\tDescription\tPart Number\tQuantity\tXML Data\n"
XML_ONE_LINE = (
    '<pre> <data> <code name="M1" xdim="0.01" ydim="0.02" zdim="0.03" > <couple name="1"> '
    '<subitem name="screw"> <pos name="x">0.1</pos> <pos name="y">0.2</pos> <pos name="z">0.3</pos> '
    '<rot name="R">0</rot> <rot name="P">0</rot> <rot name="Y">0</rot> </subitem> </couple> '
    "</code> </data> </pre>"
)


@pytest.fixture(scope="module")
def fig4() -> list[ComponentListEntry]:
    return read_component_list(FIG4)


def test_figure_4_first_row_and_its_model(fig4: list[ComponentListEntry]) -> None:
    first = fig4[0]
    assert (first.label, first.raw_id, first.description, first.part_number, first.quantity, first.line) == (
        "SSB-20B4",
        "-SSB-20B4",
        "ZONE OPENED",
        "IFM IGS232",
        1,
        2,
    )
    (model,) = first.models
    assert (model.code, model.commercial, model.role) == ("SIEMENS 5SL4202-8", "SIEMENS 5SL4202-8", None)
    assert model.dimensions == (0.0898, 0.0359, 0.07448)
    one, two = model.couples
    assert one.name == "1"
    assert one.screw == Placement(xyz=(0.0085, 0.009, 0.04496), rpy=(0.0, 0.0, 0.0), line=2, moving_axes=True)
    assert one.hole == Placement(xyz=(0.0, 0.0, 0.0), rpy=(0.0, 0.0, 0.0), line=2, moving_axes=True)
    assert two.screw is not None and two.screw.xyz == (0.0265, 0.009, 0.04496)


def test_figure_4_rows_in_order(fig4: list[ComponentListEntry]) -> None:
    assert len(fig4) == 20
    assert [e.line for e in fig4] == list(range(2, 22))
    assert all(e.models == () for e in fig4[1:])
    assert [e.part_number for e in fig4 if e.label == "SSB-10F1"] == ["PILZ.772000", "6402292", "6402293"]
    assert [(e.part_number, e.quantity) for e in fig4 if e.label == "SSB-75G2"] == [
        ("TUBO ARIA 6/4", 10),
        ("GUAINA D.23 66", 8),
    ]
    assert fig4[-1] == ComponentListEntry(
        label="SSB-10KA3",
        raw_id="-SSB-10KA3",
        description="LASER ENABLE",
        part_number="6400168",
        quantity=1,
        models=(),
        line=21,
    )


def test_italian_header_semicolons_and_xml_over_several_lines(write) -> None:
    xml = XML_ONE_LINE.replace("> <", ">\n<")
    text = (
        "Distinta;QE01\n"
        "Codice componente;Descrizione;Codice articolo;Quantità;Dati XML\n"
        f'=-Q1500.1;"CONTATTORE\nAUSILIARIO";SIE.3RT2015-1BB41;2;"{xml.replace(chr(34), chr(34) * 2)}"\n'
        "-K0060.1;RELE SICUREZZA;PILZ.750104;;\n"
    )
    first, second = read_component_list(write("distinta.csv", text))
    assert (first.label, first.raw_id, first.description, first.quantity, first.line) == (
        "Q1500.1",
        "=-Q1500.1",
        "CONTATTORE\nAUSILIARIO",
        2,
        3,
    )
    (model,) = first.models
    # The description's line break puts the XML's first line on line 4; <code> is its 3rd line.
    assert model.line == 6
    assert model.couples[0].screw is not None and model.couples[0].screw.xyz == (0.1, 0.2, 0.3)
    assert (second.label, second.quantity, second.models, second.line) == (
        "K0060.1",
        None,
        (),
        5 + xml.count("\n"),
    )


def test_error_inside_the_xml_cell_names_the_row_line(write) -> None:
    text = HEADER + "-A1\tX\tP1\t1\t\n" + f"-A2\tY\tP2\t1\t{XML_ONE_LINE.replace('0.2', 'zero')}\n"
    with pytest.raises(IngestError) as info:
        read_component_list(write("list.tsv", text))
    err = info.value
    assert (err.line, err.found) == (3, "zero")
    assert err.reason == (
        "in column 'XML Data': not a finite number in <pos name='y'> of subitem 'screw' "
        "of couple '1' of model 'M1'"
    )


def test_xml_syntax_error_on_a_later_line_of_the_cell(write) -> None:
    xml = XML_ONE_LINE.replace("> <", ">\n<").replace("</couple>", "</coupl>")
    text = HEADER + f'-A1\tX\tP1\t1\t"{xml.replace(chr(34), chr(34) * 2)}"\n'
    with pytest.raises(IngestError) as info:
        read_component_list(write("list.tsv", text))
    lines_before = xml[: xml.index("</coupl>")].count("\n")
    assert info.value.line == 2 + lines_before
    assert info.value.reason.startswith("in column 'XML Data': malformed XML: ")


@pytest.mark.parametrize("quantity", ["1,0", "abc", "-1", "0", "1.5", "99999999999"])
def test_quantity_must_be_a_positive_integer(write, quantity: str) -> None:
    text = HEADER + "-A1\tX\tP1\t1\t\n" + f"-A2\tY\tP2\t{quantity}\t\n"
    with pytest.raises(IngestError) as info:
        read_component_list(write("list.tsv", text))
    err = info.value
    assert (err.line, err.found, err.reason) == (3, quantity, "not a positive integer in column 'Quantity'")


@pytest.mark.parametrize("raw_id", ["", "-", "=-"])
def test_empty_component_id(write, raw_id: str) -> None:
    with pytest.raises(IngestError) as info:
        read_component_list(write("list.tsv", HEADER + f"{raw_id}\tY\tP2\t1\t\n"))
    assert (info.value.line, info.value.reason) == (2, "empty cell in column 'Component ID'")


def test_missing_part_number_and_xml_columns(write) -> None:
    with pytest.raises(IngestError) as info:
        read_component_list(write("list.tsv", "Component ID\tDescription\tQuantity\n-A1\tX\t1\n"))
    err = info.value
    assert (err.line, err.reason, err.found) == (
        1,
        "missing column 'Part Number' or 'XML Data'",
        "Component ID, Description, Quantity",
    )


@pytest.mark.parametrize(
    ("text", "line", "reason"),
    [
        ("Label\tPart\n-A1\tP1\n", 1, "no header row found in the first lines"),
        (HEADER + "\n\n", 1, "no rows after the header"),
        ("x\n" * 40 + HEADER + "-A1\tX\tP1\t1\t\n", 1, "no header row found in the first lines"),
    ],
    ids=["no-header", "no-rows", "header-too-late"],
)
def test_structure_errors(write, text: str, line: int, reason: str) -> None:
    with pytest.raises(IngestError) as info:
        read_component_list(write("list.tsv", text))
    assert (info.value.line, info.value.reason) == (line, reason)


# --- sniffing among the three CSV kinds ---------------------------------------------------------------

CSV_SAMPLES = [
    (FIG4, "component-list"),
    (READERS / "terminal-schema.csv", "terminal-schema"),
    (READERS / "komax-sample.csv", "connection-list"),
    (EXAMPLE / "lista-cablaggio.csv", "connection-list"),
    (EXAMPLE / "connections-fig3.tsv", "connection-list"),
]
# A terminal schema is not claimed by .tsv; .dat is claimed by no reader, so every sniffer runs.
SNIFF_CASES = [
    (sample, kind, suffix)
    for sample, kind in CSV_SAMPLES
    for suffix in (".csv", ".tsv", ".dat")
    if not (kind == "terminal-schema" and suffix == ".tsv")
]


@pytest.mark.parametrize(
    ("sample", "kind", "suffix"), SNIFF_CASES, ids=[f"{p.name}-as{s}" for p, _, s in SNIFF_CASES]
)
def test_each_csv_sample_sniffs_as_one_kind(tmp_path: Path, sample: Path, kind: str, suffix: str) -> None:
    path = tmp_path / f"input{suffix}"
    path.write_bytes(sample.read_bytes())
    assert sniff_kind(path) == kind


def test_sniff_needs_the_component_id_beside_the_part_number() -> None:
    assert looks_like_component_list(b'"Codice componente";Descrizione;"Codice articolo"\n')
    assert not looks_like_component_list(b"Terminal block;Position;Terminal;Cad ID;Part number;Levels\n")
    assert not looks_like_component_list(b"Component ID\tDescription\n")
