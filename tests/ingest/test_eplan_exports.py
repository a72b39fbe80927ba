"""EPLAN's own exports in the shapes the cell's real files have: parts management, labelling XML,
connection lists as workbooks and Komax lists, bills of materials. Small files of our own."""

from __future__ import annotations

import math
import warnings
from decimal import Decimal
from pathlib import Path

import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.eplan.bill_of_materials import BomInfo, BomLine, read_bill_of_materials
from cadkg.ingest.eplan.connection_files import read_connections
from cadkg.ingest.eplan.connection_list import (
    UNKNOWN_END,
    Connection,
    ConnectionListInfo,
    read_connection_list,
)
from cadkg.ingest.eplan.labels import PinRef, parse_pin_ref
from cadkg.ingest.eplan.parts import read_parts_management
from cadkg.registry import sniff_kind
from tests.ingest.workbooks import write_ods, write_xlsx

# --- parts management ---------------------------------------------------------------------------------

POINT = (
    ' <terminalPosition additionallength="0" {extra}direction="{code}" level="0" name="{name}" pos="{pos}"'
    ' typeofterminal="1" xdir="{dx}" xpos="{x}" ydir="{dy}" ypos="{y}" zdir="{dz}" zpos="{z}"/>'
)


def _pins(*parts: str) -> bytes:
    body = "\r\n".join(parts)
    return (
        '<?xml version="1.0" encoding="utf-8" ?>\n'
        '<partsmanagement count="2" length-unit="mm" type="EPLAN.PartsManagement" build="1.0">\r\n'
        f"{body}\r\n</partsmanagement>\r\n"
    ).encode()


def _point(name: str, pos: int, xyz: str, d: str, code: int = 1, extra: str = "") -> str:
    x, y, z = xyz.split()
    dx, dy, dz = d.split()
    return POINT.format(name=name, pos=pos, x=x, y=y, z=z, dx=dx, dy=dy, dz=dz, code=code, extra=extra)


CONTACTOR = " ".join(
    [
        ' <terminal P_PART_TERMINAL_NAME="6100003" P_PART_TERMINAL_CREATE="u / 01.02.2026 10:00:00">\r\n',
        _point("A1", 1, "5.3 46.75 57", "0 1 0") + "\r\n",
        _point("A2", 2, "5.3 10.75 57", "0 -1 0", code=2) + "\r\n",
        _point("13", 3, "40 20 60", "0 0 1") + "\r\n",
        ' <attributeposition pos="1" P_ARTICLE_ATTRIBUTE_VALUE="Acme"/>\r\n </terminal>',
    ]
)
SUPPLY = (
    ' <terminal P_PART_TERMINAL_NAME="ACME.PSU">\r\n'
    + _point("L", 1, "31.5 65 102.5", "0 0 1", 3, 'devicetag="XI" ')
    + "\r\n"
    + _point("L", 2, "31.5 10 102.5", "0 0 1", 4, 'devicetag="XO" ')
    + "\r\n </terminal>"
)


def test_parts_management_points_in_metres_with_the_wire_entry_as_z(tmp_path: Path) -> None:
    path = tmp_path / "cabinet_pins.xml"
    path.write_bytes(_pins(CONTACTOR, SUPPLY))
    assert sniff_kind(path) == "parts-management"
    with pytest.warns(IngestWarning) as caught:
        contactor, supply = read_parts_management(path)
    assert contactor.part == "6100003" and contactor.dimensions is None
    a1, a2, thirteen = contactor.points
    assert a1.name == "A1" and a1.position == pytest.approx((0.0053, 0.04675, 0.057))
    # z along +y: x stays the X axis (z has no x part), y = z × x = -Z. A quarter turn about X.
    assert a1.direction == (0.0, 1.0, 0.0)
    assert a1.orientation == pytest.approx((-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)))
    assert a2.orientation == pytest.approx((math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5)))
    assert thirteen.orientation == pytest.approx((0.0, 0.0, 0.0, 1.0))
    assert (a1.direction_code, a2.direction_code, a1.level) == ("1", "2", "0")
    # A name a part gives twice (input and output) keeps both points.
    assert [(p.name, p.written_name, p.device_tag) for p in supply.points] == [
        ("L", "L", "XI"),
        ("L~2", "L", "XO"),
    ]
    messages = [str(w.message) for w in caught]
    assert f"{path}:7: unknown element <attributeposition> inside <terminal> skipped" in messages
    assert any("names connection point 'L' 2 times" in m for m in messages)


@pytest.mark.parametrize(
    ("body", "line", "reason"),
    [
        (' <terminal P_PART_TERMINAL_NAME="">\r\n </terminal>', 3, "<terminal> without a part number"),
        (
            ' <terminal P_PART_TERMINAL_NAME="P1">\r\n'
            + _point("1", 1, "1 2 x", "0 0 1")
            + "\r\n </terminal>",
            4,
            "not a number in zpos of connection point '1'",
        ),
        (
            ' <terminal P_PART_TERMINAL_NAME="P1">\r\n'
            + _point("1", 1, "1 2 3", "0 0 0")
            + "\r\n </terminal>",
            4,
            "connection point '1' of part 'P1' has no wire entry direction",
        ),
        (
            ' <terminal P_PART_TERMINAL_NAME="P1">\r\n'
            + _point("1", 1, "1 2 3", "0 0 1").replace(' zpos="3"', "")
            + "\r\n </terminal>",
            4,
            "connection point '1' of part 'P1' lacks zpos",
        ),
    ],
    ids=["no-part-number", "not-a-number", "zero-direction", "missing-zpos"],
)
def test_parts_management_errors_are_located(tmp_path: Path, body: str, line: int, reason: str) -> None:
    path = tmp_path / "pins.xml"
    path.write_bytes(_pins(body))
    with pytest.raises(IngestError) as info:
        read_parts_management(path)
    assert (info.value.line, info.value.reason) == (line, reason)


def test_parts_management_part_variant_and_length_unit(tmp_path: Path) -> None:
    body = (
        ' <part P_PART_TERMINAL_NAME="6100003" xdim="45.0" ydim="57.5" zdim="73.0">\r\n'
        + _point("1", 1, "5.3 46.75 57", "0 0 1").replace("terminalPosition", "terminal")[:-2]
        + ">\r\n  <screw name='1'><pose>5.3 10.5 73.0 0 3.14 0</pose></screw>\r\n </terminal>\r\n </part>"
    )
    path = tmp_path / "parts.xml"
    path.write_bytes(_pins(body).replace(b'length-unit="mm"', b'length-unit="cm"'))
    with warnings.catch_warnings(record=True):
        warnings.simplefilter("always")
        (part,) = read_parts_management(path)
    assert part.dimensions == pytest.approx((0.45, 0.575, 0.73))
    assert part.points[0].position == pytest.approx((0.053, 0.4675, 0.57))


# --- EPLAN labelling XML --------------------------------------------------------------------------------

_PROPERTY = (
    '<Property FormattingType="0" FormattingLength="32" FormattingRAlign="1">'
    "<PropertyName>{}</PropertyName>{}</Property>"
)


def _labelling(header: dict[str, str], columns: list[str], lines: list[list[str]]) -> bytes:
    def prop(name: str, value: str) -> str:
        return _PROPERTY.format(
            name, f"<PropertyValue>{value}</PropertyValue>" if value else "<PropertyValue/>"
        )

    parts = ['<EplanLabelling version="1.0"><Document source_id="1"><Page source_id="1"><Header>']
    parts += [prop(k, v) for k, v in header.items()]
    parts.append("</Header>")
    parts += [
        f'<ColumnHeader DataType="Text"><PropertyName>{c}</PropertyName></ColumnHeader>' for c in columns
    ]
    for n, line in enumerate(lines, start=1):
        parts.append(f'<Line source_id="{n}" separator=";"><Label source_id="{n}">')
        parts += [prop(c, v) for c, v in zip(columns, line, strict=True)]
        parts.append("</Label></Line>")
    parts.append("<Footer/></Page></Document></EplanLabelling>")
    # One physical line after the declaration, as EPLAN writes it.
    return ('<?xml version="1.0" encoding="utf-8"?>\r\n' + "".join(parts) + "\r\n").encode()


WIRING_COLUMNS = [
    "Nome pagina (completo)",
    "Zona di montaggio (descrittiva)",
    "Nome attacco di destinazione (completo)",
    "Nome pagina (completo)",
    "Zona di montaggio (descrittiva)",
    "Nome attacco di destinazione (completo)",
    "Designazione collegamenti",
    "Sezione / Diametro collegamento",
    "Colore/numero collegamento",
    "Tipo potenziale",
    "Nome potenziale",
    "Lunghezza (completa)",
    "Ambiente 3D: traccia dei collegamenti",
    "Origine tipo di terminazione filo",
    "Destinazione tipo di terminazione filo",
    "SEF (completa)",
]
WIRE = ["+1500/1.2", "Q", "=-F1500.1:14", "+1500/1.2", "Q", "=-Q1500.1:A1", "1500.51", "0,75", "BU", "+"]
WIRE += ["24VDC", "2,00", "=-U4;=-U5", "ELETTROSALDATO_molla", "", "="]


def test_labelling_connection_list(tmp_path: Path) -> None:
    path = tmp_path / "cabinet_wiring.xml"
    second = [*WIRE]
    second[2], second[5], second[6], second[7] = "=-X1600:2:a", "=-Q1500.1:A2", "1500.52", "2.5"
    header = {"Nome progetto": "PROGETTO DEMO", "Commessa": "24-0117"}
    path.write_bytes(_labelling(header, WIRING_COLUMNS, [WIRE, second]))
    assert sniff_kind(path) == "connection-list"
    info, first, other = read_connections(path)
    assert info == ConnectionListInfo(project="PROGETTO DEMO", job="24-0117", header_line=0)
    assert isinstance(first, Connection) and isinstance(other, Connection)
    assert (first.index, first.line, first.wire_number) == (1, 1, "1500.51")
    assert first.origin == PinRef("F1500.1", "14", None, "=-F1500.1:14")
    assert (first.origin_zone, first.destination_zone, first.section_mm2) == ("Q", "Q", Decimal("0.75"))
    assert (first.length_m, first.duct_path) == (Decimal("2.00"), ("U4", "U5"))
    assert (first.origin_termination, first.destination_termination) == ("ELETTROSALDATO_molla", None)
    assert other.origin == PinRef("X1600", "2", "a", "=-X1600:2:a") and other.section_mm2 == Decimal("2.5")


def test_labelling_line_errors_name_the_line(tmp_path: Path) -> None:
    path = tmp_path / "wiring.xml"
    bad = [*WIRE]
    bad[7] = "tanto"
    path.write_bytes(_labelling({}, WIRING_COLUMNS, [WIRE, bad]))
    with pytest.raises(IngestError) as info:
        read_connections(path)
    assert str(info.value).startswith(f"{path}:<Line> 2: not a number in column 'Sezione'")


BOM_COLUMNS = [
    "SEF (completa)",
    "Numero articolo",
    "Quantità totale (n° pezzi)",
    "Articolo: designazione 1",
    "Numero tipo",
    "Produttori",
    "Zona di montaggio (descrittiva)",
]


def _breaker(line: int) -> BomLine:
    """The breaker line both forms of the bill of materials hold."""
    return BomLine(
        "F0030.1",
        "=-F0030.1",
        "6502086",
        Decimal(1),
        "INT.AUT.1P 10A (C)",
        "SIEMENS 5SY4110-7",
        "SIEMENS",
        "Q",
        None,
        line,
    )


def test_labelling_bill_of_materials(tmp_path: Path) -> None:
    path = tmp_path / "cabinet_dispatch.xml"
    lines = [
        ["=-F0030.1", "6502086", "1", "INT.AUT.1P 10A (C)", "SIEMENS 5SY4110-7", "SIEMENS", "Q"],
        ["=-X1500", "6012993", "9", "MORSETTO", "", "", ""],
    ]
    path.write_bytes(_labelling({"Nome progetto": "P", "Cliente: Nome 1": "ACME"}, BOM_COLUMNS, lines))
    assert sniff_kind(path) == "bill-of-materials"
    info, first, second = read_bill_of_materials(path)
    assert info == BomInfo(project="P", job=None, customer="ACME", machine=None)
    assert first == _breaker(line=1)
    assert isinstance(second, BomLine)
    assert (second.quantity, second.type_number, second.manufacturer, second.zone) == (
        Decimal(9),
        None,
        None,
        None,
    )


# --- workbooks ----------------------------------------------------------------------------------------

LIST_HEADER = ["N. Pagina", "Zona", "Componente:pin", "N. Pagina", "Zona", "Componente:pin", "Numero filo"]
LIST_HEADER += ["Sezione", "Colore", "Tipo pot.", "Nome pot.", "L filo (m)", "Traccia collegamenti"]


def _list_rows(*rows: list[object]) -> list[list[object]]:
    return [
        [None, None, "Nome Progetto:", "PROGETTO DEMO"],
        [None, None, "commessa:", "24-0117"],
        [None, "ORIGINE", None, None, "DESTINAZIONE"],
        LIST_HEADER,
        *rows,
    ]


ROW = [
    "+1500/1.1",
    "Q",
    "=-F1500.1:1",
    "+1500/1.1",
    "Q",
    "=-F1500.2:1",
    "0005L1",
    "1,5 mm²",
    "BK",
    "L",
    "400V",
]
ROW += ["0,474 m", "=-U4"]


def test_connection_list_workbook_picks_its_sheet_and_names_cells(tmp_path: Path) -> None:
    legend = ("configurazione gruppi", [["Q", "Quadro"], ["B", "Bordomacchina"]])
    path = write_xlsx(tmp_path / "Lista_cablaggio.xlsx", [("Lista Cablaggio_to", _list_rows(ROW)), legend])
    assert sniff_kind(path) == "connection-list"
    with pytest.warns(IngestWarning, match="sheets without a connection list skipped: configurazione gruppi"):
        info, wire = read_connections(path)
    assert info == ConnectionListInfo(project="PROGETTO DEMO", job="24-0117", header_line=4)
    assert isinstance(wire, Connection) and (wire.line, wire.section_mm2, wire.length_m) == (
        5,
        Decimal("1.5"),
        Decimal("0.474"),
    )
    bad = [*ROW]
    bad[11] = "mezzo metro"
    path = write_xlsx(tmp_path / "bad.xlsx", [("Lista Cablaggio_to", _list_rows(ROW, bad))])
    with pytest.raises(IngestError) as info_err:
        read_connections(path)
    assert info_err.value.cell == "'Lista Cablaggio_to'!L6"
    assert info_err.value.reason == "not a number in column 'L filo (m)'"


def test_a_pin_cell_showing_a_formula_error_keeps_its_wire_with_the_end_unknown(tmp_path: Path) -> None:
    from tests.ingest.workbooks import replace_in_member

    other = [*ROW]
    other[5] = "=-F1500.3:1"
    path = write_xlsx(tmp_path / "list.xlsx", [("S", _list_rows(ROW, other))])
    # What EPLAN leaves for a formula it cannot evaluate: an error cell (#NAME?).
    replace_in_member(
        path,
        "xl/worksheets/sheet1.xml",
        b'<c r="F6" t="inlineStr"><is><t>=-F1500.3:1</t></is></c>',
        b'<c r="F6" t="e"><f>-basta</f><v>#NAME?</v></c>',
    )
    with pytest.warns(IngestWarning) as caught:
        records = read_connections(path)
    kept = records[2]
    assert isinstance(kept, Connection)
    assert (kept.index, kept.origin.key, kept.destination) == (2, "F1500.1:1", UNKNOWN_END)
    assert (
        f"{path}:S!F6: the cell shows the formula error #NAME?; the wire is kept with this end unknown (?:?)"
        in [str(w.message) for w in caught]
    )


def test_an_empty_pin_cell_of_a_sheet_keeps_its_wire_and_of_a_text_list_is_an_error(tmp_path: Path) -> None:
    # LibreOffice shows the formula EPLAN could not evaluate as an empty cell: the .ods twin of #NAME?.
    other = [*ROW]
    other[5] = None
    path = write_ods(tmp_path / "list.ods", [("S", _list_rows(ROW, other))])
    with pytest.warns(IngestWarning, match="S!F6: the cell shows no pin reference; the wire is kept"):
        records = read_connections(path)
    assert [r.destination for r in records if isinstance(r, Connection)] == [
        parse_pin_ref("=-F1500.2:1"),
        UNKNOWN_END,
    ]
    text = tmp_path / "list.csv"
    text.write_text("\n".join("\t".join(c or "" for c in row) for row in _list_rows(ROW, other)) + "\n")
    with pytest.raises(IngestError, match="empty cell in column 'Componente:pin'"):
        read_connection_list(text)


KOMAX_PREAMBLE = [
    [None] * 6 + ["Nome Progetto:", "PROGETTO DEMO"] + [None] * 6 + ["Option (iema001)"],
    [None] * 6 + ["Commessa:", "24-0117"] + [None] * 6 + ["Stripping length=", "10.0"],
    [None] * 14 + ["!!! NON TOCCARE !!!!!"],
    [],
]
KOMAX_GROUPS = [
    None,
    "ORIGINE",
    "Marking END 1",
    None,
    "DESTINAZIONE",
    "Marking END 2",
    None,
    "Section (mm²)",
]
KOMAX_GROUPS += [
    "Color",
    None,
    None,
    "Lenght",
    None,
    "Type of terminal END 1",
    "Type of terminal END 2",
    None,
]
KOMAX_GROUPS += ["DIREZIONE", "DIREZIONE", None, "Article"]
KOMAX_NAMES = ["N. Pagina", "Zona", "Componente:pin", "N. Pagina", "Zona", "Componente:pin", "Numero filo"]
KOMAX_NAMES += ["Sezione", "Colore", "Tipo pot.", "Nome pot.", "L filo (mm)", "Traccia collegamenti"]
KOMAX_NAMES += ["Terminazione Origine", "Terminazione Destinazione", "Nome Cavo", "END 1", "END 2", "JOB KEY"]
KOMAX_NAMES += ["BUNDLING SIDE"]
KOMAX_ROW = [
    "+1500/1.2",
    "Q",
    "-F1500.1:14",
    "+1500/1.2",
    "Q",
    "-10F1:X4:A2",
    "1500.51",
    "0.75",
    "BU",
    "+",
    None,
]
KOMAX_ROW += ["746", "=-CN2'=-CN3'=-CN5", "PUNTALINO 0.75", None, "=", "Verso l'alto", "DN", "24-0117", 1.0]


@pytest.mark.parametrize("form", ["xlsm", "csv"])
def test_komax_list_two_row_header(tmp_path: Path, form: str) -> None:
    rows = [*KOMAX_PREAMBLE, KOMAX_GROUPS, KOMAX_NAMES, KOMAX_ROW]
    if form == "xlsm":
        path = write_xlsx(tmp_path / "LOF.xlsx", [("LOF_KOMAX_PB20", rows), ("KOMAX_MANUALE", [])])
        path = path.rename(tmp_path / "LOF.xlsm")
    else:
        path = tmp_path / "cablaggio.csv"
        text = "\n".join(
            "\t".join("" if c is None else str(c) for c in [*r, *[None] * (20 - len(r))]) for r in rows
        )
        path.write_text(text.replace("\t1.0", "\t1") + "\n", encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IngestWarning)
        info, wire = read_connections(path)
    assert isinstance(info, ConnectionListInfo) and (info.project, info.job) == ("PROGETTO DEMO", "24-0117")
    assert isinstance(wire, Connection)
    assert wire.duct_path == ("CN2", "CN3", "CN5")  # "'" separates the ducts of a Komax list
    assert (wire.origin_direction, wire.destination_direction) == ("Verso l'alto", "DN")  # END 1/END 2
    assert wire.cable_name is None  # '=': no cable
    assert (wire.length_m, wire.job_key, wire.bundling_side) == (Decimal("0.746"), "24-0117", "1")
    # A device's connector:pin is kept as pin and level, as the cell's software keeps it whole.
    assert wire.destination == PinRef("10F1", "X4", "A2", "-10F1:X4:A2")


def test_bill_of_materials_workbook_and_its_summary(tmp_path: Path) -> None:
    preamble = [
        [],
        [None, None, None, "Nome Progetto: ", "PROGETTO DEMO"],
        [None, None, None, "Commessa: ", "24-0117"],
        [],
        [None, None, None, "DISTINTA COMPONENTI : "],
    ]
    header = [
        None,
        "S.E.F.",
        "N.articolo",
        "Q.ta",
        "Descrizione",
        "Commerciale",
        "Produttore",
        "Destinazione",
    ]
    line = [None, "=-F0030.1", "6502086", 1.0, "INT.AUT.1P 10A (C)", "SIEMENS 5SY4110-7", "SIEMENS", "Q"]
    path = write_xlsx(
        tmp_path / "Distinta_Componenti.xlsx", [("Distinta", [*preamble, header, line]), ("Foglio2", [])]
    )
    assert sniff_kind(path) == "bill-of-materials"
    with pytest.warns(IngestWarning, match="sheets without a bill of materials skipped: Foglio2"):
        info, entry = read_bill_of_materials(path)
    assert info == BomInfo(project="PROGETTO DEMO", job="24-0117", customer=None, machine=None)
    assert entry == _breaker(line=7)
    summary = [
        None,
        "N.articolo",
        "Q.ta",
        "Descrizione",
        "Descrizione 2",
        "Commerciale",
        "N. Tipo",
        "Produttore",
    ]
    article = [None, "6012498", 2.0, "PONTICELLO 2P", None, "1608860000", "WEIDMULLER ZQV 2.5/2", None]
    path = write_xlsx(tmp_path / "riepilogata.xlsx", [("Riepilogo", [summary, article])])
    _, total = read_bill_of_materials(path)
    assert isinstance(total, BomLine)
    assert (total.label, total.part_number, total.quantity, total.type_number) == (
        None,
        "6012498",
        Decimal(2),
        "WEIDMULLER ZQV 2.5/2",
    )
    bad = [*line]
    bad[3] = "due"
    path = write_xlsx(tmp_path / "bad.xlsx", [("Distinta", [*preamble, header, bad])])
    with pytest.raises(IngestError) as err:
        read_bill_of_materials(path)
    assert (err.value.cell, err.value.reason) == ("Distinta!D7", "not a positive quantity")
