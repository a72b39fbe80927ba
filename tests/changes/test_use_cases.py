"""The kinds of the harness, route-bench and hose use cases, on copies of their examples edited."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import cadkg
from cadkg.changes import diff_graphs
from tests.changes.cells import copy_cell, edit
from tests.conftest import EXAMPLES

CASES: dict[str, tuple[str, tuple[tuple[str, str, str], ...], set[tuple[str, str, str]]]] = {
    # A segment made longer, a wire moved to another cavity and recoloured, a new wire.
    "vw": (
        "vw-harness",
        (
            ("door-l.harness", "segment S3 B1 B2 length=200mm", "segment S3 B1 B2 length=210mm"),
            ("door-l.harness", "W6 X2:4 X4:2 section=0.5 colour=YE", "W6 X2:4 X4:3 section=0.5 colour=GN"),
            ("door-l.harness", "wire W7 X1:5 X4:3", "wire W7 X1:5 X4:1\nwire W8 X1:6 X2:4"),
        ),
        {
            ("changed", "segment", "B1–B2"),
            # W8 runs through these: their wires changed.
            ("changed", "segment", "B1–X1"),
            ("changed", "segment", "B1–X2"),
            ("changed", "wire", "W6"),
            ("changed", "wire", "W7"),
            ("added", "wire", "W8"),
        },
    ),
    # An operation moved in the sequence and to another spot; one dropped.
    "elvez": (
        "elvez-cell",
        (
            ("Assembly_sequence.csv", "4;RC;GR12;J1.1-J3.2\n", "4;RC;GR12;J1.1-J3.1\n"),
            ("Assembly_sequence.csv", "9;TJ;WH2;J3.1\n", ""),
        ),
        {("changed", "operation", "RC GR12"), ("removed", "operation", "TJ WH2")},
    ),
    # A hose product's diameter.
    "enki": (
        "enki-hose",
        (("hoses.csv", "HX-16,16,", "HX-16,17,"),),
        {("changed", "hose", "HX-16")},
    ),
}


def _changes(case: str, tmp_path: Path) -> tuple[set[tuple[str, str, str]], Any]:
    folder, edits, _ = CASES[case]
    manifest = copy_cell(EXAMPLES / folder, tmp_path / folder)
    for name, old, new in edits:
        edit(manifest.parent / name, old, new)
    changes = diff_graphs(cadkg.build(EXAMPLES / folder / "manifest.toml"), cadkg.build(manifest))
    found = {(c.change, c.kind, c.id) for c in changes if c.kind != "file"}
    return found, changes


@pytest.mark.parametrize("case", sorted(CASES))
def test_the_changes_of_an_edited_example(case: str, tmp_path: Path) -> None:
    found, _ = _changes(case, tmp_path)
    assert found == CASES[case][2]


def test_the_attributes_of_a_harness_change(tmp_path: Path) -> None:
    _, changes = _changes("vw", tmp_path)
    by_id = {(c.kind, c.id): c for c in changes}
    assert by_id["segment", "B1–B2"].attributes == {"length": ("0.2", "0.21")}
    w6 = by_id["wire", "W6"].attributes
    assert w6["to"] == ("X4:2", "X4:3") and w6["colour"] == ("YE", "GN")
    assert by_id["segment", "B1–X1"].attributes["wires"][1] == ["W1", "W2", "W3", "W4", "W7", "W8"]
