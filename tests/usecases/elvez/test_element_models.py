"""The element models reader: the example's models in metres and radians, meshes, located errors."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.usecases.elvez.element_models import ElementModel, KeySize, read_element_models
from cadkg.usecases.elvez.xml_fields import Placement
from tests.conftest import ROOT

EXAMPLE = ROOT / "examples" / "elvez-cell"
ASSEMBLY = EXAMPLE / "assembly" / "assembly-models.xml"

Write = Callable[[str, str | bytes], Path]


@pytest.fixture(scope="module")
def assembly() -> dict[str, ElementModel]:
    return {m.number: m for m in read_element_models(ASSEMBLY)}


def test_guide_model_in_metres_and_radians(assembly: dict[str, ElementModel]) -> None:
    assert list(assembly) == ["0001", "0009", "0010", "0012"]
    guide = assembly["0009"]
    assert (guide.description, guide.line) == ("cable guide, type A", 7)
    assert guide.dimensions == pytest.approx((0.04, 0.03, 0.05))
    key, corner = guide.frames
    assert key.name == "key"
    assert key.placement.xyz == pytest.approx((0.010, 0.0, 0.040))
    assert key.placement.rpy == pytest.approx((0.0, 0.0, math.pi / 2))
    assert key.placement.line == 9
    assert corner.name == "key_corner"
    assert corner.placement.xyz == pytest.approx((-0.005, -0.003, 0.015))
    assert guide.key == KeySize(pytest.approx(0.03), pytest.approx(0.006), pytest.approx(0.025), 11)  # type: ignore[arg-type]


def test_models_without_key_or_frames(assembly: dict[str, ElementModel]) -> None:
    plate = assembly["0001"]
    assert (plate.frames, plate.key) == ((), None)
    assert plate.dimensions == pytest.approx((0.6, 0.4, 0.01))
    holder = assembly["0012"]
    assert [f.name for f in holder.frames] == ["key"] and holder.key is None


def test_mesh_is_read_from_the_named_directory(assembly: dict[str, ElementModel]) -> None:
    guide = assembly["0009"]
    assert guide.mesh_file == "meshes/0009.stl"
    assert guide.mesh == (ASSEMBLY.parent / "meshes" / "0009.stl").read_bytes()
    # 12 triangles of a box: 84 + 12 * 50 bytes.
    assert len(guide.mesh or b"") == 684


def test_units_in_metres_and_radians_need_no_conversion(write: Write) -> None:
    path = write(
        "m.xml",
        '<element_models length_unit="m" angle_unit="rad"><model number="7">'
        '<dimensions x="0.1" y="0.2" z="0.3"/>'
        '<frame name="key" x="0.01" y="0" z="0" roll="0" pitch="0" yaw="1.5"/></model></element_models>',
    )
    (model,) = read_element_models(path)
    assert model.dimensions == (0.1, 0.2, 0.3)
    assert model.frames[0].placement == Placement((0.01, 0.0, 0.0), (0.0, 0.0, 1.5), 1)
    assert (model.mesh, model.mesh_file) == (None, None)


HEAD = '<element_models length_unit="mm" angle_unit="deg">\n'
GUIDE = '<model number="0009">\n<dimensions x="40" y="30" z="50"/>\n'


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("<data>\n<code/>\n</data>", r"m\.xml:1: the root element is not <element_models> \(found '<data>'"),
        (
            '<element_models angle_unit="deg">\n</element_models>',
            r"m\.xml:1: <element_models> without a 'length_unit'",
        ),
        (
            '<element_models length_unit="mm" angle_unit="grad">\n</element_models>',
            r"m\.xml:1: unknown or missing angle_unit \(found 'grad', expected deg or rad\)",
        ),
        (HEAD + "</element_models>", r"m\.xml:1: no <model> in <element_models>"),
        (
            HEAD + GUIDE + '<keyframe name="key"/>\n</model>\n</element_models>',
            r"m\.xml:4: unexpected element <keyframe> inside <model> \(found '<keyframe>'",
        ),
        (
            HEAD + '<model number="0009">\n<dimensions x="4,0" y="30" z="50"/>\n</model>\n</element_models>',
            r"m\.xml:3: 'x' of <dimensions> is not a number \(found '4,0'",
        ),
        (
            HEAD + '<model number="0009">\n<dimensions x="40" y="-3" z="50"/>\n</model>\n</element_models>',
            r"m\.xml:3: 'y' of <dimensions> is below 0 \(found '-3'",
        ),
        (
            HEAD + '<model number="0009">\n</model>\n</element_models>',
            r"m\.xml:2: <model> has no <dimensions>",
        ),
        (
            HEAD
            + GUIDE
            + '<frame name="key" x="1" y="0" z="0" roll="0" pitch="0"/>\n</model>\n</element_models>',
            r"m\.xml:4: <frame> without a 'yaw' attribute",
        ),
        (
            HEAD
            + GUIDE
            + '<frame name="key" x="1" y="0" z="0" roll="0" pitch="0" yaw="0"/>\n'
            + '<frame name="key" x="2" y="0" z="0" roll="0" pitch="0" yaw="0"/>\n</model>\n</element_models>',
            r"m\.xml:5: frame 'key' given twice in model '0009' \(first on line 4\)",
        ),
        (
            HEAD + GUIDE + '<key length="3" gap="1"/>\n</model>\n</element_models>',
            r"m\.xml:4: <key> without a 'height' attribute",
        ),
        (
            HEAD + GUIDE + "</model>\n" + GUIDE + "</model>\n</element_models>",
            r"m\.xml:5: model '0009' given twice \(first on line 2\)",
        ),
        (
            HEAD + '<model number="../0009">\n<dimensions x="1" y="1" z="1"/>\n</model>\n</element_models>',
            r"m\.xml:2: malformed model number \(found '\.\./0009'",
        ),
        (
            HEAD
            + GUIDE
            + '<frame name="key" x="1" y="0" z="0" roll="0" pitch="0" yaw="0" w="1"/>\n</model>\n'
            "</element_models>",
            r"m\.xml:4: unknown attribute 'w' of <frame>",
        ),
        (HEAD + GUIDE + "</model>\n", r"m\.xml:\d+: malformed XML"),
        (
            '<?xml version="1.0"?>\n<!DOCTYPE x [<!ENTITY a "b">]>\n' + HEAD + "</element_models>",
            r"m\.xml:2: <!DOCTYPE> is not allowed",
        ),
        ("", r"m\.xml: the file is empty"),
    ],
)
def test_located_errors(write: Write, text: str, message: str) -> None:
    path = write("m.xml", text)
    with pytest.raises(IngestError, match=message):
        read_element_models(path)


MESHED = (
    '<element_models length_unit="mm" angle_unit="deg" meshes="{dir}">\n'
    + GUIDE
    + "</model>\n</element_models>"
)


def test_missing_mesh_directory_and_file(write: Write, tmp_path: Path) -> None:
    path = write("m.xml", MESHED.format(dir="meshes"))
    with pytest.raises(IngestError, match=r"m\.xml:1: mesh directory not found \(found 'meshes'"):
        read_element_models(path)
    (tmp_path / "meshes").mkdir()
    with pytest.raises(IngestError, match=r"m\.xml:2: no mesh for model '0009' \(found 'meshes/0009\.stl'"):
        read_element_models(path)
    (tmp_path / "meshes" / "0009.stl").write_bytes(b"PK\x03\x04 not a mesh")
    with pytest.raises(IngestError, match=r"m\.xml:2: the mesh of model '0009' is not an STL file"):
        read_element_models(path)
    ascii_stl = (
        b"solid g\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\n"
    )
    (tmp_path / "meshes" / "0009.stl").write_bytes(ascii_stl + b"endfacet\nendsolid g\n")
    (model,) = read_element_models(path)
    assert model.mesh is not None and model.mesh.startswith(b"solid g")


@pytest.mark.parametrize("directory", ["../outside", "/abs/meshes"])
def test_mesh_directory_must_stay_beside_the_file(write: Write, directory: str) -> None:
    path = write("m.xml", MESHED.format(dir=directory))
    with pytest.raises(IngestError, match=r"m\.xml:1: 'meshes' (leads outside|must be a directory relative)"):
        read_element_models(path)
