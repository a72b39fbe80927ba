"""The diff on small pairs of revisions: every kind of change an engineer would list."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest

import cadkg
from cadkg.changes import ChangeSet, Tolerances, diff_graphs
from tests.changes.cells import MINI, copy_cell, edit

DEFAULT = Tolerances()


def _diff(tmp_path: Path, *edits: tuple[str, str, str], tolerances: Tolerances = DEFAULT) -> ChangeSet:
    old = cadkg.build(MINI / "manifest.toml")
    manifest = copy_cell(MINI, tmp_path / "new")
    for name, before, after in edits:
        edit(manifest.parent / name, before, after)
    changes = diff_graphs(old, cadkg.build(manifest), tolerances=tolerances)
    # The edited file is a change of its own (its checksum), asserted once below.
    files = [c for c in changes if c.kind == "file"]
    assert [(c.id, list(c.attributes)) for c in files] == [(n, ["sha256"]) for n, _, _ in edits]
    kept = ChangeSet(changes.old, changes.new)
    for change in changes:
        if change.kind != "file":
            kept.of(change)
    return kept


def _items(changes: ChangeSet) -> dict[str, list[Any]]:
    data = changes.to_json()
    return {key: data[key] for key in ("added", "removed", "changed")}


def _plain(item: dict[str, Any]) -> dict[str, Any]:
    return {k: v for k, v in item.items() if k != "iri"}


def test_the_same_cell_has_no_change() -> None:
    assert not diff_graphs(cadkg.build(MINI / "manifest.toml"), cadkg.build(MINI / "manifest.toml"))


def test_a_renumbered_wire_is_one_change_of_its_number(tmp_path: Path) -> None:
    changes = _diff(tmp_path, ("connections.tsv", "\tW1\t", "\tW11\t"))
    assert [_plain(c) for c in _items(changes)["changed"]] == [
        {"kind": "wire", "id": "W11", "attributes": {"number": ["W1", "W11"]}}
    ]
    assert not changes.added and not changes.removed


def test_a_changed_end_keeps_the_wire(tmp_path: Path) -> None:
    changes = _diff(tmp_path, ("connections.tsv", "=-X1:2:b\tW2", "=-X1:2:a\tW2"))
    (changed,) = changes.changed
    assert (changed.kind, changed.id) == ("wire", "W2")
    assert changed.attributes == {"to": ("X1:2:b", "X1:2:a")}
    assert not changes.added and not changes.removed


def test_changed_attributes_of_a_wire(tmp_path: Path) -> None:
    changes = _diff(
        tmp_path,
        ("connections.tsv", "W3\t0,75 mm²\tBU\t-\t0V\t0,3 m", "W3\t1,5 mm²\tRD\t-\t0V\t0,35 m"),
    )
    (changed,) = changes.changed
    assert changed.id == "W3"
    assert changed.attributes == {
        "colour": ("BU", "RD"),
        "length": ("0.3", "0.35"),
        "section": ("0.75", "1.5"),
    }


def test_an_added_and_a_removed_wire(tmp_path: Path) -> None:
    line = "1\tQ\t=-K1:A2\t1\tQ\t=-K9:1\tW4\t0,75 mm²\tBU\t-\t0V\t0,3 m\t\tPUNTALINO_vite\tPUNTALINO_vite\n"
    added = line.replace("W4", "W5").replace("=-K1:A2", "=-K2:A1").replace("=-K9:1", "=-X1:2:a")
    changes = _diff(tmp_path, ("connections.tsv", line, added))
    assert [(c.kind, c.id) for c in changes.added] == [("wire", "W5")]
    assert ("wire", "W4") in [(c.kind, c.id) for c in changes.removed]


def test_a_moved_component_reports_its_offset(tmp_path: Path) -> None:
    changes = _diff(
        tmp_path,
        ("scene.x3d", '"ID000008" translation="0.3 0.5 0.0075"', '"ID000008" translation="0.32 0.5 0.0075"'),
    )
    moved = [c for c in changes.changed if c.kind == "component"]
    assert [c.id for c in moved] == ["K2"]
    (k2,) = moved
    old, new = k2.attributes["position"]
    assert new[0] - old[0] == pytest.approx(0.02)
    assert k2.offset is not None and k2.offset["distance"] == pytest.approx(0.02)
    assert k2.offset["translation"] == pytest.approx([0.02, 0.0, 0.0])
    # Its pins moved with it, not inside it: no pin is reported.
    assert not [c for c in changes.changed if c.kind == "pin"]


def test_a_move_within_the_tolerance_is_no_change(tmp_path: Path) -> None:
    changes = _diff(
        tmp_path,
        (
            "scene.x3d",
            '"ID000008" translation="0.3 0.5 0.0075"',
            '"ID000008" translation="0.3005 0.5 0.0075"',
        ),
    )
    assert not [c for c in changes.changed if c.kind == "component"]
    finer = _diff(
        tmp_path / "finer",
        (
            "scene.x3d",
            '"ID000008" translation="0.3 0.5 0.0075"',
            '"ID000008" translation="0.3005 0.5 0.0075"',
        ),
        tolerances=Tolerances(move=0.0001),
    )
    assert [c.id for c in finer.changed if c.kind == "component"] == ["K2"]


def test_a_turned_component_reports_its_rotation(tmp_path: Path) -> None:
    changes = _diff(
        tmp_path,
        ("scene.x3d", 'rotation="0 0 1 3.141592653589793"', 'rotation="0 0 1 1.5707963267948966"'),
    )
    (k2,) = [c for c in changes.changed if c.kind == "component" and c.id == "K2"]
    assert "orientation" in k2.attributes
    assert k2.offset is not None and k2.offset["rotation_deg"] == pytest.approx(90.0, abs=0.01)


def test_a_pin_moved_inside_its_model(tmp_path: Path) -> None:
    screw = '<couple name="A1">\n      <subitem name="screw"><pos name="x">0.005</pos>'
    changes = _diff(tmp_path, ("models.xml", screw, screw.replace("0.005", "0.008")))
    pins = sorted(c.id for c in changes.changed if c.kind == "pin")
    assert pins == ["K1:A1", "K2:A1"]  # both relays are of the changed model
    (k1,) = [c for c in changes.changed if c.id == "K1:A1"]
    assert k1.offset is not None and k1.offset["distance"] == pytest.approx(0.003)


def test_a_new_part_number_is_a_change_of_the_component(tmp_path: Path) -> None:
    changes = _diff(tmp_path, ("ids.wri", "ID000008\t=-K2\tRELAY", "ID000008\t=-K2\tAUX"))
    (k2,) = [c for c in changes.changed if c.kind == "component"]
    assert k2.id == "K2" and k2.attributes["partNumber"] == ("RELAY", "AUX")
