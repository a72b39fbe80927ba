"""Reader of the assembly sequence (``Assembly_sequence.csv``).

``;``-separated, header ``Order;Type of operation;Label;Spot``. Each row is one operation:
its order (a whole number from 1), its code, the labels it handles (``-``-separated) and its
spots, parsed by code:

====  ==========================================  ===============================
code  operation                                   spot
====  ==========================================  ===============================
EC    take a harness's connector out of its comb  ``C1.1.L``: comb, guide, side
PC    place a connector in a jig                  ``J8.1.L``: jig, guide, side
RC    route cables through guides, in order       ``J4.1-J3.1-J2.1``: jig.guide ...
T     tape between guides                         ``J1.1-J2.1``: jig.guide ...
TJ    tape in a jig                               ``J3.1``: jig, guide
====  ==========================================  ===============================

Codes are read in any case and kept as written; the side is L or R.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.text import first_line, iter_rows, read_text, small_integer, split_cells

__all__ = [
    "CODES",
    "SequenceStep",
    "SpotRef",
    "looks_like_sequence",
    "parse_spots",
    "read_sequence",
]

HEADER = ("order", "type of operation", "label", "spot")
_EXPECTED = "Order;Type of operation;Label;Spot rows (e.g. 3;RC;GR11;J4.1-J3.1-J2.1)"
CODES = ("EC", "PC", "RC", "T", "TJ")
"""The operation codes, in the order the docs list them."""
_FORMS = {
    "EC": "comb.guide.side, e.g. C1.1.L",
    "PC": "jig.guide.side, e.g. J8.1.L",
    "RC": "jig.guide joined by '-', e.g. J4.1-J3.1-J2.1",
    "T": "jig.guide joined by '-', e.g. J1.1-J2.1",
    "TJ": "jig.guide, e.g. J3.1",
}


@dataclass(frozen=True, slots=True)
class SpotRef:
    """A spot of an operation: an element's label, a guide id of it and, for EC/PC, a side."""

    jig: str
    guide: str
    side: str = ""


@dataclass(frozen=True, slots=True)
class SequenceStep:
    order: int
    code: str
    labels: tuple[str, ...]
    spot_text: str
    spots: tuple[SpotRef, ...]
    line: int


def looks_like_sequence(head: bytes) -> bool:
    """Whether the first line is the sequence header."""
    cells = [c.lower() for c in split_cells(first_line(head))]
    while cells and not cells[-1]:
        cells.pop()
    return tuple(cells) == HEADER


def parse_spots(code: str, text: str) -> tuple[SpotRef, ...] | None:
    """The spots of an operation of ``code`` (upper case); None when ``text`` is malformed."""
    parts = [p.strip().split(".") for p in text.split("-")] if text.strip() else []
    if not parts or any(not all(parts_of) for parts_of in parts):
        return None
    if code in ("EC", "PC"):
        if len(parts) != 1 or len(parts[0]) != 3 or parts[0][2].upper() not in ("L", "R"):
            return None
        return (SpotRef(parts[0][0], parts[0][1], parts[0][2]),)
    if code == "TJ" and len(parts) != 1:
        return None
    if any(len(p) != 2 for p in parts):
        return None
    return tuple(SpotRef(p[0], p[1]) for p in parts)


def read_sequence(path: str | Path) -> list[SequenceStep]:
    """Read the operations in file order.

    Raises
    ------
    IngestError
        On a missing header, an order that is not a whole number from 1, an unknown operation
        code, a row without a label, or a spot not of its code's form; each at its line.
    """
    text = read_text(path, expected=_EXPECTED)
    rows = iter_rows(text, ";", path)
    header = next((r for r in rows if not r.is_blank), None)
    if header is None or tuple(c.strip().lower() for c in header.cells[:4]) != HEADER:
        raise IngestError(
            path,
            "no sequence header",
            line=header.line if header is not None else None,
            found=";".join(header.cells)[:80] if header is not None else None,
            expected="Order;Type of operation;Label;Spot",
        )
    steps = []
    for row in rows:
        if row.is_blank:
            continue
        order = row.cell(0)
        # int() refuses runs of over 4,300 digits and '²', which isdigit() accepts.
        number = small_integer(order)
        if number is None or number < 1:
            raise IngestError(
                path, "Order is not a whole number from 1", line=row.line, found=order, expected="1, 2, 3 ..."
            )
        code = row.cell(1)
        if code.upper() not in CODES:
            raise IngestError(
                path, "unknown operation code", line=row.line, found=code, expected=", ".join(CODES)
            )
        labels = tuple(label.strip() for label in row.cell(2).split("-") if label.strip())
        if not labels:
            raise IngestError(
                path, f"{code} without a label", line=row.line, expected="a label such as WH1 or GR11"
            )
        spots = parse_spots(code.upper(), row.cell(3))
        if spots is None:
            raise IngestError(
                path,
                f"malformed spot of {code}",
                line=row.line,
                found=row.cell(3),
                expected=_FORMS[code.upper()],
            )
        steps.append(SequenceStep(number, code, labels, row.cell(3), spots, row.line))
    return steps
