"""Write the STL meshes of this example: a box of each element's size, in millimetres, in the
element's own frame (from its origin to x, y, z), as the cell's real STL folders hold them.

``stl/platform/`` is named by commercial code (binary STL whose header starts with ``solid``,
as many exporters write it), ``stl/combs/`` by CAD ID (ASCII STL); the ATC stations have no
STL, their scene's shapes stand in. Run from anywhere: ``python make_meshes.py``.
"""

from __future__ import annotations

import struct
import xml.etree.ElementTree as ET
from pathlib import Path

HERE = Path(__file__).resolve().parent
# Folder, file name, commercial code whose size the box takes.
MESHES = (
    ("platform", "0011", "0011"),
    ("platform", "0012", "0012"),
    ("platform", "0015", "0015"),
    ("platform", "0030", "0030"),
    ("combs", "ID0002", "0000210"),
)
_CORNERS = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)]
_FACES = [
    (0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4),
    (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7),
]  # fmt: skip


def triangles(size: tuple[float, float, float]) -> list[list[tuple[float, float, float]]]:
    points = [(a * size[0], b * size[1], c * size[2]) for a, b, c in _CORNERS]
    return [[points[i] for i in face] for face in _FACES]


def binary(size: tuple[float, float, float]) -> bytes:
    faces = triangles(size)
    data = b"solid box exported as binary".ljust(80, b" ") + struct.pack("<I", len(faces))
    for face in faces:
        data += struct.pack("<12fH", 0.0, 0.0, 0.0, *(v for point in face for v in point), 0)
    return data


def ascii_stl(size: tuple[float, float, float]) -> bytes:
    lines = ["solid box"]
    for face in triangles(size):
        lines += ["  facet normal 0 0 0", "    outer loop"]
        lines += [f"      vertex {x:g} {y:g} {z:g}" for x, y, z in face]
        lines += ["    endloop", "  endfacet"]
    return ("\n".join([*lines, "endsolid box"]) + "\n").encode()


def main() -> None:
    sizes = {
        element.get("model"): tuple(float(element.get(k, "0")) for k in ("xdim", "ydim", "zdim"))
        for element in ET.parse(HERE / "Jigs_definition_v2.xml").getroot()
    }
    for folder, name, code in MESHES:
        x, y, z = sizes[code]
        target = HERE / "stl" / folder / f"{name}.STL"
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(binary((x, y, z)) if folder == "platform" else ascii_stl((x, y, z)))
        print(target.relative_to(HERE))


if __name__ == "__main__":
    main()
