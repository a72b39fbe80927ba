"""Forgiving reads of X3D scenes (WalkOptions): broken shapes skipped with one warning each,
frames kept, and only Transforms as items. The scene below has Blender's export quirks:
CRLF, a DOCTYPE, a root scaled to millimetres, a stray '>' in the root, a Coordinate DEF name
given again, a point list that is not triples, one with two numbers run together, an index
past the points, and a mesh wrapped in a DEF-named Group."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from pathlib import Path

import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.scene.read import WalkOptions, read_x3d
from cadkg.ingest.scene.records import SceneItem

Write = Callable[[str, str | bytes], Path]
LENIENT = WalkOptions(skip_broken_shapes=True, transforms_only=True)

BOX = 'coordIndex="0 1 2 -1 0 2 3 -1"'
SQUARE = 'point="0 0 0 10 0 0 10 10 0 0 10 0"'

LINES = [
    '<?xml version="1.0" encoding="UTF-8"?>',  # 1
    '<!DOCTYPE X3D PUBLIC "ISO//Web3D//DTD X3D 3.0//EN" "http://www.web3d.org/specifications/x3d-3.0.dtd">',
    '<X3D version="3.0" profile="Immersive">',
    "<head>",
    '<meta name="generator" content="Blender 2.83.0"/>',  # 5
    "</head>",
    "<Scene>",
    '<Transform DEF="ID0001"',
    'translation="0.000000 0.000000 0.000000"',
    'scale="0.001000 0.001000 0.001000"',  # 10
    'rotation="0.0 0.0 1.0 1.5707963267948966">',
    ">",
    f'<Shape><IndexedFaceSet {BOX}><Coordinate DEF="coords_ME_Plate" point="1 2 3 4"/>',
    "</IndexedFaceSet></Shape>",
    '<Transform DEF="ID0002" translation="100 0 13" scale="1 1 1" rotation="0 0 1 0">',  # 15
    f'<Shape><IndexedFaceSet {BOX}><Coordinate DEF="coords_ME_M1" {SQUARE}/>',
    "</IndexedFaceSet></Shape>",
    "</Transform>",
    '<Transform DEF="ID0003" translation="200 0 13" scale="1 1 1" rotation="0 0 1 0">',
    f'<Shape><IndexedFaceSet {BOX}><Coordinate DEF="coords_ME_M1" {SQUARE}/>',  # 20
    "</IndexedFaceSet></Shape>",
    "</Transform>",
    '<Transform DEF="ID0004" translation="300 0 13" scale="1 1 1" rotation="0 0 1 0">',
    '<Shape><IndexedFaceSet coordIndex="0 1 7 -1"><Coordinate point="0 0 0 1 0 0 1 1 0"/>',
    "</IndexedFaceSet></Shape>",  # 25
    "</Transform>",
    '<Transform DEF="ID0005" translation="400 0 13" scale="1 1 1" rotation="0 0 1 0">',
    '<Group DEF="group_ME_Comb"><Shape><IndexedFaceSet coordIndex="0 1 2 -1">',
    '<Coordinate point="0 0 0 1.51.5 0 0 1 0"/></IndexedFaceSet></Shape></Group>',
    "</Transform>",  # 30
    '<Transform DEF="ID0006" translation="500 0 13" scale="1 1 1" rotation="0 0 1 0">',
    f'<Group DEF="group_ME_Ok"><Shape><IndexedFaceSet {BOX}><Coordinate {SQUARE}/>',
    "</IndexedFaceSet></Shape></Group>",
    "</Transform>",
    "</Transform>",  # 35
    "</Scene>",
    "</X3D>",
]


@pytest.fixture
def blender(write: Write) -> Path:
    return write("platform_cad.x3d", "\r\n".join(LINES) + "\r\n")


def read(path: Path) -> tuple[dict[str, SceneItem], list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", IngestWarning)
        items = read_x3d(path, LENIENT)
    return {i.item_id: i for i in items}, [str(w.message) for w in caught]


def test_each_broken_shape_is_one_warning_at_its_line(blender: Path) -> None:
    _, messages = read(blender)
    shown = [m.split(": ", 1) for m in messages]
    assert [(where.rsplit(":", 1)[1], text) for where, text in shown] == [
        (
            "13",
            "shape of item ID0001 skipped, its item keeps its frame: 'point' of Coordinate has 4 numbers; "
            "coordIndex 1 of IndexedFaceSet is out of range ('1')",
        ),
        (
            "20",
            "shape of item ID0003 skipped, its item keeps its frame: "
            "DEF name coords_ME_M1 given twice (first on line 16)",
        ),
        (
            "24",
            "shape of item ID0004 skipped, its item keeps its frame: "
            "coordIndex 7 of IndexedFaceSet is out of range ('7')",
        ),
        (
            "28",
            "shape of item ID0005 skipped, its item keeps its frame: "
            "bad number in 'point' of Coordinate ('1.51.5')",
        ),
    ]
    assert all(where.startswith(str(blender)) for where, _ in shown)


def test_every_transform_keeps_its_frame_in_metres(blender: Path) -> None:
    items, _ = read(blender)
    assert list(items) == [f"ID000{i}" for i in range(1, 7)]  # the Groups are no items
    assert items["ID0001"].parent_id is None and items["ID0001"].mesh is None
    s = math.sqrt(0.5)
    assert items["ID0001"].rotation == pytest.approx((0.0, 0.0, s, s))
    for i in range(2, 7):
        child = items[f"ID000{i}"]
        assert child.parent_id == "ID0001"
        # The root's scale turns the children's millimetres into metres.
        assert child.translation == pytest.approx(((i - 1) * 0.1, 0.0, 0.013))
    assert [i for i, item in items.items() if item.mesh is not None] == ["ID0002", "ID0006"]
    # A Group's shape counts for its Transform: 10 mm squares, in metres.
    assert items["ID0006"].bbox_max == pytest.approx((0.01, 0.01, 0.0))


def test_the_same_scene_is_an_error_when_read_strictly(blender: Path) -> None:
    with pytest.raises(IngestError) as info:
        read_x3d(blender)
    reason = "DEF name coords_ME_M1 given twice (first on line 16)"
    assert (info.value.line, info.value.reason) == (20, reason)


def test_a_def_name_given_twice_on_a_transform_stays_an_error(write: Write) -> None:
    text = "\n".join(
        [
            '<X3D version="3.0"><Scene>',
            '<Transform DEF="ID0001"/>',
            '<Transform DEF="ID0001"/>',
            "</Scene></X3D>",
        ]
    )
    with pytest.raises(IngestError) as info:
        read_x3d(write("twice.x3d", text), LENIENT)
    assert (info.value.line, info.value.reason) == (3, "DEF name ID0001 given twice (first on line 2)")


def test_groups_are_items_unless_told(blender: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", IngestWarning)
        items = read_x3d(blender, WalkOptions(skip_broken_shapes=True))
    names = [i.item_id for i in items]
    assert "group_ME_Ok" in names and "group_ME_Comb" in names
