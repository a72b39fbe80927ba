"""Write ``QE01_cad.x3d``, the cabinet's scene in the reference IEMA node's dialect, from ``scene.x3d``.

    python examples/iema-switchgear/make_node_scene.py

The node reads one X3D file (``NAME_cad.x3d``) its own way (README.md, "QE01_cad.x3d"):
millimetres, z up (the plate in the x-z plane, y into it), one root item (``ID000001``, the
WRI's first row, the cabinet: its faces are the mounting plate's) holding every other item,
each item's faces an ``IndexedFaceSet`` directly under its ``Transform`` (no placement
``Transform`` between), numbers separated by single spaces, and no ``Inline`` (the fan is
written in place). The same cabinet as ``scene.x3d``: every item's pose and faces are that
file's, in millimetres.

A ``Transform`` without a DEF above the root scales the file to metres and turns z up into the
cabinet frame's y up for readers that apply a file's transforms (cadkg); the node reads the
items' transforms only. The output is the same bytes on every run.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from cadkg.geometry.poses import Pose
from cadkg.ingest.scene.read import read_x3d
from cadkg.ingest.scene.records import SceneItem

HERE = Path(__file__).resolve().parent
ROOT_ITEM = "ID000001"
# The cabinet frame (x right, y up, z out of the plate) seen from the node's z-up frame: a
# quarter turn about x. Written with the digits of a double so that readers agree to 1e-15.
QUARTER_TURN = math.pi / 2


def _number(value: float) -> str:
    text = f"{round(value, 6):.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def _numbers(values: object) -> str:
    return " ".join(_number(float(v)) for v in np.asarray(values, dtype=float).ravel())


def _axis_angle(quaternion: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    x, y, z, w = quaternion
    s = math.sqrt(x * x + y * y + z * z)
    if s < 1e-12:
        return (0.0, 0.0, 1.0, 0.0)
    return (x / s, y / s, z / s, 2 * math.atan2(s, w))


def _z_up(points: object) -> np.ndarray:
    """Cabinet-frame points (x right, y up, z out), in metres, as the node's: mm, z up, y in."""
    x, y, z = np.asarray(points, dtype=float).reshape(-1, 3).T * 1000
    return np.stack([x, -z, y], axis=1)


def _faces(vertices: object, faces: object, indent: str) -> str:
    indices = " ".join(f"{a} {b} {c} -1" for a, b, c in np.asarray(faces).tolist())
    return (
        f'{indent}<Shape><IndexedFaceSet coordIndex="{indices}"><Coordinate point="{_numbers(vertices)}"/>'
        "</IndexedFaceSet></Shape>"
    )


def _transform(item: SceneItem, top: bool, indent: str) -> list[str]:
    translation = np.asarray(item.translation, dtype=float) * 1000
    rotation = tuple(float(v) for v in item.rotation)
    if top:  # a child of the root: its pose in the z-up frame
        translation = _z_up(item.translation)[0]
        half = QUARTER_TURN / 2
        quarter = Pose((0.0, 0.0, 0.0), (math.sin(half), 0.0, 0.0, math.cos(half)))
        rotation = (quarter * Pose((0.0, 0.0, 0.0), rotation)).orientation  # type: ignore[arg-type]
    attributes = f'DEF="{item.item_id}" translation="{_numbers(translation)}"'
    axis_angle = _axis_angle(rotation)  # type: ignore[arg-type]
    if abs(axis_angle[3]) > 1e-12:
        attributes += f' rotation="{_numbers(axis_angle[:3])} {axis_angle[3]!r}"'
    lines = [f"{indent}<Transform {attributes}>"]
    if item.mesh is not None:
        lines.append(_faces(np.asarray(item.mesh.vertices) * 1000, item.mesh.faces, indent + "  "))
    return lines


def write_node_scene() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        items = read_x3d(HERE / "scene.x3d")
    children: dict[str | None, list[SceneItem]] = {}
    for item in items:
        children.setdefault(item.parent_id, []).append(item)

    def subtree(item: SceneItem, depth: int) -> list[str]:
        indent = "  " * depth
        lines = _transform(item, depth == 4, indent)
        for child in children.get(item.item_id, []):
            lines += subtree(child, depth + 1)
        return [*lines, f"{indent}</Transform>"]

    # The root item is the cabinet: the mounting plate's faces, in the root (cabinet) frame.
    plate = next(item for item in items if item.item_id == "PLATE")
    assert plate.mesh is not None and plate.rotation == (0.0, 0.0, 0.0, 1.0)
    plate_points = _z_up(np.asarray(plate.mesh.vertices) + plate.translation)
    plate_faces = _faces(plate_points, plate.mesh.faces, " " * 8)
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        '<X3D profile="Interchange" version="3.3">',
        "  <head>",
        '    <meta name="title" content="QE01_cad.x3d"/>',
        '    <meta name="description" content="Quadro elettrico QE01, commessa 24-0117; millimetres, z up"/>',
        "  </head>",
        "  <Scene>",
        f'    <Transform scale="0.001 0.001 0.001" rotation="1 0 0 {-QUARTER_TURN!r}">',
        f'      <Transform DEF="{ROOT_ITEM}">',
        plate_faces,
    ]
    for item in children[None]:
        if item.item_id == "PLATE":
            continue
        lines += subtree(item, 4)
    lines += ["      </Transform>", "    </Transform>", "  </Scene>", "</X3D>", ""]
    (HERE / "QE01_cad.x3d").write_bytes("\r\n".join(lines).encode("utf-8"))


if __name__ == "__main__":
    write_node_scene()
