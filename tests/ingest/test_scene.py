"""The geometry of scene items: transforms, their split into frame and residual, meshes, STL."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
import trimesh

from cadkg.ingest.scene.read import read_vrml, read_x3d
from cadkg.ingest.scene.records import (
    IDENTITY_ROTATION,
    SceneItem,
    TriangleMesh,
    axis_angle_matrix,
    box_mesh,
    cone_mesh,
    cylinder_mesh,
    fan_triangulate,
    invert_rigid,
    merge_meshes,
    quaternion_from_matrix,
    rigid_matrix,
    sphere_mesh,
    split_affine,
    stl_files,
    transform_matrix,
)
from tests.conftest import EXAMPLES

EXAMPLE = EXAMPLES / "iema-switchgear"

HALF_PI = math.pi / 2
S = math.sqrt(0.5)


# --- helpers the reader tests share --------------------------------------------------------------------


def matrix_of_quaternion(q: tuple[float, float, float, float]) -> np.ndarray:
    """3x3 rotation of a unit quaternion (x, y, z, w), written out independently of the reader."""
    x, y, z, w = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def pose(item: SceneItem) -> np.ndarray:
    """The item's pose in its parent's frame as a 4x4 matrix."""
    m = np.eye(4)
    m[:3, :3] = matrix_of_quaternion(item.rotation)
    m[:3, 3] = item.translation
    return m


def world(items: list[SceneItem], item_id: str) -> np.ndarray:
    """The item's frame in the scene root frame: its pose composed with its ancestors'."""
    by_id = {i.item_id: i for i in items}
    m = np.eye(4)
    item: SceneItem | None = by_id[item_id]
    while item is not None:
        m = pose(item) @ m
        item = by_id[item.parent_id] if item.parent_id is not None else None
    return m


def world_vertices(items: list[SceneItem], item_id: str) -> np.ndarray:
    mesh = {i.item_id: i for i in items}[item_id].mesh
    assert mesh is not None
    m = world(items, item_id)
    result: np.ndarray = mesh.vertices @ m[:3, :3].T + m[:3, 3]
    return result


# --- rotations and transforms --------------------------------------------------------------------------


def test_axis_angle_quarter_turn_about_z_maps_x_to_y() -> None:
    np.testing.assert_allclose(axis_angle_matrix((0, 0, 1), HALF_PI) @ [1, 0, 0], [0, 1, 0], atol=1e-15)
    # The axis is normalised: its length does not matter.
    np.testing.assert_allclose(axis_angle_matrix((0, 0, 5), HALF_PI), axis_angle_matrix((0, 0, 1), HALF_PI))


def test_axis_angle_about_a_diagonal_cycles_the_axes() -> None:
    # A third of a turn about (1, 1, 1) sends x to y, y to z, z to x.
    r = axis_angle_matrix((1, 1, 1), 2 * math.pi / 3)
    np.testing.assert_allclose(r, [[0, 0, 1], [1, 0, 0], [0, 1, 0]], atol=1e-15)


def test_zero_axis() -> None:
    np.testing.assert_array_equal(axis_angle_matrix((0, 0, 0), 0.0), np.eye(3))
    with pytest.raises(ValueError, match="rotation axis is zero"):
        axis_angle_matrix((0, 0, 0), 1.0)


def test_center_is_the_fixed_point_of_rotation_and_scale() -> None:
    m = transform_matrix(rotation=(0, 0, 1, HALF_PI), scale=(3, 3, 3), center=(1, 0, 0))
    np.testing.assert_allclose(m @ [1, 0, 0, 1], [1, 0, 0, 1], atol=1e-15)
    # (2, 0, 0) is 1 from the centre along x: scaled to 3, turned to +y.
    np.testing.assert_allclose(m @ [2, 0, 0, 1], [1, 3, 0, 1], atol=1e-15)


def test_scale_orientation_scales_along_the_turned_axes() -> None:
    m = transform_matrix(scale=(2, 1, 1), scale_orientation=(0, 0, 1, math.pi / 4))
    np.testing.assert_allclose(m @ [1, 1, 0, 1], [2, 2, 0, 1], atol=1e-15)
    np.testing.assert_allclose(m @ [1, -1, 0, 1], [1, -1, 0, 1], atol=1e-15)
    np.testing.assert_allclose(m @ [0, 0, 1, 1], [0, 0, 1, 1], atol=1e-15)


def test_transform_matrix_is_t_c_r_sr_s_sr_inverse_c_inverse() -> None:
    def translate(v: tuple[float, float, float]) -> np.ndarray:
        m = np.eye(4)
        m[:3, 3] = v
        return m

    def linear(a: np.ndarray) -> np.ndarray:
        m = np.eye(4)
        m[:3, :3] = a
        return m

    t, c, s = (0.1, -2.0, 3.0), (0.5, 0.25, -1.0), (1.5, 0.5, 2.0)
    r = axis_angle_matrix((1, 2, 3), 0.7)
    sr = axis_angle_matrix((-1, 0, 2), 1.1)
    expected = (
        translate(t)
        @ translate(c)
        @ linear(r)
        @ linear(sr)
        @ linear(np.diag(s))
        @ linear(sr.T)
        @ translate((-0.5, -0.25, 1.0))
    )
    actual = transform_matrix(t, (1, 2, 3, 0.7), s, (-1, 0, 2, 1.1), c)
    np.testing.assert_allclose(actual, expected, atol=1e-14)


def test_split_of_a_scaled_rotation_keeps_the_scale_out_of_the_rotation() -> None:
    rotation = axis_angle_matrix((0, 1, 0), HALF_PI)
    r, k = split_affine(2.0 * rotation)
    np.testing.assert_allclose(r, rotation, atol=1e-15)
    np.testing.assert_allclose(k, 2.0 * np.eye(3), atol=1e-15)


def test_split_of_a_stretch_and_shear() -> None:
    rotation = axis_angle_matrix((1, -1, 0.5), 0.9)
    linear = rotation @ np.array([[2.0, 0.3, 0.0], [0.3, 1.0, 0.0], [0.0, 0.0, 0.5]])
    r, k = split_affine(linear)
    np.testing.assert_allclose(r, rotation, atol=1e-12)
    np.testing.assert_allclose(r @ k, linear, atol=1e-14)


def test_split_of_a_mirror_keeps_the_mirror_in_the_residual() -> None:
    linear = axis_angle_matrix((0, 0, 1), 0.3) @ np.diag([-1.0, 2.0, 3.0])
    r, k = split_affine(linear)
    assert np.linalg.det(r) == pytest.approx(1.0)
    np.testing.assert_allclose(r.T @ r, np.eye(3), atol=1e-14)
    assert np.linalg.det(k) == pytest.approx(-6.0)
    np.testing.assert_allclose(r @ k, linear, atol=1e-14)


@pytest.mark.parametrize(
    ("axis", "angle", "expected"),
    [
        ((0, 0, 1), 0.0, IDENTITY_ROTATION),
        ((0, 0, 1), HALF_PI, (0.0, 0.0, S, S)),
        ((1, 0, 0), HALF_PI, (S, 0.0, 0.0, S)),
        ((0, 1, 0), -HALF_PI, (0.0, -S, 0.0, S)),
        ((1, 0, 0), math.pi, (1.0, 0.0, 0.0, 0.0)),
        ((0, 1, 0), math.pi, (0.0, 1.0, 0.0, 0.0)),
        ((0, 0, 1), math.pi, (0.0, 0.0, 1.0, 0.0)),
    ],
)
def test_quaternion_of_known_rotations(
    axis: tuple[float, float, float], angle: float, expected: tuple[float, float, float, float]
) -> None:
    assert quaternion_from_matrix(axis_angle_matrix(axis, angle)) == pytest.approx(expected, abs=1e-12)


def test_quaternion_round_trip_on_many_rotations() -> None:
    rng = np.random.default_rng(7)
    for _ in range(200):
        axis = rng.normal(size=3)
        rotation = axis_angle_matrix(axis, float(rng.uniform(-math.pi, math.pi)))
        q = quaternion_from_matrix(rotation)
        assert math.fsum(v * v for v in q) == pytest.approx(1.0, abs=1e-12)
        assert q[3] >= 0.0
        np.testing.assert_allclose(matrix_of_quaternion(q), rotation, atol=1e-12)


def test_invert_rigid() -> None:
    m = rigid_matrix(axis_angle_matrix((1, 2, 3), 0.4), (1.0, -2.0, 0.5))
    np.testing.assert_allclose(invert_rigid(m) @ m, np.eye(4), atol=1e-15)


# --- meshes --------------------------------------------------------------------------------------------


def test_fan_triangulation_of_a_quad_and_a_pentagon() -> None:
    faces = fan_triangulate(np.array([0, 1, 2, 3, -1, 4, 5, 6, 7, 8], dtype=np.int64))
    assert faces.tolist() == [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7], [4, 7, 8]]


def test_fan_triangulation_skips_polygons_without_area() -> None:
    faces = fan_triangulate(np.array([-1, 0, 1, -1, -1, 2, -1, 3, 4, 5, -1], dtype=np.int64))
    assert faces.tolist() == [[3, 4, 5]]
    assert fan_triangulate(np.array([], dtype=np.int64)).shape == (0, 3)


def test_box_mesh_is_closed_with_the_size_as_extents() -> None:
    vertices, faces = box_mesh((0.2, 0.4, 0.6))
    assert vertices.shape == (8, 3)
    assert faces.shape == (12, 3)
    np.testing.assert_allclose(vertices.min(axis=0), [-0.1, -0.2, -0.3])
    np.testing.assert_allclose(vertices.max(axis=0), [0.1, 0.2, 0.3])
    mesh = trimesh.Trimesh(vertices, faces, process=False)
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(0.2 * 0.4 * 0.6)


def test_round_primitives_stand_on_the_y_axis() -> None:
    vertices, _ = cylinder_mesh(0.5, 2.0)
    np.testing.assert_allclose(vertices.min(axis=0), [-0.5, -1.0, -0.5], atol=1e-12)
    np.testing.assert_allclose(vertices.max(axis=0), [0.5, 1.0, 0.5], atol=1e-12)
    vertices, faces = cone_mesh(0.5, 2.0)
    apex = vertices[vertices[:, 1].argmax()]
    np.testing.assert_allclose(apex, [0.0, 1.0, 0.0], atol=1e-12)
    assert vertices[:, 1].min() == pytest.approx(-1.0)
    assert trimesh.Trimesh(vertices, faces, process=False).volume > 0  # outward faces
    vertices, _ = sphere_mesh(0.25)
    np.testing.assert_allclose(np.linalg.norm(vertices, axis=1), 0.25)


def test_stl_bytes_hold_every_triangle() -> None:
    mesh = merge_meshes([box_mesh((1, 1, 1)), cylinder_mesh(0.1, 0.5)])
    assert mesh is not None
    triangles = 12 + len(cylinder_mesh(0.1, 0.5)[1])
    data = mesh.to_stl()
    assert len(data) == 84 + 50 * triangles
    assert int.from_bytes(data[80:84], "little") == triangles
    loaded = trimesh.load(io.BytesIO(data), file_type="stl", process=False)
    assert len(loaded.faces) == triangles


def test_merge_offsets_the_faces_of_later_parts() -> None:
    mesh = merge_meshes([box_mesh((1, 1, 1)), box_mesh((2, 2, 2))])
    assert isinstance(mesh, TriangleMesh)
    assert mesh.vertices.shape == (16, 3)
    assert mesh.faces[12:].min() == 8
    assert mesh.faces.max() == 15
    assert not mesh.vertices.flags.writeable
    assert merge_meshes([]) is None


def _one_export(mesh: TriangleMesh) -> bytes:
    data = trimesh.Trimesh(vertices=mesh.vertices, faces=mesh.faces, process=False).export(file_type="stl")
    assert isinstance(data, bytes)
    return data


def test_stl_files_are_each_mesh_exported_alone() -> None:
    meshes = [
        r.mesh
        for r in [*read_x3d(EXAMPLE / "scene.x3d"), *read_vrml(EXAMPLE / "scene.wrl")]
        if r.mesh is not None
    ]
    # A degenerate triangle (zero normal) and a mesh of a single triangle too.
    meshes.append(
        TriangleMesh(
            np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0.5]], dtype=float),
            np.array([[0, 1, 2], [0, 1, 3]]),
        )
    )
    meshes.append(TriangleMesh(np.eye(3), np.array([[0, 1, 2]])))
    assert len(meshes) > 40
    together = stl_files(meshes)
    assert together == [_one_export(m) for m in meshes]
    assert meshes[-1].to_stl() == together[-1]
    assert len(together[0]) == 84 + 50 * len(meshes[0].faces)
