"""Records of a CAD scene and the geometry they are computed with.

A scene is read as a list of :class:`SceneItem`: the DEF-named Transforms and Groups of an
X3D or VRML97 file. Each item has a rigid frame (a pose relative to its parent item) and its
own geometry as one triangle mesh in that frame. Transforms may scale, shear or mirror; those
parts cannot be expressed by a pose, so they are moved into the geometry instead (see
:func:`split_affine`). Lengths are the file's units, which cadkg takes to be metres.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from functools import cache

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "IDENTITY_ROTATION",
    "Floats",
    "Ints",
    "Numbers",
    "Part",
    "Quat",
    "SceneItem",
    "TriangleMesh",
    "Vec3",
    "apply_affine",
    "axis_angle_matrix",
    "box_mesh",
    "cone_mesh",
    "cylinder_mesh",
    "fan_triangulate",
    "invert_rigid",
    "merge_meshes",
    "quaternion_from_matrix",
    "rigid_matrix",
    "sphere_mesh",
    "split_affine",
    "stl_files",
    "transform_matrix",
]

Vec3 = tuple[float, float, float]
Quat = tuple[float, float, float, float]
"""A rotation as ``(x, y, z, w)`` (ROS order), unit length."""

Floats = NDArray[np.float64]
Ints = NDArray[np.int64]
Numbers = Sequence[float] | Floats

IDENTITY_ROTATION: Quat = (0.0, 0.0, 0.0, 1.0)

# Round primitives are approximated; 32 sections keep a cylinder's volume within 0.7 %.
_SECTIONS = 32
_SPHERE_SUBDIVISIONS = 2


@dataclass(frozen=True, slots=True, eq=False)
class TriangleMesh:
    """Triangles in an item's frame: vertices in metres (n, 3), faces as vertex indices (m, 3)."""

    vertices: Floats
    faces: Ints

    def to_stl(self) -> bytes:
        """The mesh as binary STL (84 header bytes + 50 bytes per triangle)."""
        return stl_files([self])[0]


_STL_HEADER = 84
_STL_RECORD = 50


def stl_files(meshes: Sequence[TriangleMesh]) -> list[bytes]:
    """Each mesh as binary STL, from one trimesh export of all of them.

    A scene has tens of thousands of small meshes, and a trimesh export costs about the same
    for 12 triangles as for 12,000. Binary STL is an 80-byte header, a triangle count and
    one 50-byte record per triangle (its normal, three vertices, an attribute), each record
    computed from its own triangle only; so the records of one export of all the meshes,
    cut where each mesh's triangles end, are that mesh's records.
    """
    if not meshes:
        return []
    import trimesh  # a third of a second to import: only where meshes are written

    offsets = np.cumsum([0] + [len(m.vertices) for m in meshes[:-1]])
    vertices = np.concatenate([m.vertices for m in meshes]).reshape(-1, 3)
    faces = np.concatenate([m.faces + offset for m, offset in zip(meshes, offsets, strict=True)])
    data = trimesh.Trimesh(vertices=vertices, faces=faces.reshape(-1, 3), process=False).export(
        file_type="stl"
    )
    if not isinstance(data, bytes):  # trimesh returns bytes for binary formats
        raise TypeError(f"STL export gave {type(data).__name__}")
    header = data[: _STL_HEADER - 4]
    files = []
    start = _STL_HEADER
    for mesh in meshes:
        count = len(mesh.faces)
        end = start + count * _STL_RECORD
        files.append(header + count.to_bytes(4, "little") + data[start:end])
        start = end
    return files


@dataclass(frozen=True, slots=True)
class SceneItem:
    """One DEF-named Transform or Group of a scene.

    ``translation`` and ``rotation`` are the rigid pose of this item's frame in its parent
    item's frame (the scene root frame when ``parent_id`` is None). The bounding box and the
    mesh hold the item's own geometry (not that of nested items), in the item's frame.
    """

    item_id: str
    parent_id: str | None
    translation: Vec3
    rotation: Quat
    bbox_min: Vec3 | None
    bbox_max: Vec3 | None
    mesh: TriangleMesh | None
    source: str
    line: int


# --- transforms ----------------------------------------------------------------------------------------


def axis_angle_matrix(axis: Numbers, angle: float) -> Floats:
    """3x3 rotation of ``angle`` radians about ``axis`` (any length but zero).

    A zero axis is accepted with a zero angle (``0 0 0 0`` is written for "no rotation").
    """
    x, y, z = (float(v) for v in axis)
    norm = math.sqrt(x * x + y * y + z * z)
    if norm == 0.0:
        if angle == 0.0:
            return np.eye(3)
        raise ValueError("rotation axis is zero")
    x, y, z = x / norm, y / norm, z / norm
    c, s = math.cos(angle), math.sin(angle)
    t = 1.0 - c
    return np.array(
        [
            [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
            [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
            [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
        ]
    )


def _affine(linear: Floats | None = None, translation: Numbers | None = None) -> Floats:
    m = np.eye(4)
    if linear is not None:
        m[:3, :3] = linear
    if translation is not None:
        m[:3, 3] = translation
    return m


def transform_matrix(
    translation: Numbers = (0.0, 0.0, 0.0),
    rotation: Numbers = (0.0, 0.0, 1.0, 0.0),
    scale: Numbers = (1.0, 1.0, 1.0),
    scale_orientation: Numbers = (0.0, 0.0, 1.0, 0.0),
    center: Numbers = (0.0, 0.0, 0.0),
) -> Floats:
    """4x4 matrix of an X3D/VRML Transform: ``T · C · R · SR · S · SR⁻¹ · C⁻¹``.

    Rotations are axis-angle ``(x, y, z, angle)``; raises ValueError on a zero axis with a
    non-zero angle.
    """
    linear = axis_angle_matrix(rotation[:3], float(rotation[3]))
    if any(float(v) != 1.0 for v in scale):
        sr = axis_angle_matrix(scale_orientation[:3], float(scale_orientation[3]))
        linear = linear @ sr @ np.diag(np.asarray(scale, dtype=np.float64)) @ sr.T
    c = np.asarray(center, dtype=np.float64)
    # T · C · L · C⁻¹ is the affine map p ↦ L(p − c) + c + t.
    return _affine(linear, np.asarray(translation, dtype=np.float64) + c - linear @ c)


def split_affine(linear: Floats) -> tuple[Floats, Floats]:
    """Split a 3x3 linear map into ``(R, K)`` with ``linear = R @ K`` and ``det R = +1``.

    R is the proper rotation nearest to ``linear`` (polar decomposition by SVD); when the map
    mirrors, the mirror is kept in K by flipping the direction of least stretch.
    """
    gram = linear.T @ linear
    if abs(gram - np.eye(3)).max() < 1e-12 and np.linalg.det(linear) > 0.0:
        # Already a rotation (the common case): the decomposition would only add round-off.
        return linear, np.eye(3)
    u, _, vt = np.linalg.svd(linear)
    r = u @ vt
    if np.linalg.det(r) < 0.0:
        u = u.copy()
        u[:, -1] = -u[:, -1]
        r = u @ vt
    return r, r.T @ linear


def rigid_matrix(rotation: Floats, translation: Numbers) -> Floats:
    """4x4 matrix of a rotation (3x3) and a translation."""
    return _affine(rotation, translation)


def invert_rigid(matrix: Floats) -> Floats:
    """Inverse of a rigid 4x4 matrix (rotation and translation only)."""
    rt = matrix[:3, :3].T
    return _affine(rt, -rt @ matrix[:3, 3])


def quaternion_from_matrix(rotation: Floats) -> Quat:
    """Unit quaternion ``(x, y, z, w)`` of a proper 3x3 rotation, with ``w >= 0``."""
    m = rotation
    trace = m[0, 0] + m[1, 1] + m[2, 2]
    # Branch on the largest of w, x, y, z so the square root is never of a tiny number.
    if trace > 0.0:
        s = 2.0 * math.sqrt(1.0 + trace)
        q = ((m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s, s / 4)
    elif m[0, 0] >= m[1, 1] and m[0, 0] >= m[2, 2]:
        s = 2.0 * math.sqrt(max(1.0 + m[0, 0] - m[1, 1] - m[2, 2], 0.0))
        q = (s / 4, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s, (m[2, 1] - m[1, 2]) / s)
    elif m[1, 1] >= m[2, 2]:
        s = 2.0 * math.sqrt(max(1.0 + m[1, 1] - m[0, 0] - m[2, 2], 0.0))
        q = ((m[0, 1] + m[1, 0]) / s, s / 4, (m[1, 2] + m[2, 1]) / s, (m[0, 2] - m[2, 0]) / s)
    else:
        s = 2.0 * math.sqrt(max(1.0 + m[2, 2] - m[0, 0] - m[1, 1], 0.0))
        q = ((m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, s / 4, (m[1, 0] - m[0, 1]) / s)
    norm = math.sqrt(sum(v * v for v in q))
    sign = -1.0 if q[3] < 0.0 else 1.0
    x, y, z, w = (float(sign * v / norm) for v in q)
    return (x, y, z, w)


def apply_affine(matrix: Floats, vertices: Floats) -> Floats:
    """Vertices (n, 3) mapped by a 4x4 affine matrix."""
    result: Floats = vertices @ matrix[:3, :3].T + matrix[:3, 3]
    return result


# --- meshes --------------------------------------------------------------------------------------------

Part = tuple[Floats, Ints]


def _frozen(vertices: Floats, faces: Ints) -> Part:
    vertices = np.ascontiguousarray(vertices, dtype=np.float64)
    faces = np.ascontiguousarray(faces, dtype=np.int64)
    vertices.setflags(write=False)
    faces.setflags(write=False)
    return vertices, faces


# X3D's round primitives stand on the y axis, trimesh's on z: x, y, z ↦ x, z, −y turns z into y.
_Z_TO_Y = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, -1.0, 0.0]])


@cache
def _unit(kind: str) -> Part:
    import trimesh.creation  # a third of a second to import: only where a primitive is met

    if kind == "box":
        mesh = trimesh.creation.box(extents=(1.0, 1.0, 1.0))
        return _frozen(mesh.vertices, mesh.faces)
    if kind == "sphere":
        mesh = trimesh.creation.icosphere(subdivisions=_SPHERE_SUBDIVISIONS, radius=1.0)
        return _frozen(mesh.vertices, mesh.faces)
    if kind == "cylinder":
        mesh = trimesh.creation.cylinder(radius=1.0, height=1.0, sections=_SECTIONS)
        return _frozen(mesh.vertices @ _Z_TO_Y.T, mesh.faces)
    mesh = trimesh.creation.cone(radius=1.0, height=1.0, sections=_SECTIONS)
    # trimesh's cone has its base at z = 0; X3D's is centred, apex up.
    return _frozen((mesh.vertices - (0.0, 0.0, 0.5)) @ _Z_TO_Y.T, mesh.faces)


def _scaled(kind: str, factors: Sequence[float]) -> Part:
    vertices, faces = _unit(kind)
    return vertices * np.asarray(factors, dtype=np.float64), faces


def box_mesh(size: Sequence[float]) -> Part:
    """A box of ``size`` (x, y, z) centred at the origin: 8 vertices, 12 triangles."""
    return _scaled("box", size)


def sphere_mesh(radius: float) -> Part:
    """A sphere centred at the origin (an icosphere, 320 triangles)."""
    return _scaled("sphere", (radius, radius, radius))


def cylinder_mesh(radius: float, height: float) -> Part:
    """A closed cylinder on the y axis, centred at the origin."""
    return _scaled("cylinder", (radius, height, radius))


def cone_mesh(bottom_radius: float, height: float) -> Part:
    """A closed cone on the y axis, centred at the origin, apex at ``+height/2``."""
    return _scaled("cone", (bottom_radius, height, bottom_radius))


def fan_triangulate(index: Ints) -> Ints:
    """Triangles of polygons given as vertex indices separated by -1 (a coordIndex).

    Each polygon ``a b c d ...`` becomes the fan ``a b c, a c d, ...``; polygons of fewer than
    three vertices have no area and give no triangle. Indices are not range checked here.
    """
    index = np.asarray(index, dtype=np.int64)
    separator = index == -1
    values = index[~separator]
    if values.size == 0:
        return np.empty((0, 3), dtype=np.int64)
    polygon = np.cumsum(separator)[~separator]
    first = np.r_[True, polygon[1:] != polygon[:-1]]
    starts = np.flatnonzero(first)
    run = np.cumsum(first) - 1
    position = np.arange(values.size) - starts[run]
    corner = np.flatnonzero(position >= 2)
    return np.column_stack((values[starts[run[corner]]], values[corner - 1], values[corner]))


def merge_meshes(parts: Sequence[Part]) -> TriangleMesh | None:
    """One mesh of several parts (None when there are no triangles)."""
    parts = [p for p in parts if len(p[1])]
    if not parts:
        return None
    if len(parts) == 1:
        return TriangleMesh(*_frozen(*parts[0]))
    offsets = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
    vertices = np.concatenate([v for v, _ in parts])
    faces = np.concatenate([f + o for (_, f), o in zip(parts, offsets, strict=True)])
    vertices, faces = _frozen(vertices, faces)
    return TriangleMesh(vertices, faces)
