"""Reader of the harness components (``Components_definition.csv``).

``;``-separated with the header ``Type;Model;Reference;Label;Color;length;Diameter;x;y;z;Type``
(``Type`` twice: the component's kind, and a device's type). A row is a ``Connector``, a
``Cable`` or a ``Device`` (any case); cells that do not apply are empty, so rows end in ``;``.
Colours are English names (``White``), lengths, diameters and sizes millimetres (records in
metres). A colour name is given its red, green and blue values from :data:`COLOURS` (the CSS
colour keywords of the same name); an unknown name is kept as written, with a warning.
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.text import first_line, iter_rows, read_text, split_cells
from cadkg.usecases.elvez.files.xml_fields import metres

__all__ = [
    "COLOURS",
    "HEADER",
    "HarnessComponent",
    "looks_like_components",
    "read_components",
]

HEADER = ("type", "model", "reference", "label", "color", "length", "diameter", "x", "y", "z", "type")
_EXPECTED = "Type;Model;Reference;Label;Color;length;Diameter;x;y;z;Type rows of Connector, Cable or Device"
_KINDS = {"connector": "connector", "cable": "cable", "device": "device"}

COLOURS: dict[str, tuple[int, int, int]] = {
    "black": (0, 0, 0),
    "white": (255, 255, 255),
    "grey": (128, 128, 128),
    "gray": (128, 128, 128),
    "silver": (192, 192, 192),
    "red": (255, 0, 0),
    "green": (0, 128, 0),
    "lime": (0, 255, 0),
    "blue": (0, 0, 255),
    "yellow": (255, 255, 0),
    "orange": (255, 165, 0),
    "brown": (165, 42, 42),
    "pink": (255, 192, 203),
    "violet": (238, 130, 238),
    "purple": (128, 0, 128),
    "cyan": (0, 255, 255),
    "turquoise": (64, 224, 208),
    "magenta": (255, 0, 255),
    "gold": (255, 215, 0),
    "beige": (245, 245, 220),
}
"""Red, green, blue (0 to 255) of the colour names, by lower-case name (CSS colour keywords)."""


@dataclass(frozen=True, slots=True)
class HarnessComponent:
    """A row: ``kind`` is connector, cable or device; lengths in metres, None where empty."""

    kind: str
    model: str
    reference: str
    label: str
    colour: str
    rgb: tuple[int, int, int] | None
    length: float | None
    diameter: float | None
    size: tuple[float, float, float] | None
    device_type: str
    line: int


def looks_like_components(head: bytes) -> bool:
    """Whether the first line is the components header."""
    cells = [c.strip().lower() for c in split_cells(first_line(head))]
    while cells and not cells[-1]:
        cells.pop()
    return tuple(cells) == HEADER


def read_components(path: str | Path) -> list[HarnessComponent]:
    """Read the components in file order.

    Raises
    ------
    IngestError
        On a missing header, an unknown Type, a row without a label, a label given twice, a
        number that is not one, or a size given in part; each at its line.
    """
    return list(_rows(path))


def _rows(path: str | Path) -> Iterator[HarnessComponent]:
    text = read_text(path, expected=_EXPECTED)
    rows = iter_rows(text, ";", path)
    header = next((r for r in rows if not r.is_blank), None)
    if header is None or tuple(c.strip().lower() for c in header.cells[: len(HEADER)]) != HEADER:
        raise IngestError(
            path,
            "no components header",
            line=header.line if header is not None else None,
            found=";".join(header.cells)[:80] if header is not None else None,
            expected=";".join(
                ("Type", "Model", "Reference", "Label", "Color", "length", "Diameter", "x", "y", "z", "Type")
            ),
        )
    seen: dict[str, int] = {}
    for row in rows:
        if row.is_blank:
            continue
        extra = [c for c in row.cells[len(HEADER) :] if c.strip()]
        if extra:
            raise IngestError(
                path, f"{len(row.cells)} cells in the row", line=row.line, found=extra[0], expected="11 cells"
            )
        kind = _KINDS.get(row.cell(0).lower())
        if kind is None:
            raise IngestError(
                path,
                "unknown component type",
                line=row.line,
                found=row.cell(0),
                expected="Connector, Cable or Device",
            )
        label = row.cell(3)
        if not label:
            raise IngestError(
                path, "a component without a label", line=row.line, expected="a Label such as WH1 or CA1"
            )
        if label in seen:
            raise IngestError(
                path,
                f"label {label} given twice (first on line {seen[label]})",
                line=row.line,
                expected="each label once",
            )
        seen[label] = row.line
        colour = row.cell(4)
        rgb = COLOURS.get(colour.lower()) if colour else None
        if colour and rgb is None:
            warnings.warn(
                IngestWarning(
                    path, f"colour {colour!r} of {label} has no red, green, blue values", line=row.line
                ),
                stacklevel=2,
            )
        numbers = [
            _millimetres(path, row.line, name, row.cell(i)) for i, name in enumerate(HEADER) if 5 <= i <= 9
        ]
        size = numbers[2:]
        if any(v is not None for v in size) and any(v is None for v in size):
            raise IngestError(
                path, f"size of {label} given in part", line=row.line, expected="x, y and z, or none"
            )
        yield HarnessComponent(
            kind=kind,
            model=row.cell(1),
            reference=row.cell(2),
            label=label,
            colour=colour,
            rgb=rgb,
            length=numbers[0],
            diameter=numbers[1],
            size=(size[0], size[1], size[2])
            if size[0] is not None and size[1] is not None and size[2] is not None
            else None,
            device_type=row.cell(10),
            line=row.line,
        )


def _millimetres(path: str | Path, line: int, column: str, text: str) -> float | None:
    if not text:
        return None
    try:
        value = float(text.replace(",", "."))
    except ValueError:
        value = math.nan
    if not math.isfinite(value) or value < 0:
        raise IngestError(
            path, f"{column} is not a number of millimetres", line=line, found=text, expected="e.g. 5.1"
        )
    return metres(text.replace(",", "."))
