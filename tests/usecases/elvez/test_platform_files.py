"""The platform files of an ELVEZ cell: WRI tables (label letters, platform names), STL meshes
(binary with a 'solid' header, ASCII, broken), and Blender scenes read as element frames."""

from __future__ import annotations

import struct
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.usecases.elvez.files.platforms import (
    element_type,
    platform_name,
    read_platform_ids,
    read_platform_mesh,
    read_platform_scene,
)
from tests.ingest.test_scene_lenient import LINES

Write = Callable[[str, str | bytes], Path]


@pytest.mark.parametrize(
    ("name", "platform"),
    [
        ("platform_cad.x3d", "platform"),
        ("ATC_ids.wri", "ATC"),
        ("combs_cad.x3d", "combs"),
        ("holder.x3d", "holder"),
        ("_cad.x3d", "_cad"),
    ],
)
def test_the_platform_is_named_by_the_file(name: str, platform: str) -> None:
    assert platform_name(Path("cell") / name) == platform


@pytest.mark.parametrize(
    ("label", "kind"),
    [
        ("T1", "table"),
        ("J1S", "jig"),
        ("B3", "box"),
        ("C1", "comb"),
        ("Agun", "atc_station"),
        ("X1", ""),
        ("j1", ""),
    ],
)
def test_the_first_letter_gives_the_type(label: str, kind: str) -> None:
    assert element_type(label) == kind


def test_wri_without_header_in_crlf(write: Write) -> None:
    path = write("ATC_ids.wri", b"ID000001\tT1\t0000001\r\nID000002\tAEEF_taping_gun\t0000301\r\n")
    rows = read_platform_ids(path)
    assert [(r.platform, r.cad_id, r.label, r.model, r.element_type, r.line) for r in rows] == [
        ("ATC", "ID000001", "T1", "0000001", "table", 1),
        ("ATC", "ID000002", "AEEF_taping_gun", "0000301", "atc_station", 2),
    ]


def test_a_wri_row_without_a_label_is_located(write: Write) -> None:
    with pytest.raises(IngestError) as info:
        read_platform_ids(write("platform_ids.wri", "ID0001\tT1\t0001\nID0002\n"))
    assert info.value.line == 2


def _binary_stl(triangles: list[list[tuple[float, float, float]]], header: bytes = b"solid part") -> bytes:
    data = header.ljust(80, b" ") + struct.pack("<I", len(triangles))
    for triangle in triangles:
        data += struct.pack("<12fH", 0.0, 0.0, 1.0, *(v for point in triangle for v in point), 0)
    return data


def test_binary_stl_with_a_solid_header_in_metres(write: Write) -> None:
    folder = Path(write("x", b"").parent) / "stl" / "platform"
    folder.mkdir(parents=True)
    path = folder / "0011.STL"
    path.write_bytes(_binary_stl([[(0.0, 0.0, 0.0), (10.0, 0.0, 0.0), (10.0, 24.0, 153.0)]]))
    (mesh,) = read_platform_mesh(path)
    assert (mesh.platform, mesh.name) == ("platform", "0011")
    np.testing.assert_allclose(mesh.mesh.vertices.max(axis=0), [0.01, 0.024, 0.153])
    assert mesh.mesh.faces.tolist() == [[0, 1, 2]]


def test_ascii_stl(write: Write) -> None:
    text = "solid x\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n   vertex 1 1 2e1\n"
    text += "  endloop\n endfacet\nendsolid x\n"
    (mesh,) = read_platform_mesh(write("ID0002.STL", text))
    np.testing.assert_allclose(mesh.mesh.vertices[2], [0.001, 0.001, 0.02])


@pytest.mark.parametrize(
    ("content", "reason"),
    [
        (b"", "the file is empty"),
        (b"PK\x03\x04 not a mesh", "not an STL file"),
        (_binary_stl([]), "no triangles"),
        (b"solid x\n vertex 0 0 0\n vertex 1 0 0\nendsolid x\n", "2 vertices"),
    ],
)
def test_broken_stl_files(write: Write, content: bytes, reason: str) -> None:
    with pytest.raises(IngestError) as info:
        read_platform_mesh(write("broken.STL", content))
    assert info.value.reason == reason


def test_a_binary_stl_whose_size_lies_is_read_as_text_and_refused(write: Write) -> None:
    data = _binary_stl([[(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 1.0, 0.0)]], header=b"mesh")[:-3]
    with pytest.raises(IngestError, match="not an STL file"):
        read_platform_mesh(write("short.STL", data))


def test_a_blender_scene_gives_every_transform_with_its_platform(write: Write) -> None:
    path = write("platform_cad.x3d", "\r\n".join(LINES) + "\r\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", IngestWarning)
        items = read_platform_scene(path)
    assert len(caught) == 4
    assert [(i.platform, i.cad_id, i.parent_id, i.line) for i in items] == [
        ("platform", "ID0001", None, 11),  # where its start tag ends
        ("platform", "ID0002", "ID0001", 15),
        ("platform", "ID0003", "ID0001", 19),
        ("platform", "ID0004", "ID0001", 23),
        ("platform", "ID0005", "ID0001", 27),
        ("platform", "ID0006", "ID0001", 31),
    ]
    assert items[1].translation == pytest.approx((0.1, 0.0, 0.013))
