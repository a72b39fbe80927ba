"""Write the cabinet's EPLAN exports that are not plain text, from the text files beside them.

    python examples/iema-switchgear/make_exports.py

Writes, in the shapes EPLAN and the cell's tools write them (see README.md):

- ``lista-cablaggio.xlsx``: ``lista-cablaggio.csv`` cell for cell, as text, on sheet
  ``Lista Cablaggio_QE01``, with the zone legend on sheet ``configurazione gruppi``;
- ``schema-morsetti.ods``: the terminal diagram, one sheet for all strips, its rows the
  strips' items in rail order (``terminals.csv``: pin ``0`` for the end stop before a strip's
  first terminal, ``999999`` for the end stop or plate after its last) and its destinations
  the other ends of the wires ``lista-cablaggio.csv`` lands on each terminal;
- ``distinta-componenti.xlsx``: the bill of materials, one line per device and article;
- ``qr-markers.ods``: the QR-code marker table, the marker positions of ``components.xml``;
- ``pins.xml``: EPLAN's parts-management export of the interface relay ``6400170``.

The files come out byte for byte the same on every run (fixed dates inside and in the
archives), so they are committed and a change to them shows in review.
"""

from __future__ import annotations

import csv
import datetime
import io
import re
import zipfile
from collections import defaultdict
from pathlib import Path

import openpyxl
from odf.opendocument import OpenDocumentSpreadsheet
from odf.table import CoveredTableCell, Table, TableCell, TableRow
from odf.text import P

HERE = Path(__file__).resolve().parent
FIXED = datetime.datetime(2026, 11, 21, 8, 0, 0)
ZONES = [("Q", "Quadro"), ("P", "Pulsantiera"), ("B", "Bordomacchina")]


def _wri() -> list[tuple[str, str, str]]:
    text = (HERE / "ids.wri").read_text(encoding="utf-8")
    return [tuple([*line.split("\t"), "", ""][:3]) for line in text.splitlines() if line.strip()]  # type: ignore[misc]


def _bare(label: str) -> str:
    return label.lstrip("=").lstrip("-") if not label.startswith("-SSB") else label[1:]


def _list_rows() -> list[list[str]]:
    with (HERE / "lista-cablaggio.csv").open(encoding="utf-8", newline="") as handle:
        return list(csv.reader(handle, delimiter="\t"))


def _reproducible_zip(path: Path, data: bytes) -> None:
    """Rewrite an archive with fixed member dates, in its own member order."""
    source = zipfile.ZipFile(io.BytesIO(data))
    stamp = FIXED.strftime("%Y-%m-%dT%H:%M:%SZ").encode()
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as target:
        for info in source.infolist():
            member = zipfile.ZipInfo(info.filename, date_time=FIXED.timetuple()[:6])
            member.compress_type = zipfile.ZIP_STORED if info.filename == "mimetype" else zipfile.ZIP_DEFLATED
            member.external_attr = 0o644 << 16
            data = source.read(info.filename)
            if info.filename == "docProps/core.xml":  # the library stamps the time of saving
                data = re.sub(rb"(<dcterms:(?:created|modified)[^>]*>)[^<]*", rb"\g<1>" + stamp, data)
            target.writestr(member, data)


def _save_xlsx(book: openpyxl.Workbook, name: str) -> None:
    book.properties.creator = book.properties.lastModifiedBy = "EPLAN"
    buffer = io.BytesIO()
    book.save(buffer)
    _reproducible_zip(HERE / name, buffer.getvalue())


def _text_cell(sheet: object, row: int, column: int, value: str) -> None:
    cell = sheet.cell(row=row, column=column, value=value)  # type: ignore[attr-defined]
    cell.data_type = "s"  # '=-F1500.1:14' is text, as EPLAN writes it, not a formula


def write_list() -> None:
    book = openpyxl.Workbook()
    sheet = book.active
    sheet.title = "Lista Cablaggio_QE01"
    for r, row in enumerate(_list_rows(), start=1):
        for c, value in enumerate(row, start=1):
            if value:
                _text_cell(sheet, r, c, value)
    legend = book.create_sheet("configurazione gruppi")
    for r, (zone, name) in enumerate(ZONES, start=1):
        _text_cell(legend, r, 1, zone)
        _text_cell(legend, r, 2, name)
    _save_xlsx(book, "lista-cablaggio.xlsx")


def _ods_row(table: Table, values: list[object], spans: dict[int, tuple[int, int]] | None = None) -> None:
    row = TableRow()
    for column, value in enumerate(values):
        if value is _COVERED:
            row.addElement(CoveredTableCell())
            continue
        attributes: dict[str, object] = {}
        if spans and column in spans:
            rows, columns = spans[column]
            attributes = {"numberrowsspanned": rows, "numbercolumnsspanned": columns}
        if value is None:
            row.addElement(TableCell(**attributes))
        elif isinstance(value, float):
            cell = TableCell(valuetype="float", value=value, **attributes)
            cell.addElement(P(text=repr(value)))
            row.addElement(cell)
        else:
            cell = TableCell(valuetype="string", **attributes)
            cell.addElement(P(text=str(value)))
            row.addElement(cell)
    table.addElement(row)


_COVERED = object()


_META = (
    b'<?xml version="1.0" encoding="UTF-8"?>\n<office:document-meta'
    b' xmlns:office="urn:oasis:names:tc:opendocument:xmlns:office:1.0" office:version="1.2"/>'
)


def _save_ods(document: OpenDocumentSpreadsheet, name: str) -> None:
    buffer = io.BytesIO()
    document.write(buffer)
    data = buffer.getvalue()
    # odfpy stamps the meta file with the time of writing; the diagram does not need one.
    source = zipfile.ZipFile(io.BytesIO(data))
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w") as target:
        for info in source.infolist():
            member = source.read(info.filename)
            if info.filename == "meta.xml":
                member = _META
            target.writestr(info, member)
    _reproducible_zip(HERE / name, out.getvalue())


def _wires_on_terminals() -> dict[tuple[str, str], list[str]]:
    """(strip, terminal) → the other ends of the wires landing on it, in list order."""
    ends: dict[tuple[str, str], list[str]] = defaultdict(list)
    for row in _list_rows()[4:]:
        origin, destination = row[2], row[5]
        for here, other in ((origin, destination), (destination, origin)):
            parts = here.removeprefix("=-").split(":")
            if len(parts) == 3:
                ends[(parts[0], parts[1])].append(other)
    return ends


def write_diagram() -> None:
    document = OpenDocumentSpreadsheet()
    table = Table(name="QE01_Schema_Morsetti_00")
    header = [
        "Morsettiera",
        "Zona",
        "Pin",
        "Comp. Destinazione 1",
        None,
        "Comp. Destinazione 2",
        None,
        "Testo funzionale",
    ]
    _ods_row(table, header)
    ends = _wires_on_terminals()
    strips: dict[str, list[str]] = defaultdict(list)
    for row in (HERE / "terminals.csv").read_text(encoding="utf-8").splitlines()[1:]:
        strip, _, terminal, *_ = row.split(",")
        strips[strip].append(terminal)
    functions = {"X1500": "MOTORI", "X1600": "COMANDO TELERUTTORI", "X1700": "SENSORI"}
    for strip, terminals in strips.items():
        named = [t for t in terminals if t]
        for at, terminal in enumerate(terminals):
            if not terminal:
                # An end stop or end plate: pin 0 before the first terminal, 999999 after the
                # last, as the diagram the reference node reads writes them (gearbox_demo's .ods;
                # the workbooks' rows holding the strip's label alone stop its reader there).
                pin = "0" if at == 0 else "999999"
                _ods_row(table, [f"=-{strip}", "Q", pin, None, None, None, None, "FERMO MORSETTO"])
                continue
            others = ends.get((strip, terminal), [])[:2]
            cells: list[object] = [f"=-{strip}", "Q", terminal]
            for other in [*others, None, None][:2]:
                cells += [other, "Q" if other else None]
            cells.append(functions.get(strip) if terminal == named[0] else None)
            _ods_row(table, cells)
    document.spreadsheet.addElement(table)
    _save_ods(document, "schema-morsetti.ods")


# The makers of the parts whose codes are the distributor's (digits only, as the cell's real
# cabinets write them), for the bill of materials' Produttore column.
MAKERS = {
    "6400750": "PILZ",
    "6400772": "PILZ",
    "6503515": "SIEMENS",
    "6503522": "SIEMENS",
    "6503202": "SIEMENS",
    "6800212": "SIEMENS",
    "6800221": "SIEMENS",
    "6800222": "SIEMENS",
    "6800241": "SIEMENS",
    "6400553": "FINDER",
    "6720232": "IFM",
}


def write_bill_of_materials() -> None:
    names = {}
    text = (HERE / "components.xml").read_text(encoding="utf-8")
    for chunk in text.split("<code ")[1:]:
        attributes = dict(
            part.split('="', 1)
            for part in chunk.split(">", 1)[0].replace('"/', '"').split('" ')
            if '="' in part
        )
        code = attributes.get("commercial", attributes.get("name", "")).strip('"')
        names[code] = attributes.get("name", "").strip('"')
    descriptions = {}
    for line in (HERE / "component-list.csv").read_text(encoding="utf-8").splitlines()[1:]:
        cells = line.split("\t")
        if len(cells) > 2 and cells[2]:
            descriptions.setdefault(cells[2], cells[1])
    lines: dict[tuple[str, str], int] = {}
    for _, label, code in _wri():
        if code:
            key = ("=-" + _bare(label) if not label.startswith("-SSB") else "=" + label, code)
            lines[key] = lines.get(key, 0) + 1
    book = openpyxl.Workbook()
    sheet = book.active
    sheet.title = "QE01_Distinta_Componenti_Z"
    preamble = [
        ("Nome Progetto: ", "REMODEL_QE01"),
        ("Descrizione macchina: ", "QUADRO QE01"),
        ("Cliente: ", "IEMA"),
        ("Commessa: ", "24-0117"),
    ]
    for r, (label, value) in enumerate(preamble, start=2):
        _text_cell(sheet, r, 4, label)
        _text_cell(sheet, r, 5, value)
    _text_cell(sheet, 7, 4, "DISTINTA COMPONENTI : ")
    for c, name in enumerate(
        ["S.E.F.", "N.articolo", "Q.ta", "Descrizione", "Commerciale", "Produttore", "Destinazione"], start=2
    ):
        _text_cell(sheet, 8, c, name)
    for r, ((label, code), quantity) in enumerate(sorted(lines.items()), start=9):
        maker = MAKERS.get(code)
        _text_cell(sheet, r, 2, label)
        _text_cell(sheet, r, 3, code)
        sheet.cell(row=r, column=4, value=float(quantity))
        _text_cell(sheet, r, 5, descriptions.get(code, names.get(code, code)))
        _text_cell(sheet, r, 6, names.get(code, code))
        if maker:
            _text_cell(sheet, r, 7, maker)
        _text_cell(sheet, r, 8, "Q")
    book.create_sheet("Foglio2")
    _save_xlsx(book, "distinta-componenti.xlsx")


# Product, commercial code and the marker item of its model (components.xml), per block.
MARKERS = [
    ("3RV2011-1JA10", 6503372.0, (0.0225, 0.06, 0.097)),
    ("3RT2015-1BB41", 6503515.0, (0.0225, 0.03, 0.073)),
]


def write_markers() -> None:
    items: dict[str, list[tuple[str, str]]] = defaultdict(list)
    for cad_id, label, code in _wri():
        items[code].append((_bare(label), cad_id))
    document = OpenDocumentSpreadsheet()
    table = Table(name="Sheet1")
    _ods_row(table, [None] * 8)
    _ods_row(table, [None, "ORIENTATIONS OF QR CODES", *[_COVERED] * 6], {1: (1, 7)})
    _ods_row(table, [None, "Product", "Commercial", "ID", _COVERED, "X (m)", "Y (m)", "Z (m)"], {3: (1, 2)})
    for number, (product, commercial, (x, y, z)) in enumerate(MARKERS):
        if number:
            _ods_row(table, [None, None, *[_COVERED] * 6], {1: (1, 7)})
        code = commercial if isinstance(commercial, str) else str(int(commercial))
        block = [(label, cad_id) for label, cad_id in items[code] if label.startswith(("F1500", "Q1500"))]
        for index, (label, cad_id) in enumerate(block):
            first = [product, commercial] if index == 0 else [_COVERED, _COVERED]
            spans = {1: (len(block), 1), 2: (len(block), 1)} if index == 0 and len(block) > 1 else None
            _ods_row(table, [None, *first, label, cad_id, x, y, z], spans)
    document.spreadsheet.addElement(table)
    _save_ods(document, "qr-markers.ods")


# The relay's connection points (mm from the corner of its box) and wire entry direction.
RELAY_POINTS = [
    ("A1", 3.1, 65.0, 42.0),
    ("A2", 3.1, 55.0, 42.0),
    ("11", 3.1, 5.0, 42.0),
    ("12", 3.1, 15.0, 42.0),
    ("14", 3.1, 25.0, 42.0),
]


def _point(name: str, pos: int, x: float, y: float, z: float) -> str:
    return (
        ' <terminalPosition additionallength="0" direction="1" level="0" maxcrosssection="2.5"'
        f' maxwirecount="2" mincrosssection="0.5" name="{name}" pos="{pos}" targetinfo="0" twinsleeve="0"'
        ' type="0"'
        f' typeofterminal="1" xdir="0" xpos="{x:g}" ydir="0" ypos="{y:g}" zdir="1" zpos="{z:g}"/>'
    )


def write_pins() -> None:
    lines = [
        '<partsmanagement count="2" length-unit="mm" type="EPLAN.PartsManagement" build="132.8"'
        ' database="C:\\EPLAN\\Parts\\parts.mdb">',
        ' <terminal P_PART_TERMINAL_NAME="6400170" P_PART_TERMINAL_CREATE="progettista / 12.11.2026 09:14:02"'
        ' P_PART_TERMINAL_LASTCHANGE="progettista / 12.11.2026 09:20:45">',
        *(_point(name, pos, x, y, z) for pos, (name, x, y, z) in enumerate(RELAY_POINTS, start=1)),
        ' <attributeposition pos="1" P_ARTICLE_ATTRIBUTE_VALUE="Finder"/>',
        " </terminal>",
        ' <terminal P_PART_TERMINAL_NAME="Nuovo_1" P_PART_TERMINAL_CREATE="progettista / 12.11.2026 09:21:10"'
        ' P_PART_TERMINAL_LASTCHANGE="progettista / 12.11.2026 09:21:10">',
        _point("1", 1, 5.0, 10.0, 40.0),
        " </terminal>",
        "</partsmanagement>",
    ]
    # EPLAN ends the declaration with LF and every other line with CRLF.
    text = '<?xml version="1.0" encoding="utf-8" ?>\n' + "\r\n".join(lines) + "\r\n"
    (HERE / "pins.xml").write_bytes(text.encode("utf-8"))


if __name__ == "__main__":
    write_list()
    write_diagram()
    write_bill_of_materials()
    write_markers()
    write_pins()
