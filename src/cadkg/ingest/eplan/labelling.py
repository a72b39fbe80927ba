"""EPLAN's labelling XML (``<EplanLabelling>``): any EPLAN report as header properties and lines.

EPLAN writes a report (a connection list, a bill of materials) as one ``<Line>`` per row,
each repeating every column as ``<Property><PropertyName>…<PropertyValue>``, in the order
of the ``<ColumnHeader>`` elements. Column names repeat (origin and destination share
``Nome attacco di destinazione (completo)``), so columns are taken by position, the first
of a name being the origin. Names are in the language of the EPLAN that wrote the file:
:func:`canonical` gives each the header a spreadsheet export uses for the same meaning,
in Italian, German or English, so the readers of those exports read these lines too.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from cadkg.errors import IngestError
from cadkg.ingest.text import Row
from cadkg.ingest.xml_input import read_xml_file

__all__ = ["LabellingReport", "canonical", "looks_like_labelling", "read_labelling"]

_EXPECTED = "<EplanLabelling><Document><Page> with <ColumnHeader> and <Line> elements"

# Property name (lower case, white space folded, no spaces around '/') → the header the
# spreadsheet exports use for it. The German and English names are EPLAN's for the same
# properties; only the Italian ones are checked against real exports.
_CANONICAL = {
    # connection list
    "nome pagina (completo)": "N. Pagina",
    "seitenname (vollständig)": "N. Pagina",
    "page name (full)": "N. Pagina",
    "zona di montaggio (descrittiva)": "Zona",
    "einbauort (beschreibend)": "Zona",
    "mounting location (descriptive)": "Zona",
    "nome attacco di destinazione (completo)": "Componente:pin",
    "anschlussbezeichnung des ziels (vollständig)": "Componente:pin",
    "zielanschluss (vollständig)": "Componente:pin",
    "target connection point designation (full)": "Componente:pin",
    "designazione collegamenti": "Numero filo",
    "verbindungsbezeichnung": "Numero filo",
    "connection designation": "Numero filo",
    "sezione/diametro collegamento": "Sezione",
    "verbindung: querschnitt/durchmesser": "Sezione",
    "querschnitt/durchmesser": "Sezione",
    "connection: cross-section/diameter": "Sezione",
    "cross-section/diameter": "Sezione",
    "colore/numero collegamento": "Colore",
    "verbindung: farbe/nummer": "Colore",
    "farbe/nummer": "Colore",
    "connection color/number": "Colore",
    "color/number": "Colore",
    "tipo potenziale": "Tipo pot.",
    "potenzialtyp": "Tipo pot.",
    "potential type": "Tipo pot.",
    "nome potenziale": "Nome pot.",
    "potenzialname": "Nome pot.",
    "potential name": "Nome pot.",
    "name of potential": "Nome pot.",
    "lunghezza (completa)": "L filo (m)",
    "länge (vollständig)": "L filo (m)",
    "length (full)": "L filo (m)",
    "ambiente 3d: traccia dei collegamenti": "Traccia collegamenti",
    "3d-umgebung: verbindungsverlauf": "Traccia collegamenti",
    "3d environment: connection routing path": "Traccia collegamenti",
    "origine tipo di terminazione filo": "Terminazione Origine",
    "quelle: aderendbehandlung": "Terminazione Origine",
    "source wire termination processing": "Terminazione Origine",
    "destinazione tipo di terminazione filo": "Terminazione Destinazione",
    "ziel: aderendbehandlung": "Terminazione Destinazione",
    "target wire termination processing": "Terminazione Destinazione",
    # bill of materials
    "sef (completa)": "S.E.F.",
    "bmk (vollständig)": "S.E.F.",
    "dt (full)": "S.E.F.",
    "device tag (full)": "S.E.F.",
    "numero articolo": "N.articolo",
    "artikelnummer": "N.articolo",
    "part number": "N.articolo",
    "quantità totale (n° pezzi)": "Q.ta",
    "gesamtmenge (stück)": "Q.ta",
    "total quantity (pieces)": "Q.ta",
    "articolo: designazione 1": "Descrizione",
    "artikel: bezeichnung 1": "Descrizione",
    "part: designation 1": "Descrizione",
    "numero tipo": "Commerciale",
    "typnummer": "Commerciale",
    "type number": "Commerciale",
    "produttori": "Produttore",
    "produttore": "Produttore",
    "hersteller": "Produttore",
    "manufacturer": "Produttore",
}
# A bill of materials names its zone column 'Destinazione'; a connection list its zones 'Zona'.
_BOM_ZONE = "Destinazione"


@dataclass(frozen=True, slots=True)
class LabellingReport:
    """A report: its header properties, its column names and its lines (``Row.line`` is the
    1-based number of the ``<Line>``; the document is often on one physical line)."""

    header: dict[str, str]
    columns: tuple[str, ...]
    lines: tuple[Row, ...]

    def canonical_header(self) -> Row:
        """The columns under the names a spreadsheet export gives them (see :func:`canonical`)."""
        names = [canonical(c) for c in self.columns]
        if "S.E.F." in names and "Componente:pin" not in names:
            names = [_BOM_ZONE if n == "Zona" else n for n in names]
        return Row(0, tuple(names))


def canonical(name: str) -> str:
    """``'Designazione collegamenti'`` → ``'Numero filo'``; a name not known comes back as it is."""
    key = re.sub(r"\s*/\s*", "/", re.sub(r"\s+", " ", name.strip().lower()))
    return _CANONICAL.get(key, name.strip())


def looks_like_labelling(head: bytes) -> bool:
    """Whether a file's first bytes open an ``<EplanLabelling>`` document."""
    return b"<EplanLabelling" in head[:4096]


def read_labelling(path: str | Path) -> LabellingReport:
    """Read an EPLAN labelling XML report.

    Raises
    ------
    IngestError
        On a file that is not ``<EplanLabelling>`` XML, one without column headers, or a line
        whose properties are not the columns in order.
    """
    root = read_xml_file(path, root="EplanLabelling", what="EPLAN labelling XML", expected=_EXPECTED)
    header: dict[str, str] = {}
    for prop in root.iterfind("./Document/Page/Header/Property"):
        name, value = _property(prop)
        header.setdefault(name, value)
    columns = tuple(
        (element.findtext("PropertyName") or "").strip()
        for element in root.iterfind("./Document/Page/ColumnHeader")
    )
    if not columns:
        raise IngestError(path, "no <ColumnHeader> in the report", line=root.sourceline, expected=_EXPECTED)
    lines = []
    for number, line in enumerate(root.iterfind("./Document/Page/Line"), start=1):
        lines.append(_line(path, line, number, columns))
    return LabellingReport(header, columns, tuple(lines))


def _property(element: etree._Element) -> tuple[str, str]:
    return (element.findtext("PropertyName") or "").strip(), (element.findtext("PropertyValue") or "").strip()


def _line(path: str | Path, line: etree._Element, number: int, columns: tuple[str, ...]) -> Row:
    values = [_property(p) for p in line.iterfind("./Label/Property")]
    names = tuple(name for name, _ in values)
    at = next((i for i, name in enumerate(names) if i >= len(columns) or name != columns[i]), None)
    if at is not None:
        raise IngestError(
            path,
            f"<Line> {number}: property {at + 1} is not the column of that position",
            line=line.sourceline,
            found=names[at],
            expected=columns[at] if at < len(columns) else "no more properties than columns",
        )
    return Row(number, tuple(value for _, value in values))
