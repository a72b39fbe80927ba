"""The three files of an ELVEZ platform: its X3D scene, its WRI ID table and its STL meshes.

A platform (``platform``, ``combs``, ``ATC``) is named by its files: ``platform_cad.x3d`` and
``platform_ids.wri`` (the name is the stem without ``_cad`` or ``_ids``), and ``stl/platform/``
holds its meshes (the name is the folder's). CAD IDs repeat between platforms, so every record
carries its platform.

The scenes are Blender X3D exports in millimetres under a root scaled by 0.001: they are read
with broken shapes skipped (one warning each, naming the line) and only Transforms as
elements, so an element keeps its frame whatever became of its mesh. The label's first letter
gives the element's type (T table, J jig, B box, C comb, A ATC station, whose tool is the rest
of the label). STL meshes are in millimetres, binary or ASCII, in the element's own frame.
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from cadkg.errors import IngestError
from cadkg.ingest.scene.read import WalkOptions, read_x3d
from cadkg.ingest.scene.records import Quat, TriangleMesh, Vec3
from cadkg.ingest.wri import iter_wri

__all__ = [
    "ELEMENT_TYPES",
    "ElementMesh",
    "PlatformId",
    "PlatformItem",
    "element_type",
    "platform_name",
    "read_platform_ids",
    "read_platform_mesh",
    "read_platform_scene",
]

ELEMENT_TYPES = {"T": "table", "J": "jig", "B": "box", "C": "comb", "A": "atc_station"}
"""Element type by the first letter of its label; other letters give no type."""

_MILLIMETRE = 0.001
_STL_HEADER = 84
_STL_RECORD = 50
_RECORD = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attribute", "<u2")])
_VERTEX = re.compile(rb"^\s*vertex\s+(\S+)\s+(\S+)\s+(\S+)\s*$", re.MULTILINE)


@dataclass(frozen=True, slots=True)
class PlatformItem:
    """An element frame of a platform scene: pose in its parent element (metres), own mesh."""

    platform: str
    cad_id: str
    parent_id: str | None
    translation: Vec3
    rotation: Quat
    mesh: TriangleMesh | None
    line: int


@dataclass(frozen=True, slots=True)
class PlatformId:
    """A row of a platform's WRI table: CAD ID, label, commercial code and the label's type."""

    platform: str
    cad_id: str
    label: str
    model: str | None
    element_type: str
    line: int


@dataclass(frozen=True, slots=True)
class ElementMesh:
    """An STL mesh of a platform's folder (metres), named by a CAD ID or a commercial code."""

    platform: str
    name: str
    mesh: TriangleMesh


def platform_name(path: str | Path) -> str:
    """``platform_cad.x3d`` → ``platform``; ``ATC_ids.wri`` → ``ATC``; other stems as they are."""
    stem = Path(path).stem
    for suffix in ("_cad", "_ids"):
        if stem.lower().endswith(suffix) and len(stem) > len(suffix):
            return stem[: -len(suffix)]
    return stem


def element_type(label: str) -> str:
    """The type the first letter of a label gives (``J4`` → ``jig``), or ``""``."""
    return ELEMENT_TYPES.get(label[:1], "")


def read_platform_scene(path: str | Path) -> list[PlatformItem]:
    """The element frames of a platform scene; a broken shape is skipped with a warning.

    Raises
    ------
    IngestError
        On what the X3D reader refuses besides broken shapes (malformed XML, a DEF name of a
        Transform given twice, bad transform numbers ...).
    """
    platform = platform_name(path)
    items = read_x3d(path, WalkOptions(skip_broken_shapes=True, transforms_only=True))
    return [
        PlatformItem(platform, i.item_id, i.parent_id, i.translation, i.rotation, i.mesh, i.line)
        for i in items
    ]


def read_platform_ids(path: str | Path) -> list[PlatformId]:
    """The rows of a platform's WRI table (no header, tab separated), labels as written.

    Raises
    ------
    IngestError
        As the WRI reader: a row without a label, a malformed CAD ID or one given twice.
    """
    platform = platform_name(path)
    return [
        PlatformId(
            platform, e.cad_id, e.raw_label.strip(), e.commercial, element_type(e.raw_label.strip()), e.line
        )
        for e in iter_wri(path)
    ]


def read_platform_mesh(path: str | Path) -> list[ElementMesh]:
    """One STL mesh in millimetres, as metres; its platform is its folder's name.

    Raises
    ------
    IngestError
        On an empty file, a binary file whose size does not match its triangle count, or an
        ASCII file with a vertex that is not three numbers.
    """
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as err:
        raise IngestError(path, f"cannot read the file: {err.strerror}") from err
    return [ElementMesh(path.parent.name, path.stem, _stl_mesh(path, data))]


def _stl_mesh(path: Path, data: bytes) -> TriangleMesh:
    expected = "a binary STL (84 bytes, then 50 per triangle) or an ASCII STL (solid ... endsolid)"
    text = data.removeprefix(b"\xef\xbb\xbf").removeprefix(b"\xff\xfe").removeprefix(b"\xfe\xff")
    if not text.replace(b"\x00", b"").strip():
        raise IngestError(path, "the file is empty", expected=expected)
    if len(data) >= _STL_HEADER:
        (count,) = struct.unpack_from("<I", data, 80)
        # Many binary files start their header with "solid" too: the size tells them apart.
        if len(data) == _STL_HEADER + _STL_RECORD * count:
            table = np.frombuffer(data, dtype=_RECORD, count=count, offset=_STL_HEADER)
            return _mesh(path, table["v"].reshape(-1, 3).astype(np.float64))
    if not data.lstrip().startswith(b"solid"):
        raise IngestError(path, "not an STL file", expected=expected)
    vertices = []
    for match in _VERTEX.finditer(data):
        try:
            vertices.append([float(v) for v in match.groups()])
        except ValueError:
            line = data.count(b"\n", 0, match.start()) + 1
            raise IngestError(
                path,
                "bad number in a vertex",
                line=line,
                found=match.group(0).strip().decode(errors="replace"),
            ) from None
    if len(vertices) % 3:
        raise IngestError(path, f"{len(vertices)} vertices", expected="three vertices per facet")
    return _mesh(path, np.array(vertices, dtype=np.float64).reshape(-1, 3))


def _mesh(path: Path, vertices: np.ndarray) -> TriangleMesh:
    if not len(vertices):
        raise IngestError(path, "no triangles", expected="an STL mesh with at least one facet")
    if not np.isfinite(vertices).all():
        raise IngestError(path, "a vertex that is not a finite number", expected="finite coordinates")
    vertices = np.ascontiguousarray(vertices * _MILLIMETRE)
    faces = np.arange(len(vertices), dtype=np.int64).reshape(-1, 3)
    vertices.setflags(write=False)
    faces.setflags(write=False)
    return TriangleMesh(vertices, faces)
