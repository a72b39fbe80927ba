"""The VRML97 scene reader: tests/data/readers/scene/*.wrl and small scenes written per test."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.scene.read import read_vrml, read_x3d
from cadkg.ingest.scene.records import IDENTITY_ROTATION
from cadkg.ingest.scene.vrml import parse_vrml
from cadkg.registry import sniff_kind
from tests.ingest.test_scene import world

SCENE = Path(__file__).resolve().parents[1] / "data" / "readers" / "scene"
S = math.sqrt(0.5)

Write = Callable[[str, str | bytes], Path]


def wrl(body: str) -> str:
    return f"#VRML V2.0 utf8\n{body}\n"


def error(path: Path) -> IngestError:
    with pytest.raises(IngestError) as info:
        read_vrml(path)
    assert info.value.path == str(path)
    return info.value


# --- the cell scene, in both encodings -----------------------------------------------------------------


def test_vrml_and_x3d_give_the_same_items() -> None:
    vrml, x3d = read_vrml(SCENE / "cell.wrl"), read_x3d(SCENE / "cell.x3d")
    assert [(i.item_id, i.parent_id) for i in vrml] == [(i.item_id, i.parent_id) for i in x3d]
    assert len(vrml) == 6
    for a, b in zip(vrml, x3d, strict=True):
        assert a.translation == pytest.approx(b.translation, abs=1e-12), a.item_id
        assert a.rotation == pytest.approx(b.rotation, abs=1e-12), a.item_id
        assert (a.bbox_min is None) == (b.bbox_min is None)
        if a.bbox_min is not None and b.bbox_min is not None and a.bbox_max and b.bbox_max:
            assert a.bbox_min == pytest.approx(b.bbox_min, abs=1e-12), a.item_id
            assert a.bbox_max == pytest.approx(b.bbox_max, abs=1e-12), a.item_id
        if a.mesh is not None and b.mesh is not None:
            np.testing.assert_allclose(a.mesh.vertices, b.mesh.vertices, atol=1e-12)
            np.testing.assert_array_equal(a.mesh.faces, b.mesh.faces)
        else:
            assert a.mesh is b.mesh is None


def test_cell_lines_and_a_computed_pose() -> None:
    items = read_vrml(SCENE / "cell.wrl")
    assert [(i.item_id, i.line) for i in items] == [
        ("BASE", 4),
        ("ARM", 12),
        ("TOOL", 19),
        ("PANEL", 26),
        ("FLOOR", 29),
        ("FOOT", 33),
    ]
    np.testing.assert_allclose(world(items, "TOOL")[:3, 3], [1.0, 2.5, 2.0], atol=1e-12)
    assert items[2].rotation == pytest.approx((S, 0, 0, S), abs=1e-12)


# --- syntax --------------------------------------------------------------------------------------------


def test_comments_commas_strings_and_routes(write: Write) -> None:
    body = r"""
# a comment with "quotes" and [ brackets {
DEF A Transform { # the item
  translation 1,2,3, rotation 0 0 1 0
  children [ WorldInfo { title "a \"quoted\" # not a comment" info [ "x\\y", "" ] } ]
}
ROUTE A.translation_changed TO A.set_translation
"""
    path = write("s.wrl", wrl(body))
    (item,) = read_vrml(path)
    assert item.translation == (1.0, 2.0, 3.0)
    assert item.rotation == IDENTITY_ROTATION
    info = parse_vrml(path).roots[0].nodes["children"][0]
    assert info.fields["title"].raw == ['a "quoted" # not a comment']
    assert info.fields["info"].raw == ["x\\y", ""]


def test_protos_are_skipped_and_their_instances_warned(write: Write) -> None:
    body = """
PROTO Bolt [ field SFFloat length 0.1 exposedField MFNode parts [] ] {
  Transform { children [ Shape { geometry Box { size IS length } } ] }
}
EXTERNPROTO Nut [ field SFFloat size ] [ "nut.wrl#Nut" "https://example.com/nut.wrl#Nut" ]
EXTERNPROTO Washer [ ] "washer.wrl"
DEF A Transform {
  children [
    Bolt { length 0.2 parts [ Shape { geometry Box { } } ] }
    Shape { geometry Box { size 1 1 1 } }
  ]
}
"""
    with pytest.warns(IngestWarning) as record:
        (item,) = read_vrml(write("p.wrl", wrl(body)))
    assert [(w.message.line, w.message.reason) for w in record if isinstance(w.message, IngestWarning)] == [
        (10, "Bolt node is not read (not a grouping, Shape or Inline node); skipped")
    ]
    assert item.bbox_max == pytest.approx((0.5, 0.5, 0.5))


def test_scripts_and_unknown_nodes_are_parsed_generically(write: Write) -> None:
    body = """
DEF A Group {
  children [
    DEF S Script {
      eventIn SFTime touched
      eventOut SFBool active
      field SFNode target NULL
      field MFFloat weights [ 1 2 3 ]
      url "javascript: function touched(v) { active = TRUE; }"
      directOutput TRUE
    }
    Gizmo { size 1 2 3 flag FALSE names [ "a" "b" ] node Box { } list [ Box { } USE S ] nothing NULL }
  ]
}
"""
    with pytest.warns(IngestWarning, match="Gizmo node is not read") as record:
        (item,) = read_vrml(write("u.wrl", wrl(body)))
    assert len(record) == 1
    assert item.item_id == "A"
    assert item.mesh is None


def test_use_of_shared_geometry(write: Write) -> None:
    body = """
DEF A Transform { children Shape { geometry DEF G Box { size 1 2 3 } } }
DEF B Transform { translation 4 0 0 children Shape { geometry USE G } }
"""
    a, b = read_vrml(write("g.wrl", wrl(body)))
    assert a.bbox_max == b.bbox_max == pytest.approx((0.5, 1.0, 1.5))
    assert b.translation == (4.0, 0.0, 0.0)


def test_quad_face_set_is_two_triangles(write: Write) -> None:
    body = """DEF Q Transform { children Shape { geometry IndexedFaceSet {
  coord Coordinate { point [ 0 0 0, 2 0 0, 2 1 0, 0 1 0 ] }
  coordIndex [ 0, 1, 2, 3 ]
} } }"""
    (item,) = read_vrml(write("q.wrl", wrl(body)))
    assert item.mesh is not None
    assert item.mesh.faces.tolist() == [[0, 1, 2], [0, 2, 3]]
    assert len(item.mesh.to_stl()) == 84 + 2 * 50
    assert (item.bbox_min, item.bbox_max) == ((0.0, 0.0, 0.0), (2.0, 1.0, 0.0))


def test_switch_choice_and_lod_level(write: Write) -> None:
    body = """
DEF SW Switch { whichChoice 0 choice [ DEF ON Group { } DEF OFF Group { } ] }
DEF L LOD { range [ 10 ] level [ DEF NEAR Group { } DEF FAR Group { } ] }
"""
    items = read_vrml(write("sw.wrl", wrl(body)))
    assert [(i.item_id, i.parent_id) for i in items] == [
        ("SW", None),
        ("ON", "SW"),
        ("L", None),
        ("NEAR", "L"),
    ]


def test_a_byte_order_mark_before_the_header(write: Write) -> None:
    (item,) = read_vrml(write("bom.wrl", b"\xef\xbb\xbf" + wrl("DEF A Group { }").encode()))
    assert item.line == 2


def test_an_empty_scene_warns(write: Write) -> None:
    with pytest.warns(IngestWarning, match="no items"):
        assert read_vrml(write("e.wrl", wrl("# nothing here"))) == []


# --- malformed input -----------------------------------------------------------------------------------


def test_vrml1_header() -> None:
    err = error(SCENE / "wrong-header.wrl")
    assert (err.line, err.reason, err.found) == (1, "VRML 1.0 is not read", "#VRML V1.0 ascii")


def test_other_header(write: Write) -> None:
    err = error(write("x.wrl", "#X3D V3.3 utf8\nGroup { }\n"))
    assert (err.line, err.reason, err.found) == (1, "not a VRML97 file", "#X3D V3.3 utf8")
    assert err.expected == "a VRML97 file starting with '#VRML V2.0 utf8'"


def test_unterminated_bracket() -> None:
    err = error(SCENE / "unterminated-bracket.wrl")
    assert err.line == 3
    assert err.reason == "unexpected end of file: '[' on line 3 is never closed"


def test_unexpected_end_of_file() -> None:
    err = error(SCENE / "unexpected-eof.wrl")
    assert (err.line, err.reason, err.expected) == (5, "unexpected end of file", "a DEF name")


@pytest.mark.parametrize(
    ("body", "line", "reason", "found"),
    [
        ('DEF A Group { }\nWorldInfo { title "no end }\n', 3, "unterminated string", '"no end }\n\n'),
        (
            "DEF A Transform {\n translation 0 0 0\n",
            2,
            "unexpected end of file: '{' on line 2 is never closed",
            None,
        ),
        ("DEF A Transform { translation 1 2 3 ] }", 2, "unexpected token", "]"),
        ("DEF A Transform { children [ Box { } } ] }", 2, "unexpected token", "}"),
        ("Group { children [ 1 2 ] }\n{", 3, "unexpected token", "{"),
        ("DEF A Group { }\nDEF 12 Group { }", 3, "unexpected token", "12"),
        ("DEF A Group { }\nUSE TRUE", 3, "unexpected token", "TRUE"),
        ("DEF A Transform { translation 1 2 3.4.5 }", 2, "bad number in 'translation' of Transform", "3.4.5"),
        (
            "DEF A Transform {\n\n rotation 0 0 0 1 }",
            4,
            "'rotation' of Transform has a zero axis and a non-zero angle",
            "0 0 0 1",
        ),
        ("DEF A Group {\n children USE B }", 3, "USE of an undefined name", "B"),
        ("ROUTE A.x FROM B.y", 2, "unexpected token", "FROM"),
        ("PROTO P [ field SFFloat x 1 { }", 2, "unexpected end of file: '[' on line 2 is never closed", None),
    ],
)
def test_syntax_errors(write: Write, body: str, line: int, reason: str, found: str | None) -> None:
    err = error(write("bad.wrl", wrl(body)))
    assert (err.line, err.reason, err.found) == (line, reason, found)


def test_zero_rotation_axis() -> None:
    err = error(SCENE / "zero-axis.wrl")
    assert (err.line, err.found) == (5, "0 0 0 1.2")
    assert err.reason == "'rotation' of Transform has a zero axis and a non-zero angle"


def test_duplicate_def() -> None:
    err = error(SCENE / "duplicate-def.wrl")
    assert (err.line, err.reason, err.found) == (
        4,
        "DEF name ID000041 given twice (first on line 2)",
        "ID000041",
    )


def test_use_of_an_item(write: Write) -> None:
    body = "DEF A Group { children [ DEF B Transform { } ] }\nDEF C Group { children [ USE B ] }"
    err = error(write("u.wrl", wrl(body)))
    assert err.line == 3
    assert err.reason.startswith("USE B repeats item B")


def test_index_out_of_range(write: Write) -> None:
    body = """DEF A Group { children Shape { geometry IndexedTriangleSet {
  coord Coordinate { point [ 0 0 0 1 0 0 0 1 0 ] }
  index [ 0 1 -1 ]
} } }"""
    err = error(write("i.wrl", wrl(body)))
    assert (err.line, err.reason) == (4, "index -1 of IndexedTriangleSet is out of range")
    assert err.expected == "an index below 3 (the Coordinate has 3 points)"


def test_deep_nesting_is_a_located_error(write: Write) -> None:
    body = "Group { children [ " * 150 + "] } " * 150
    err = error(write("deep.wrl", wrl(body)))
    assert (err.line, err.reason) == (2, "nodes nest deeper than 100 levels")


# --- Inline --------------------------------------------------------------------------------------------


def test_inline_network_url() -> None:
    err = error(SCENE / "inline-network.wrl")
    assert (err.line, err.found) == (4, "https://example.com/cell.wrl")
    assert err.reason == "Inline url is not a local file; network resources are never read"


def test_inline_cycle_from_vrml() -> None:
    with pytest.raises(IngestError) as info:
        read_vrml(SCENE / "cycle-b.wrl")
    err = info.value
    assert (err.path, err.line) == (str(SCENE / "cycle-a.x3d"), 4)
    assert err.reason == "Inline cycle: cycle-b.wrl → cycle-a.x3d → cycle-b.wrl"


def test_inline_relative_to_the_inlining_file(write: Write, tmp_path: Path) -> None:
    (tmp_path / "sub").mkdir()
    write("sub/a.wrl", wrl('DEF A Transform { translation 1 0 0 children Inline { url "b.wrl" } }'))
    write("sub/b.wrl", wrl("DEF B Transform { translation 0 1 0 }"))
    top = write("top.wrl", wrl('DEF T Group { children Inline { url [ "sub/a.wrl" ] } }'))
    items = read_vrml(top)
    assert [(i.item_id, i.parent_id, i.source) for i in items] == [
        ("T", None, str(top)),
        ("A", "T", str(tmp_path / "sub" / "a.wrl")),
        ("B", "A", str(tmp_path / "sub" / "b.wrl")),
    ]
    np.testing.assert_allclose(world(items, "B")[:3, 3], [1.0, 1.0, 0.0])


def test_inline_error_is_located_in_the_inlined_file(write: Write) -> None:
    part = write("part.wrl", wrl("DEF P Transform {\n translation 1 x 0 }"))
    top = write("top.wrl", wrl('DEF T Group { children Inline { url "part.wrl" } }'))
    with pytest.raises(IngestError) as info:
        read_vrml(top)
    assert (info.value.path, info.value.line) == (str(part), 3)


# --- registry ------------------------------------------------------------------------------------------


def test_registry_picks_vrml_by_suffix_and_header(tmp_path: Path) -> None:
    assert sniff_kind(SCENE / "cell.wrl") == "vrml"
    renamed = tmp_path / "scene.dat"
    renamed.write_bytes((SCENE / "cell.wrl").read_bytes())
    assert sniff_kind(renamed) == "vrml"
    assert sniff_kind(tmp_path / "absent", head=b"\xef\xbb\xbf#VRML V2.0 utf8\n") == "vrml"
    with pytest.raises(IngestError):
        sniff_kind(tmp_path / "absent", head=b"#VRML V1.0 ascii\n")
