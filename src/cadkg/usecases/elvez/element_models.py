"""Reader of platform element models: each model's size, points of interest and STL mesh.

One file per platform (D3.1 section 4.3, Figure 24c): for every element model (``0009``, a
guide) its dimensions, its named frames of interest (``key``, ``key_corner`` ...) relative to
the model's origin, the size of a guide's key (length, gap, height), and, when the root names a
mesh directory, the STL mesh ``<directory>/<number>.stl``. See docs/formats/elvez-models.md.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path, PureWindowsPath

from lxml import etree

from cadkg.usecases.elvez.xml_fields import Placement, Units, XmlReader, first_element_name

__all__ = [
    "ROOT",
    "ElementModel",
    "KeySize",
    "PointOfInterest",
    "looks_like_element_models",
    "read_element_models",
]

ROOT = "element_models"
_EXPECTED = '<element_models length_unit="mm" angle_unit="deg"> holding <model number="..."> elements'
# The number names the mesh file, so it must be a plain file name.
_NUMBER = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")
_FRAME_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")
_MAX_MESH_BYTES = 64 << 20


@dataclass(frozen=True, slots=True)
class PointOfInterest:
    """A named frame of a model (``key``, ``key_corner`` ...), relative to the model's origin."""

    name: str
    placement: Placement


@dataclass(frozen=True, slots=True)
class KeySize:
    """The key (cable slot) of a guide model: length, gap and height in metres."""

    length: float
    gap: float
    height: float
    line: int


@dataclass(frozen=True, slots=True)
class ElementModel:
    """One ``<model>``: sizes in metres, frames relative to the model origin, the mesh bytes."""

    number: str
    description: str | None
    dimensions: tuple[float, float, float]
    frames: tuple[PointOfInterest, ...]
    key: KeySize | None
    mesh: bytes | None
    mesh_file: str | None
    line: int


def looks_like_element_models(head: bytes) -> bool:
    """Whether the file's first element is ``<element_models>``."""
    return first_element_name(head) == ROOT


def read_element_models(path: str | Path) -> list[ElementModel]:
    """Read an element models file (and the STL mesh of each model when a directory is named).

    Raises
    ------
    IngestError
        On an empty or binary file, malformed XML, a document type or entity declaration, a
        root other than ``<element_models>``, unknown units, elements or attributes, a missing
        or malformed number, a negative size, a model or frame given twice, a mesh directory
        outside the file's directory, a missing mesh or one that is not an STL file.
    """
    return _Reader(Path(path)).read()


class _Reader(XmlReader):
    def __init__(self, path: Path) -> None:
        super().__init__(path, _EXPECTED)
        self.file = path

    def read(self) -> list[ElementModel]:
        root = self.root(ROOT)
        self.attributes(root, ("length_unit", "angle_unit"), ("meshes",))
        units = self.units(root)
        meshes = self.mesh_dir(root)
        models: list[ElementModel] = []
        seen: dict[str, int] = {}
        for element in self.children(root, ("model",)):
            model = self.model(element, units, meshes)
            if model.number in seen:
                raise self.error(
                    f"model {model.number!r} given twice (first on line {seen[model.number]})",
                    element,
                    expected="each model number once",
                )
            seen[model.number] = model.line
            models.append(model)
        if not models:
            raise self.error("no <model> in <element_models>", root, expected=_EXPECTED)
        return models

    def mesh_dir(self, root: etree._Element) -> tuple[Path, str] | None:
        written = self.text(root, "meshes")
        if "meshes" not in root.attrib:
            return None
        if not written or written.startswith(("/", "\\")) or PureWindowsPath(written).drive:
            raise self.error(
                "'meshes' must be a directory relative to this file",
                root,
                found=written,
                expected='a relative path such as meshes="meshes"',
            )
        base = self.file.parent.resolve()
        directory = (base / written).resolve()
        if not directory.is_relative_to(base):
            raise self.error(
                "'meshes' leads outside the directory of this file",
                root,
                found=written,
                expected="a directory beside or below this file",
            )
        if not directory.is_dir():
            raise self.error(
                "mesh directory not found", root, found=written, expected="an existing directory"
            )
        return directory, written.rstrip("/\\")

    def model(self, element: etree._Element, units: Units, meshes: tuple[Path, str] | None) -> ElementModel:
        self.attributes(element, ("number",), ("description",))
        number = self.text(element, "number")
        if not _NUMBER.match(number):
            raise self.error(
                "malformed model number",
                element,
                found=number,
                expected="letters, digits, _ . - (the number names the STL file), e.g. 0009",
            )
        self.children(element, ("dimensions", "frame", "key"))
        dimensions = self.one(element, "dimensions", required=True)
        assert dimensions is not None
        frames: list[PointOfInterest] = []
        first: dict[str, int] = {}
        for frame in (c for c in element if isinstance(c.tag, str) and c.tag == "frame"):
            name = self.text(frame, "name")
            if not _FRAME_NAME.match(name):
                raise self.error(
                    f"malformed frame name in model {number!r}",
                    frame,
                    found=name or None,
                    expected="a name of letters, digits and _, starting with a letter, e.g. key_corner",
                )
            if name in first:
                raise self.error(
                    f"frame {name!r} given twice in model {number!r} (first on line {first[name]})",
                    frame,
                    expected="each frame name once per model",
                )
            first[name] = int(frame.sourceline or 0)
            frames.append(PointOfInterest(name, self.placement(frame, units, ("name",))))
        key_element = self.one(element, "key", required=False)
        key = None
        if key_element is not None:
            self.attributes(key_element, ("length", "gap", "height"))
            length, gap, height = (
                self.number(key_element, name, minimum=0.0) * units.length
                for name in ("length", "gap", "height")
            )
            key = KeySize(length, gap, height, int(key_element.sourceline or 0))
        mesh, mesh_file = self.mesh(element, number, meshes)
        return ElementModel(
            number=number,
            description=self.text(element, "description") or None,
            dimensions=self.size(dimensions, units),
            frames=tuple(frames),
            key=key,
            mesh=mesh,
            mesh_file=mesh_file,
            line=int(element.sourceline or 0),
        )

    def mesh(
        self, element: etree._Element, number: str, meshes: tuple[Path, str] | None
    ) -> tuple[bytes | None, str | None]:
        if meshes is None:
            return None, None
        directory, written = meshes
        shown = f"{written}/{number}.stl"
        path = directory / f"{number}.stl"
        try:
            size = path.stat().st_size
            if size > _MAX_MESH_BYTES:
                raise self.error(
                    f"mesh of model {number!r} is too large ({size} bytes)",
                    element,
                    found=shown,
                    expected=f"an STL file under {_MAX_MESH_BYTES >> 20} MiB",
                )
            data = path.read_bytes()
        except OSError:
            raise self.error(
                f"no mesh for model {number!r}",
                element,
                found=shown,
                expected="an STL file named by the model number in the mesh directory",
            ) from None
        if not _is_stl(data):
            raise self.error(
                f"the mesh of model {number!r} is not an STL file",
                element,
                found=shown,
                expected="binary STL (84-byte header, 50 bytes a triangle) or ASCII STL (solid ... endsolid)",
            )
        return data, shown


def _is_stl(data: bytes) -> bool:
    if len(data) >= 84:
        triangles = int.from_bytes(data[80:84], "little")
        if len(data) == 84 + 50 * triangles and triangles > 0:
            return True
    text = data[:1024].lstrip().lower()
    return (
        text.startswith(b"solid") and b"facet" in data[:4096].lower() and b"endsolid" in data[-1024:].lower()
    )
