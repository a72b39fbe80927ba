"""Reader of the ELVEZ action plan: the ordered operations of the harness assembly.

Each row is one operation: its index (1, 2, 3 ... in file order), its type (``insert`` a
connector, ``route`` cables, ``tape`` cables), the components it handles, the spots where it
happens (labels of platform elements, in order: a route's guides) and the tool it needs
(D3.1 section 4.3, Table 2 ``all_op`` and ``index_op``). See docs/formats/elvez-action-plan.md.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.text import (
    Row,
    check_columns,
    find_header,
    first_line,
    named_columns,
    read_text,
    split_cells,
)

__all__ = ["OPERATION_TYPES", "PlannedOperation", "looks_like_action_plan", "read_action_plan"]

OPERATION_TYPES = ("insert", "route", "tape")
_COLUMNS = ("index", "operation", "components", "spots", "tool")
_EXPECTED = "a header row: index, operation, components, spots, tool"
_ITEM = re.compile(r"^[^\s;,]+$")
_TOOL = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


@dataclass(frozen=True, slots=True)
class PlannedOperation:
    """One operation of the plan, with its lists in the order the plan gives them."""

    index: int
    kind: str
    components: tuple[str, ...]
    spots: tuple[str, ...]
    tool: str
    line: int


def looks_like_action_plan(head: bytes) -> bool:
    """Whether the first non-empty line names the columns index, operation, components and spots."""
    cells = {c.lower() for c in split_cells(first_line(head))}
    return {"index", "operation", "components", "spots"} <= cells


def _columns(row: Row) -> dict[str, int]:
    return named_columns(row, _COLUMNS)


def read_action_plan(path: str | Path) -> list[PlannedOperation]:
    """Read an action plan.

    Raises
    ------
    IngestError
        On an empty or binary file, a missing header or column, an unknown column or
        operation type, an index out of sequence, an empty or malformed list of components or
        spots, an insert of more than one connector, or a malformed tool name.
    """
    text = read_text(path, expected=_EXPECTED)
    rows, header, columns = find_header(
        text, path, _columns, lambda c: {"index", "operation"} <= c.keys(), _EXPECTED, scan_rows=5
    )
    head = rows[header]
    check_columns(path, head, columns, _COLUMNS, _COLUMNS, _EXPECTED)
    operations: list[PlannedOperation] = []
    for row in rows[header + 1 :]:
        if row.is_blank:
            continue
        operations.append(_operation(path, row, columns, len(operations) + 1))
    if not operations:
        raise IngestError(path, "no operations after the header", line=head.line, expected=_EXPECTED)
    return operations


def _operation(path: str | Path, row: Row, columns: dict[str, int], expected_index: int) -> PlannedOperation:
    def fail(reason: str, found: object = None, expected: str | None = None) -> IngestError:
        return IngestError(path, reason, line=row.line, found=found, expected=expected)

    raw_index = row.cell(columns["index"])
    if not re.fullmatch(r"\d{1,9}", raw_index) or int(raw_index) != expected_index:
        raise fail(
            "operation index out of sequence",
            raw_index,
            f"{expected_index} (operations are numbered 1, 2, 3 ... in file order)",
        )
    kind = row.cell(columns["operation"]).lower()
    if kind not in OPERATION_TYPES:
        raise fail("unknown operation type", row.cell(columns["operation"]), " | ".join(OPERATION_TYPES))

    def items(column: str) -> tuple[str, ...]:
        raw = row.cell(columns[column])
        values = tuple(v.strip() for v in raw.split(";"))
        if not raw or not all(_ITEM.match(v) for v in values):
            raise fail(
                f"malformed {column} of operation {expected_index}",
                raw,
                "names separated by ';', e.g. W101;W102",
            )
        if len(set(values)) != len(values):
            raise fail(f"a name is given twice in the {column} of operation {expected_index}", raw)
        return values

    components = items("components")
    spots = items("spots")
    if kind == "insert" and len(components) != 1:
        raise fail(
            f"insert operation {expected_index} names {len(components)} components",
            ";".join(components),
            "one connector",
        )
    tool = row.cell(columns["tool"])
    if not _TOOL.match(tool):
        raise fail(f"malformed tool of operation {expected_index}", tool, "a tool name of the tools file")
    return PlannedOperation(expected_index, kind, components, spots, tool, row.line)
