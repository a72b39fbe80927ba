"""Write the STL mesh of every element model of this example: a box of the model's size.

Each platform directory holds ``<platform>-models.xml`` and ``meshes/<number>.stl``. The box
stands on the model's origin: centred in x and y, from z = 0 up to its height, in metres (the
units RViz expects of a mesh marker). Run from anywhere: ``python make_meshes.py``.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path

import trimesh

HERE = Path(__file__).resolve().parent
TO_METRES = {"mm": 0.001, "m": 1.0}


def main() -> None:
    for models in sorted(HERE.glob("*/*-models.xml")):
        root = ET.parse(models).getroot()
        scale = TO_METRES[root.get("length_unit", "m")]
        meshes = models.parent / root.get("meshes", "meshes")
        meshes.mkdir(exist_ok=True)
        for model in root.iter("model"):
            size = model.find("dimensions")
            assert size is not None
            x, y, z = (float(size.get(axis, "0")) * scale for axis in ("x", "y", "z"))
            box = trimesh.creation.box(extents=(x, y, z))
            box.apply_translation((0.0, 0.0, z / 2))
            target = meshes / f"{model.get('number')}.stl"
            target.write_bytes(box.export(file_type="stl"))
            print(target.relative_to(HERE))


if __name__ == "__main__":
    main()
