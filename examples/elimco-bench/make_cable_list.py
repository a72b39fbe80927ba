"""Write ``cable-list.xlsx``: the rows of D3.1 Figure 11 as ELIMCO's cable list workbook.

Run from anywhere: ``python examples/elimco-bench/make_cable_list.py``. The workbook is
generated rather than stored so the rows stay readable and reviewable here.

``FIGURE_11`` holds the rows exactly as the reference prints them. Two things are done to
them, both explained in this folder's README:

1. Realignment: after ``CN TIPO`` the printed rows give their ten values in another order
   than the printed header (type, length, construction, route, far connector, far
   contact, far contact part, remark, gauge, check). Each value is put under the column it
   means, so ``LONGITUD`` holds the length and ``ZONA_B``/``BORNIA_B`` the far end.
2. Corrections (``CORRECTIONS``): the connector spelling of the route application, and two
   slips that the repeated rows of the list itself contradict.
"""

from __future__ import annotations

import sys
from pathlib import Path

import openpyxl

HEADER = (
    "PN", "REV", "IND", "ORDEN", "REP", "SIMBOLO_A", "ZONA_A", "BORNIA_A", "CNX_A", "SH", "HILO",
    "CABLE", "CN TIPO", "AWG", "CABLE", "LONGITUD", "ROUTA", "OB", "ZONA_B", "BORNIA_B", "CNX_B",
    "CK_CABLE",
)  # fmt: skip

_AX = "CAN68576B22 (AX2B22)"
_DR = "EN2267-010A004S (DR)"
_EN = "EN3155-019F2020"
_M3 = "M39029/56-351"

# As printed: PN REV IND ORDEN REP SIMBOLO_A ZONA_A BORNIA_A CNX_A SH HILO CABLE, then ten values.
FIGURE_11 = (
    ("F929A", "A", 2, 1, 0, "B1", "A918VC1A", "B", "-", "A4351-1669/1", "A4351-1687SH", "A4351-1687",
     _DR, 400, "1X5", "-", "A918VC1A", "B", "-", _EN, "-", 0),
    ("F929A", "A", 2, 1, 0, "B1", "A918VC1A", "A", _EN, "-", "A4351-1689B", "A4351-1689",
     _AX, 1504, "1X5", "-", "A1U23B", 5, "-", "-", "-", 0),
    ("F929A", "A", 2, 1, 0, "B1", "A918VC1A", "H", _EN, "-", "A4351-1669W", "A4351-1669",
     _AX, 1504, "1X5", "-", "A1U23B", 22, "-", "-", "-", 0),
    ("F929A", "A", 2, 2, 0, "B2", "A350VC-A", "-", "-", "A4351-2401/1", "A4351-2279SH", "A4351-2401",
     _AX, 1057, "1X5", "-", "A350VC-A", "BS1", "-", "-", "-", 0),
    ("F929A", "A", 2, 2, 0, "B2", "A350VC-A", "BS1", "-", "-", "A4351-2279SH", "A4351-2401",
     _AX, 1057, "1X5", "-", "A350VC-A", "-", "-", "-", "-", 0),
    ("F929A", "A", 2, 2, 0, "B2", "A350VC-A", "A", _M3, "-", "A4351-2401W", "A4351-2401",
     _AX, 1057, "1X5", "-", "A350VC-A", 14, "-", "-", "-", 0),
    ("F929A", "A", 2, 2, 0, "B2", "A350VC-A", "B", _M3, "-", "A4351-2401B", "A4351-2401",
     _AX, 1057, "1X5", "-", "A1U23C", 13, "-", "-", "-", 0),
    ("F929A", "A", 2, 3, 0, "A3", "A1U23C", "-", "-", "A4351-2401/1", "A4351-1740SH", "A4351-2401",
     _AX, 1057, "1X5", "-", "A1U23C", "BS1", "-", "-", "-", 0),
    ("F929A", "A", 2, 3, 0, "A3", "A1U23C", "BS1", "-", "-", "A4351-1740SH", "A4351-2401",
     _AX, 1057, "1X5", "-", "A1U23C", "-", "-", "-", "-", 0),
    ("F929A", "A", 2, 3, 1, "A3", "A1U23C", 13, "-", "-", "A4351-2401B", "A4351-2401",
     _AX, 1057, "1X5", "-", "A350VC-A", "B", _M3, "-", "-", 0),
    ("F929A", "A", 2, 3, 1, "A3", "A1U23C", 14, "-", "-", "A4351-2401W", "A4351-2401",
     _AX, 1057, "1X5", "-", "A350VC-A", "A", _M3, "-", "-", 0),
    ("F929A", "A", 2, 4, 0, "A4", "A1U23B", "-", "-", "A4351-1669/1", "A4351-1691SH", "A4351-1669",
     _AX, 1504, "1X5", "-", "A1U23B", "BS1", "-", "-", "-", 0),
    ("F929A", "A", 2, 4, 0, "A4", "A1U23B", "-", "-", "A4351-1677/1", "A4351-1692SH", "A4351-1677",
     _AX, 1668, "1X5", "-", "A1U23B", "BS1", "-", "-", "-", 0),
    ("F929A", "A", 2, 4, 0, "A4", "A1U23B", "BS1", "-", "-", "A4351-1691SH", "A4351-1669",
     _AX, 1504, "1X5", "-", "A1U23B", "-", "-", "-", "-", 0),
    ("F929A", "A", 2, 4, 0, "A4", "A1U23B", "BS1", "-", "-", "A4351-1692SH", "A4351-1677",
     _AX, 1668, "1X5", "-", "A1U23B", "-", "-", "-", "-", 0),
    ("F929A", "A", 2, 4, 1, "A4", "A1U23B", 22, "-", "-", "A4351-1669W", "A4351-1669",
     _AX, 1504, "1X5", "-", "A918VC1A", "H", _EN, "-", "-", 0),
    ("F929A", "A", 2, 4, 0, "A4", "A1U23B", 24, "-", "-", "A4351-1677B", "A4351-1677",
     _AX, 1668, "1X5", "-", "7RN4A", "B", "-", "-", "-", 1),
    ("F929A", "A", 2, 4, 1, "A4", "A1U23B", 5, "-", "-", "A4351-1669B", "A4351-1669",
     _AX, 1504, "1X5", "-", "A918VC1A", "A", _EN, "-", "-", 0),
    ("F929A", "A", 2, 4, 0, "A4", "A1U23B", 9, "-", "-", "A4351-1677W", "A4351-1677",
     _AX, 1668, "1X5", "-", "7RN4A", "A", "-", "-", "-", 1),
    ("F929A", "A", 2, 5, 0, "A5", "7RN4A", "-", "-", "A4351-1677/1", "A4351-1698SH", "A4351-1698",
     _DR, 400, "1X5", "-", "7RN4A", "C", "-", "-", "-", 0),
    ("F929A", "A", 2, 5, 0, "A5", "7RN4A", "C", "-", "-", "A4351-1698SH", "A4351-1677",
     _DR, 400, "1X5", "-", "7RN4A", "-", "-", "-", "-", 0),
    ("F929A", "A", 2, 5, 1, "A5", "7RN4A", "A", "-", "-", "A4351-1677W", "A4351-1677",
     _AX, 1668, "1X5", "-", "A1U23B", 9, "-", "-", "-", 1),
    ("F929A", "A", 2, 5, 1, "A5", "7RN4A", "B", "-", "-", "A4351-1677B", "A4351-1677",
     _AX, 1668, "1X5", "-", "A1U23B", 24, "-", "-", "-", 1),
)  # fmt: skip

# Printed position (0-based, from CN TIPO on) -> header position of the column it means.
_REALIGN = {12: 12, 13: 15, 14: 14, 15: 16, 16: 18, 17: 19, 18: 20, 19: 17, 20: 13, 21: 21}

# (0-based row of FIGURE_11, header name or "connectors", value): see the README.
CORRECTIONS = (
    (1, "HILO", "A4351-1669B"),  # its repeat (row 18) and the shield group name cable A4351-1669
    (1, "CABLE", "A4351-1669"),
    (5, "ZONA_B", "A1UZ3C"),  # its repeat (row 11) runs A1UZ3C:14 -> A350VC-A:A
)
SPELLING = {"A1U23B": "A1UZ3B", "A1U23C": "A1UZ3C"}  # the route application's names (Figs. 15, 19)


def realigned(row: tuple[object, ...]) -> list[object]:
    """A printed row with each value under the column it means."""
    out: list[object] = list(row[:12]) + [None] * 10
    for printed, column in _REALIGN.items():
        out[column] = row[printed]
    return out


def rows(*, corrected: bool = True) -> list[list[object]]:
    """The header and the 23 rows, realigned; ``corrected`` applies the spelling and the corrections."""
    body = [realigned(r) for r in FIGURE_11]
    if corrected:
        body = [[SPELLING.get(v, v) if isinstance(v, str) else v for v in r] for r in body]
        for index, name, value in CORRECTIONS:
            body[index][HEADER.index(name)] = value  # the first CABLE is the cable
    return [list(HEADER), *body]


def write(path: Path, table: list[list[object]], sheet: str = "Hoja1") -> Path:
    book = openpyxl.Workbook()
    book.active.title = sheet
    for values in table:
        book.active.append(values)
    book.save(path)
    return path


if __name__ == "__main__":
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).with_name("cable-list.xlsx")
    print(write(target, rows()))
