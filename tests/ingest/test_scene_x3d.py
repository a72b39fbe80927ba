"""The X3D scene reader: tests/data/readers/scene/*.x3d and small scenes written per test."""

from __future__ import annotations

import io
import math
import time
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest
import trimesh

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.scene.read import read_x3d
from cadkg.ingest.scene.records import IDENTITY_ROTATION, SceneItem
from cadkg.registry import reader_for, sniff_kind
from tests.ingest.test_scene import world, world_vertices

SCENE = Path(__file__).resolve().parents[1] / "data" / "readers" / "scene"
S = math.sqrt(0.5)
HALF_PI = "1.5707963267948966"

Write = Callable[[str, str | bytes], Path]


def x3d(body: str) -> str:
    return f'<?xml version="1.0" encoding="UTF-8"?>\n<X3D version="3.3">\n<Scene>\n{body}\n</Scene>\n</X3D>\n'


def by_id(items: list[SceneItem]) -> dict[str, SceneItem]:
    return {i.item_id: i for i in items}


def error(path: Path) -> IngestError:
    with pytest.raises(IngestError) as info:
        read_x3d(path)
    assert info.value.path == str(path)
    return info.value


@pytest.fixture(scope="module")
def cell() -> list[SceneItem]:
    return read_x3d(SCENE / "cell.x3d")


# --- the cell scene ------------------------------------------------------------------------------------


def test_items_in_document_order_with_parents_and_lines(cell: list[SceneItem]) -> None:
    assert [(i.item_id, i.parent_id, i.line) for i in cell] == [
        ("BASE", None, 9),
        ("ARM", "BASE", 14),
        ("TOOL", "ARM", 19),
        ("PANEL", "BASE", 24),
        ("FLOOR", None, 27),
        ("FOOT", "FLOOR", 29),
    ]
    assert {i.source for i in cell} == {str(SCENE / "cell.x3d")}


def test_poses(cell: list[SceneItem]) -> None:
    items = by_id(cell)
    expected = {
        "BASE": ((1, 2, 0), (0, 0, S, S)),
        "ARM": ((0.5, 0, 0), IDENTITY_ROTATION),
        # Through the non-DEF Transform: up 1, a quarter turn about x, then 1 along the turned y.
        "TOOL": ((0, 0, 2), (S, 0, 0, S)),
        "PANEL": ((0, 0, 0), IDENTITY_ROTATION),
        "FLOOR": ((0, 0, -1), (0, S, 0, S)),
        # FLOOR scales by 2: the foot's 1 along x is 2 in FLOOR's (rigid) frame.
        "FOOT": ((2, 0, 0), IDENTITY_ROTATION),
    }
    for item_id, (translation, rotation) in expected.items():
        assert items[item_id].translation == pytest.approx(translation, abs=1e-12), item_id
        assert items[item_id].rotation == pytest.approx(rotation, abs=1e-12), item_id


def test_a_child_of_a_turned_parent_ends_at_the_computed_point(cell: list[SceneItem]) -> None:
    # BASE turns 90° about z: ARM's 0.5 along x becomes 0.5 along y, from (1, 2, 0).
    np.testing.assert_allclose(world(cell, "ARM")[:3, 3], [1.0, 2.5, 0.0], atol=1e-12)
    # TOOL: ARM's (0, 0, 2) turned by nothing more, so (1, 2.5, 2); its x axis is the world's y.
    tool = world(cell, "TOOL")
    np.testing.assert_allclose(tool[:3, 3], [1.0, 2.5, 2.0], atol=1e-12)
    np.testing.assert_allclose(tool[:3, 0], [0.0, 1.0, 0.0], atol=1e-12)
    # FOOT: FLOOR turns x into -z and scales by 2, so 1 along x is (0, 0, -2) from (0, 0, -1).
    np.testing.assert_allclose(world(cell, "FOOT")[:3, 3], [0.0, 0.0, -3.0], atol=1e-12)


def test_bounding_boxes(cell: list[SceneItem]) -> None:
    items = by_id(cell)
    expected = {
        "BASE": ((-0.1, -0.2, -0.3), (0.1, 0.2, 0.3)),
        # A 0.1 box under a non-DEF Transform 0.1 up.
        "ARM": ((-0.05, -0.05, 0.05), (0.05, 0.05, 0.15)),
        "TOOL": ((-0.05, -0.1, -0.05), (0.05, 0.1, 0.05)),
        "FLOOR": ((-1, -1, -1), (1, 1, 1)),
        # The shared 0.2 x 0.4 x 0.6 PLATE and a 0.5 quad, both scaled by FLOOR's 2; the unused
        # point 9 9 9 is not geometry.
        "FOOT": ((-0.2, -0.4, -0.6), (1.0, 1.0, 0.6)),
    }
    for item_id, (low, high) in expected.items():
        assert items[item_id].bbox_min == pytest.approx(low, abs=1e-12), item_id
        assert items[item_id].bbox_max == pytest.approx(high, abs=1e-12), item_id
    assert items["PANEL"].bbox_min is None
    assert items["PANEL"].bbox_max is None
    assert items["PANEL"].mesh is None


def test_meshes_are_in_the_item_frame(cell: list[SceneItem]) -> None:
    items = by_id(cell)
    assert {k: len(v.mesh.faces) for k, v in items.items() if v.mesh is not None} == {
        "BASE": 12,
        "ARM": 12,
        "TOOL": 128,
        "FLOOR": 12,
        "FOOT": 12 + 2,  # the quad is two triangles
    }
    # In the world, FOOT's quad lies in FLOOR's turned plane: x = 0 .. 1 became z = -3 .. -4.
    vertices = world_vertices(cell, "FOOT")
    np.testing.assert_allclose(vertices.min(axis=0), [-0.6, -0.4, -4.0], atol=1e-12)
    np.testing.assert_allclose(vertices.max(axis=0), [0.6, 1.0, -2.8], atol=1e-12)


def test_stl_of_an_item(cell: list[SceneItem]) -> None:
    mesh = by_id(cell)["FOOT"].mesh
    assert mesh is not None
    data = mesh.to_stl()
    assert len(data) == 84 + 50 * 14
    loaded = trimesh.load(io.BytesIO(data), file_type="stl", process=False)
    assert len(loaded.faces) == 14
    np.testing.assert_allclose(loaded.bounds, [[-0.2, -0.4, -0.6], [1.0, 1.0, 0.6]], atol=1e-6)


# --- transforms ----------------------------------------------------------------------------------------


def test_center_rotation(write: Write) -> None:
    path = write("c.x3d", x3d(f'<Transform DEF="C" center="1 0 0" rotation="0 0 1 {HALF_PI}"/>'))
    (item,) = read_x3d(path)
    # Turning about (1, 0, 0) moves the origin to (1, -1, 0).
    assert item.translation == pytest.approx((1, -1, 0), abs=1e-12)
    assert item.rotation == pytest.approx((0, 0, S, S), abs=1e-12)


def test_scale_orientation_stays_in_the_geometry(write: Write) -> None:
    body = (
        '<Transform DEF="S" scale="2 1 1" scaleOrientation="0 0 1 0.7853981633974483">'
        '<Shape><Box size="1 1 1"/></Shape></Transform>'
    )
    (item,) = read_x3d(write("s.x3d", x3d(body)))
    assert item.rotation == pytest.approx(IDENTITY_ROTATION, abs=1e-12)
    # The stretch along the diagonal sends corner (0.5, 0.5) to (1, 1) and (0.5, -0.5) nowhere new.
    assert item.bbox_min == pytest.approx((-1, -1, -0.5), abs=1e-12)
    assert item.bbox_max == pytest.approx((1, 1, 0.5), abs=1e-12)


def test_uniform_scale_of_a_parent_flows_into_the_child_geometry_only(write: Write) -> None:
    body = f"""
<Transform DEF="P" rotation="0 0 1 {HALF_PI}" scale="3 3 3">
  <Transform DEF="C" translation="1 0 0" rotation="1 0 0 {HALF_PI}">
    <Shape><Box size="1 1 1"/></Shape>
  </Transform>
</Transform>"""
    items = by_id(read_x3d(write("u.x3d", x3d(body))))
    parent, child = items["P"], items["C"]
    assert parent.rotation == pytest.approx((0, 0, S, S), abs=1e-12)
    assert child.translation == pytest.approx((3, 0, 0), abs=1e-12)
    assert child.rotation == pytest.approx((S, 0, 0, S), abs=1e-12)
    assert math.fsum(v * v for v in child.rotation) == pytest.approx(1.0, abs=1e-12)
    assert child.bbox_min == pytest.approx((-1.5, -1.5, -1.5), abs=1e-12)
    assert child.bbox_max == pytest.approx((1.5, 1.5, 1.5), abs=1e-12)


def test_a_mirror_stays_in_the_geometry(write: Write) -> None:
    body = (
        '<Transform DEF="M" scale="-1 1 1"><Transform translation="1 0 0">'
        '<Shape><Box size="0.2 0.2 0.2"/></Shape></Transform></Transform>'
    )
    items = read_x3d(write("m.x3d", x3d(body)))
    assert math.fsum(v * v for v in items[0].rotation) == pytest.approx(1.0)
    # Whatever frame the mirror gets, the box lands at x = -1 in the world.
    np.testing.assert_allclose(world_vertices(items, "M").mean(axis=0), [-1.0, 0.0, 0.0], atol=1e-12)


def test_numbers_may_be_separated_by_commas(write: Write) -> None:
    (item,) = read_x3d(write("n.x3d", x3d('<Transform DEF="A" translation=" 1,2 , 3e-1 "/>')))
    assert item.translation == pytest.approx((1, 2, 0.3))


# --- geometry ------------------------------------------------------------------------------------------


def test_indexed_triangle_set_and_empty_face_set(write: Write) -> None:
    body = """
<Transform DEF="T">
  <Shape>
    <IndexedTriangleSet index="0 1 2 2 1 3"><Coordinate point="0 0 0 1 0 0 0 1 0 1 1 1"/></IndexedTriangleSet>
  </Shape>
</Transform>
<Transform DEF="E">
  <Shape><IndexedFaceSet coordIndex=""><Coordinate point=""/></IndexedFaceSet></Shape>
</Transform>"""
    items = by_id(read_x3d(write("t.x3d", x3d(body))))
    mesh = items["T"].mesh
    assert mesh is not None
    assert mesh.faces.tolist() == [[0, 1, 2], [2, 1, 3]]
    assert items["T"].bbox_max == pytest.approx((1, 1, 1))
    assert items["E"].mesh is None
    assert items["E"].bbox_min is None


def read_warned(path: Path) -> tuple[list[SceneItem], list[tuple[int | None, str]]]:
    """The items of ``path`` and the (line, reason) of each warning reading them gave."""
    with pytest.warns(IngestWarning) as record:
        items = read_x3d(path)
    return items, [(w.message.line, w.message.reason) for w in record if isinstance(w.message, IngestWarning)]


def test_unread_geometry_and_nodes_are_skipped_with_a_warning(write: Write) -> None:
    body = """<Transform DEF="A">
<Shape><ElevationGrid xDimension="2" zDimension="2" height="0 0 0 0"/></Shape>
<Shape><Box/></Shape>
<FancyNode/>
<Viewpoint position="0 0 10"/>
</Transform>"""
    (item,), messages = read_warned(write("w.x3d", x3d(body)))
    assert messages == [
        (5, "ElevationGrid geometry is not read; skipped"),
        (7, "FancyNode node is not read (not a grouping, Shape or Inline node); skipped"),
    ]
    assert item.bbox_max == pytest.approx((1, 1, 1))  # the default Box is 2 wide


def test_a_face_set_without_coordinates_and_a_zero_scale_warn(write: Write) -> None:
    body = """<Transform DEF="A">
<Shape><IndexedFaceSet coordIndex="0 1 2 -1"/></Shape>
<Transform scale="1 0 1"><Shape><Box size="0.2 0.2 0.2"/></Shape></Transform>
</Transform>"""
    (item,), messages = read_warned(write("z.x3d", x3d(body)))
    assert messages == [
        (5, "IndexedFaceSet has a coordIndex but no coordinates; skipped"),
        (6, "'scale' of Transform has a zero factor; the geometry below it is flat"),
    ]
    assert item.bbox_min == pytest.approx((-0.1, 0, -0.1))
    assert item.bbox_max == pytest.approx((0.1, 0, 0.1))  # flattened, as the file says


def test_shapes_outside_items_give_one_warning(write: Write) -> None:
    body = (
        '<Shape><Box/></Shape><Transform translation="1 0 0"><Shape><Box/></Shape></Transform>'
        '<Group DEF="G"/>'
    )
    with pytest.warns(IngestWarning, match=r"2 shape\(s\) outside any DEF-named"):
        items = read_x3d(write("l.x3d", x3d(body)))
    assert [i.item_id for i in items] == ["G"]


def test_switch_reads_the_chosen_child_and_lod_the_first_level(write: Write) -> None:
    body = """
<Switch DEF="SW" whichChoice="1">
  <Transform DEF="NOT_SHOWN"/>
  <Transform DEF="SHOWN" translation="0 1 0"/>
</Switch>
<LOD DEF="LOD">
  <Transform DEF="FINE"/>
  <Transform DEF="COARSE"/>
</LOD>
<Collision DEF="COL"><Anchor DEF="ANC"><Billboard DEF="BB"/></Anchor></Collision>"""
    items = read_x3d(write("sw.x3d", x3d(body)))
    assert [(i.item_id, i.parent_id) for i in items] == [
        ("SW", None),
        ("SHOWN", "SW"),
        ("LOD", None),
        ("FINE", "LOD"),
        ("COL", None),
        ("ANC", "COL"),
        ("BB", "ANC"),
    ]


def test_def_on_shapes_is_not_an_item_and_use_shares_it(write: Write) -> None:
    body = """
<Transform DEF="A"><Shape DEF="S"><Box size="1 2 3"/></Shape></Transform>
<Transform DEF="B" translation="5 0 0"><Shape USE="S"/></Transform>"""
    items = by_id(read_x3d(write("u.x3d", x3d(body))))
    assert sorted(items) == ["A", "B"]
    assert items["B"].bbox_max == items["A"].bbox_max == pytest.approx((0.5, 1, 1.5))


# --- namespaces and XML safety -------------------------------------------------------------------------


def test_the_x3d_namespace_is_read(write: Write) -> None:
    text = (
        '<X3D xmlns="http://www.web3d.org/specifications/x3d-namespace"><Scene><Group DEF="G"/></Scene></X3D>'
    )
    assert [i.item_id for i in read_x3d(write("ns.x3d", text))] == ["G"]


def test_the_dtd_is_not_fetched(write: Write) -> None:
    # 192.0.2.0/24 is reserved for documentation: a fetch would hang until a timeout.
    text = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<!DOCTYPE X3D PUBLIC "ISO//Web3D//DTD X3D 3.3//EN" "http://192.0.2.1/x3d-3.3.dtd">\n'
        '<X3D><Scene><Group DEF="G"/></Scene></X3D>\n'
    )
    started = time.perf_counter()
    assert [i.item_id for i in read_x3d(write("dtd.x3d", text))] == ["G"]
    assert time.perf_counter() - started < 2.0


def test_entity_declarations_are_refused_before_parsing() -> None:
    started = time.perf_counter()
    err = error(SCENE / "entity.x3d")
    assert time.perf_counter() - started < 1.0
    assert err.line == 3
    assert err.reason == "<!ENTITY> is not allowed in X3D"
    assert err.found == "<!ENTITY"


def test_predefined_character_references_still_work(write: Write) -> None:
    (item,) = read_x3d(write("amp.x3d", x3d('<Group DEF="A&amp;B"/>')))
    assert item.item_id == "A&B"


# --- malformed input -----------------------------------------------------------------------------------


def test_xml_syntax_error() -> None:
    err = error(SCENE / "bad-syntax.x3d")
    assert err.line == 5
    assert err.reason.startswith("malformed XML: Opening and ending tag mismatch: Transform line 3 and Group")


def test_missing_scene() -> None:
    err = error(SCENE / "no-scene.x3d")
    assert err.line == 2
    assert err.reason == "no <Scene> in <X3D>"
    assert err.found == "<head>, <scene>"


def test_not_x3d(write: Write) -> None:
    path = write("svg.x3d", '<svg xmlns="http://www.w3.org/2000/svg"><Scene/></svg>')
    err = error(path)
    assert (err.line, err.reason, err.found) == (
        1,
        "not an X3D document",
        "<{http://www.w3.org/2000/svg}svg>",
    )


def test_bad_number() -> None:
    err = error(SCENE / "bad-number.x3d")
    assert err.line == 4
    assert err.reason == "bad number in 'translation' of Transform"
    assert err.found == "1O"
    assert err.expected is not None and "decimal number" in err.expected


@pytest.mark.parametrize(
    ("attribute", "reason", "found"),
    [
        ('translation="0.5 0,5 1"', "'translation' of Transform has 4 number(s)", "0.5 0,5 1"),
        ('rotation="0 0 0 1"', "'rotation' of Transform has a zero axis and a non-zero angle", "0 0 0 1"),
        ('scale="1 1 nan"', "bad number in 'scale' of Transform", "nan"),
        ('center="1e999 0 0"', "bad number in 'center' of Transform", "1e999"),
    ],
)
def test_bad_transform_fields(write: Write, attribute: str, reason: str, found: str) -> None:
    err = error(write("t.x3d", x3d(f'<Group DEF="G">\n<Transform DEF="T" {attribute}/></Group>')))
    assert (err.line, err.reason, err.found) == (5, reason, found)


def test_coord_index_out_of_range() -> None:
    err = error(SCENE / "bad-coordindex.x3d")
    assert err.line == 5
    assert err.reason == "coordIndex 4 of IndexedFaceSet is out of range"
    assert err.expected == "-1 or an index below 4 (the Coordinate has 4 points)"


def test_use_of_an_item() -> None:
    err = error(SCENE / "use-item.x3d")
    assert err.line == 8
    assert err.reason.startswith("USE HOLDER repeats item HOLDER")
    assert "an item ID must name one thing" in err.reason


def test_use_of_an_inline_holding_items(write: Write) -> None:
    write("part.x3d", x3d('<Transform DEF="PART"/>'))
    body = (
        '<Group DEF="A"><Inline DEF="IN" url=\'"part.x3d"\'/></Group>\n'
        '<Group DEF="B"><Inline USE="IN"/></Group>'
    )
    err = error(write("top.x3d", x3d(body)))
    assert err.line == 5
    assert err.reason.startswith("USE IN repeats item PART")


def test_duplicate_def_and_undefined_use(write: Write) -> None:
    err = error(write("d.x3d", x3d('<Group DEF="A"/>\n<Box DEF="A"/>')))
    assert (err.line, err.reason) == (5, "DEF name A given twice (first on line 4)")
    err = error(write("u.x3d", x3d('<Group DEF="A"/>\n<Group USE="B"/>')))
    assert (err.line, err.reason, err.found) == (5, "USE of an undefined name in <Group>", "B")


def test_length_units_other_than_metres_are_refused(write: Write) -> None:
    text = """<X3D version="3.3"><head>
<unit category="length" name="millimetre" conversionFactor="0.001"/>
</head><Scene><Group DEF="G"/></Scene></X3D>"""
    err = error(write("mm.x3d", text))
    assert (err.line, err.reason, err.found) == (
        2,
        "a length unit other than metres is declared",
        "conversionFactor=0.001",
    )


def test_deep_nesting_is_a_located_error(write: Write) -> None:
    body = "<Group>" * 150 + "</Group>" * 150
    err = error(write("deep.x3d", x3d(body)))
    assert err.reason == "elements nest deeper than 100 levels"
    assert err.line == 4
    # Deeper still, the XML parser stops first, with its own limit and no advice to lift it.
    err = error(write("deeper.x3d", x3d("<Group>\n" * 300 + "</Group>" * 300)))
    assert err.reason == "elements nest deeper than 256 levels"
    assert err.line == 3 + 255  # the 255th Group, 257th element down from <X3D>


# --- Inline --------------------------------------------------------------------------------------------


def test_inline_of_vrml_that_inlines_x3d() -> None:
    items = read_x3d(SCENE / "inline-top.x3d")
    assert [(i.item_id, i.parent_id, i.source, i.line) for i in items] == [
        ("RACK", None, str(SCENE / "inline-top.x3d"), 4),
        ("PART", "RACK", str(SCENE / "parts" / "part.wrl"), 2),
        ("SCREW", "PART", str(SCENE / "parts" / "sub.x3d"), 3),
    ]
    np.testing.assert_allclose(world(items, "SCREW")[:3, 3], [1.0, 0.0, 1.5])
    assert by_id(items)["SCREW"].bbox_max == pytest.approx((0.01, 0.01, 0.01))


@pytest.mark.parametrize(
    ("name", "line", "reason", "found"),
    [
        ("cycle-a.x3d", 3, "Inline cycle: cycle-a.x3d → cycle-b.wrl → cycle-a.x3d", None),
        (
            "inline-escape.x3d",
            4,
            "Inline url leads outside the directory of the scene file",
            "../outside.x3d",
        ),
    ],
)
def test_inline_errors(name: str, line: int, reason: str, found: str | None) -> None:
    with pytest.raises(IngestError) as info:
        read_x3d(SCENE / name)
    err = info.value
    assert (err.line, err.reason, err.found) == (line, reason, found)


def test_inline_cycle_is_reported_where_it_closes() -> None:
    with pytest.raises(IngestError) as info:
        read_x3d(SCENE / "cycle-a.x3d")
    assert info.value.path == str(SCENE / "cycle-b.wrl")


@pytest.mark.parametrize(
    ("url", "reason"),
    [
        ('"/etc/passwd.x3d"', "Inline url is an absolute path"),
        ('"C:\\\\scenes\\\\part.x3d"', "Inline url is an absolute path"),
        (
            '"urn:web3d:part" "ftp://example.com/part.x3d"',
            "Inline url is not a local file; network resources are never read",
        ),
        ('"missing.x3d"', "Inline file not found"),
        ('"part.x3dz"', "Inline file type is not read"),
        ('"sub/../../x/part.x3d"', "Inline url leads outside the directory of the scene file"),
    ],
)
def test_inline_url_errors(tmp_path: Path, url: str, reason: str) -> None:
    scene = tmp_path / "scene"
    scene.mkdir()
    (scene / "part.x3dz").write_bytes(b"")
    (tmp_path / "x").mkdir()
    (tmp_path / "x" / "part.x3d").write_text(x3d('<Group DEF="X"/>'))
    path = scene / "top.x3d"
    path.write_text(x3d(f"<Group DEF=\"A\">\n<Inline url='{url}'/></Group>"))
    err = error(path)
    assert (err.line, err.reason) == (5, reason)


def test_inline_without_url_is_skipped_with_a_warning(write: Write) -> None:
    with pytest.warns(IngestWarning, match="Inline without url; skipped"):
        (item,) = read_x3d(write("top.x3d", x3d('<Group DEF="A"><Inline url=\'"" \'/></Group>')))
    assert item.mesh is None


def test_def_names_must_be_unique_across_inline_files(write: Write) -> None:
    part = write("part.x3d", x3d('\n<Transform DEF="A"/>'))
    top = write("top.x3d", x3d('<Group DEF="A"><Inline url=\'"part.x3d"\'/></Group>'))
    with pytest.raises(IngestError) as info:
        read_x3d(top)
    err = info.value
    assert (err.path, err.line) == (str(part), 5)
    assert err.reason == f"DEF name A is already defined at {top}:4"


def test_one_file_inlined_twice_is_refused(write: Write) -> None:
    write("part.x3d", x3d('<Transform DEF="P"/>'))
    body = (
        '<Group DEF="A"><Inline url=\'"part.x3d"\'/></Group>'
        '<Group DEF="B"><Inline url=\'"part.x3d"\'/></Group>'
    )
    top = write("top.x3d", x3d(body))
    with pytest.raises(IngestError) as info:
        read_x3d(top)
    assert info.value.path == str(top.parent / "part.x3d")
    assert info.value.reason == (
        f"DEF name P is already defined at {top.parent / 'part.x3d'}:4; the file is inlined more than once"
    )


def test_an_inline_without_items_may_be_shared(write: Write) -> None:
    write("bolt.x3d", x3d('<Shape><Box size="0.1 0.1 0.1"/></Shape>'))
    body = (
        '<Group DEF="A"><Inline DEF="BOLT" url="bolt.x3d"/></Group>'
        '<Group DEF="B"><Inline USE="BOLT"/></Group>'
    )
    items = by_id(read_x3d(write("top.x3d", x3d(body))))
    assert items["A"].bbox_max == items["B"].bbox_max == pytest.approx((0.05, 0.05, 0.05))


# --- registry and size ---------------------------------------------------------------------------------


def test_registry_picks_x3d_by_suffix() -> None:
    assert sniff_kind(SCENE / "cell.x3d") == "x3d"
    assert sniff_kind(SCENE / "CELL.X3D", head=b"") == "x3d"
    assert reader_for("x3d").read is read_x3d


@pytest.mark.slow
def test_ten_thousand_boxes_read_in_seconds(write: Write) -> None:
    body = "\n".join(
        f'<Transform DEF="ID{i:06d}" translation="{i * 0.1} 0 0" rotation="0 1 0 0.3">'
        f'<Shape><Box size="0.1 0.2 0.3"/></Shape></Transform>'
        for i in range(10_000)
    )
    path = write("big.x3d", x3d(body))
    started = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        items = read_x3d(path)
    assert time.perf_counter() - started < 10.0
    assert len(items) == 10_000
    assert items[-1].translation == pytest.approx((999.9, 0, 0))
