"""Reader of the robot/human assignment overlay: which work a person does instead of the robot.

A small CSV the manifest names as a source::

    kind,id,performer
    wire,PE.1,human
    component,S0050.1,human
    operation,12,human

``kind`` is wire (a wire number), component (a label) or operation (a list
position); ``performer`` is robot or human. Later rows win over earlier ones.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.eplan.labels import normalize_label
from cadkg.ingest.text import iter_rows, read_text
from cadkg.plan.decision import Performer

__all__ = ["KINDS", "Assignment", "looks_like_assignments", "read_assignments"]

KINDS = ("wire", "component", "operation")
_PERFORMERS = tuple(p.value for p in Performer)
_EXPECTED = "a CSV with the header kind,id,performer"


@dataclass(frozen=True, slots=True)
class Assignment:
    kind: str
    ident: str
    performer: str
    line: int


def read_assignments(path: str | Path) -> list[Assignment]:
    """Read an assignment overlay.

    Raises
    ------
    IngestError
        On a missing header, an unknown kind or performer, an empty id or a
        non-integer operation position; located by line.
    """
    text = read_text(path, expected=_EXPECTED)
    delimiter = ";" if text.split("\n", 1)[0].count(";") > text.split("\n", 1)[0].count(",") else ","
    rows = [row for row in iter_rows(text, delimiter, path) if not row.is_blank]
    header = [c.strip().lower() for c in rows[0].cells] if rows else []
    if header[:3] != ["kind", "id", "performer"]:
        raise IngestError(
            path,
            "missing header",
            line=rows[0].line if rows else 1,
            found=",".join(header),
            expected=_EXPECTED,
        )
    result = []
    for row in rows[1:]:
        kind, ident, performer = (row.cell(0).lower(), row.cell(1), row.cell(2).lower())
        if kind not in KINDS:
            raise IngestError(path, "unknown kind", line=row.line, found=kind, expected=" | ".join(KINDS))
        if performer not in _PERFORMERS:
            raise IngestError(
                path, "unknown performer", line=row.line, found=performer, expected=" | ".join(_PERFORMERS)
            )
        if not ident:
            raise IngestError(path, "empty id", line=row.line, expected=f"the {kind} to assign")
        if kind == "component":
            ident = normalize_label(ident)
        # ASCII digits, not all zeros: '²'.isdigit() holds too, and is no list position.
        if kind == "operation" and not (ident.isascii() and ident.isdigit() and ident.strip("0")):
            raise IngestError(
                path, "operation id is not a list position", line=row.line, found=ident, expected="1, 2, ..."
            )
        result.append(Assignment(kind, ident, performer, row.line))
    if not result:
        raise IngestError(path, "no assignments after the header", line=rows[0].line, expected=_EXPECTED)
    return result


def looks_like_assignments(head: bytes) -> bool:
    """Whether the first line is the overlay's header ``kind,id,performer``."""
    first = head.decode("utf-8", errors="replace").lstrip("\ufeff").split("\n", 1)[0]
    return first.strip().lower().replace(";", ",").startswith("kind,id,performer")
