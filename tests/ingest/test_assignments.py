"""The robot/human assignment overlay: the example's rows, and every bad row located by line."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.assignments import Assignment, read_assignments
from tests.conftest import EXAMPLES

Write = Callable[[str, str | bytes], Path]


def test_the_example_overlay() -> None:
    rows = read_assignments(EXAMPLES / "iema-switchgear" / "assignments.csv")
    assert rows == [
        Assignment("wire", "0020.03", "human", 2),
        Assignment("wire", "0070.05", "human", 3),
        Assignment("wire", "SSB10.05", "human", 4),
        Assignment("wire", "0040.07", "human", 5),
        Assignment("component", "S0050.1", "human", 6),
        Assignment("operation", "93", "human", 7),
    ]


def test_semicolons_case_labels_and_blank_lines(write: Write) -> None:
    text = "Kind;ID;Performer\r\n\r\nCOMPONENT;=-K1;Robot\r\noperation;007;human\r\n"
    assert read_assignments(write("a.csv", text)) == [
        Assignment("component", "K1", "robot", 3),
        Assignment("operation", "007", "human", 4),
    ]


def test_bom_and_latin1(write: Write) -> None:
    bom = "\ufeffkind,id,performer\nwire,W1,human\n".encode()
    assert read_assignments(write("a.csv", bom)) == [Assignment("wire", "W1", "human", 2)]
    with pytest.warns(IngestWarning, match="Windows-1252"):
        rows = read_assignments(write("b.csv", "kind,id,performer\nwire,Wü,human\n".encode("cp1252")))
    assert rows == [Assignment("wire", "Wü", "human", 2)]


@pytest.mark.parametrize(
    ("body", "line", "reason", "found"),
    [
        ("wire,W1,human\nwir,W2,human\n", 3, "unknown kind", "wir"),
        ("wire,W1,machine\n", 2, "unknown performer", "machine"),
        ("wire,,human\n", 2, "empty id", None),
        ("operation,0,human\n", 2, "operation id is not a list position", "0"),
        ("operation,-3,human\n", 2, "operation id is not a list position", "-3"),
        ("operation,x1,human\n", 2, "operation id is not a list position", "x1"),
        # '²'.isdigit() holds, but it is no list position (and int() refuses it).
        ("operation,\u00b2,human\n", 2, "operation id is not a list position", "\u00b2"),
        # An unclosed quote swallows the rest of the line: the performer is then missing.
        ('wire,"W1,human\n', 2, "unknown performer", ""),
    ],
    ids=["kind", "performer", "empty-id", "zero", "negative", "text", "superscript", "open-quote"],
)
def test_bad_row_is_located(write: Write, body: str, line: int, reason: str, found: str | None) -> None:
    path = write("a.csv", "kind,id,performer\n" + body)
    with pytest.raises(IngestError) as info:
        read_assignments(path)
    assert (info.value.line, info.value.found) == (line, found)
    assert info.value.reason.startswith(reason)
    assert str(info.value).startswith(f"{path}:{line}: {reason}")


@pytest.mark.parametrize(
    ("content", "reason"),
    [
        (b"", "the file is empty"),
        (b"id,kind,performer\nW1,wire,human\n", "missing header"),
        (b"kind,id,performer\n", "no assignments after the header"),
        (b"\x00\x01\x02\xff" * 50, "binary"),
    ],
    ids=["empty", "header-order", "header-only", "binary"],
)
def test_bad_file(write: Write, content: bytes, reason: str) -> None:
    with pytest.raises(IngestError) as info:
        read_assignments(write("a.csv", content))
    assert reason in info.value.reason
