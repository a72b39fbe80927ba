"""The walk that turns a parsed scene graph into items: it composes the transforms, meshes the
shapes, follows Inline files and collects the DEF-named groups as :class:`SceneItem`.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path, PureWindowsPath
from urllib.parse import unquote

import numpy as np

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.scene.nodes import (
    Node,
    ParsedFile,
    Parser,
    floats_of,
    ints_of,
    strings_of,
    vector_of,
)
from cadkg.ingest.scene.records import (
    Floats,
    Ints,
    Numbers,
    Part,
    SceneItem,
    Vec3,
    apply_affine,
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
    transform_matrix,
)

__all__ = ["MAX_EXPANDED", "STRICT", "WalkOptions", "read_scene"]

_MAX_WALK_DEPTH = 300
# The scene as the walk expands it: every node visited (a USE at each use) and every vertex
# placed. DEF and USE let a few KB say more: each level using the one below twice doubles it,
# and eighteen levels of spheres were 2.4 GB. No CAD export comes near this.
MAX_EXPANDED = 1 << 22

_GROUPS = frozenset(
    {"Group", "Transform", "Collision", "Anchor", "Switch", "LOD", "Billboard", "StaticGroup"}
)
_TRANSFORM_FIELDS: dict[str, tuple[float, ...]] = {
    "translation": (0.0, 0.0, 0.0),
    "rotation": (0.0, 0.0, 1.0, 0.0),
    "scale": (1.0, 1.0, 1.0),
    "scaleOrientation": (0.0, 0.0, 1.0, 0.0),
    "center": (0.0, 0.0, 0.0),
}
_COORDINATES = frozenset({"Coordinate", "CoordinateDouble"})
# Nodes that place no geometry in the scene: read silently as nothing.
_NOT_GEOMETRY = frozenset(
    {
        "Background",
        "TextureBackground",
        "Fog",
        "NavigationInfo",
        "Viewpoint",
        "OrthoViewpoint",
        "WorldInfo",
        "Script",
        "Sound",
        "AudioClip",
        "DirectionalLight",
        "PointLight",
        "SpotLight",
    }
)
_NOT_GEOMETRY_SUFFIXES = ("Sensor", "Interpolator", "Trigger", "Sequencer", "Filter", "Chaser", "Damper")
_SCHEME = re.compile(r"^([A-Za-z][A-Za-z0-9+.\-]*):")


# --- the walk ------------------------------------------------------------------------------------------


@dataclass(slots=True)
class _Item:
    node: Node
    parent: _Item | None
    inverse: Floats
    relative: Floats
    parts: list[Part] = field(default_factory=list)


def _warn(node: Node, reason: str) -> None:
    warnings.warn(IngestWarning(node.source, reason, line=node.line), stacklevel=4)


def _bad_numbers(node: Node, name: str, reason: str, values: Iterable[float], expected: str) -> IngestError:
    """An error at the line of ``node``'s field ``name``, showing its numbers."""
    found = " ".join(f"{v:g}" for v in values)
    return IngestError(node.source, reason, line=node.fields[name].line, found=found, expected=expected)


@dataclass(frozen=True, slots=True)
class WalkOptions:
    """How forgiving the walk is (the defaults are strict).

    ``skip_broken_shapes``: a shape whose coordinates are broken (a point list that is not
    x y z triples, an index past the points, a DEF name given again on its Coordinate) is
    skipped with one warning naming its line instead of stopping the read; the item keeps
    its frame. ``transforms_only``: only DEF-named Transforms are items; the shapes of a
    DEF-named Group count for the Transform around it.
    """

    skip_broken_shapes: bool = False
    transforms_only: bool = False


STRICT = WalkOptions()


class _Walk:
    def __init__(self, top: Path, parsers: dict[str, Parser], options: WalkOptions = STRICT) -> None:
        self.options = options
        # The directory as named, so a scene reached through a symbolic link keeps its neighbours.
        self.top_dir = top.parent.resolve()
        self.display_dir = top.parent
        self.parsers = parsers
        self.items: list[_Item] = []
        self.defs: dict[str, tuple[str, int]] = {}
        self.chain: list[Path] = []
        self.inlined: dict[int, tuple[Path, ParsedFile]] = {}
        self.meshes: dict[int, Part | None] = {}
        self.loose: dict[str, list[int]] = {}
        self.expanded = 0

    def grow(self, size: int, node: Node) -> None:
        self.expanded += size
        if self.expanded > MAX_EXPANDED:
            raise IngestError(
                node.source,
                "the scene expands to more than cadkg reads (each USE counted where it is used)",
                line=node.line,
                expected=f"at most {MAX_EXPANDED:,} nodes and mesh vertices placed",
            )

    def add_file(self, path: Path, parsed: ParsedFile) -> None:
        for name, line in parsed.defs.items():
            if name in self.defs:
                first, first_line = self.defs[name]
                again = "; the file is inlined more than once" if first == str(path) else ""
                raise IngestError(
                    path,
                    f"DEF name {name} is already defined at {first}:{first_line}{again}",
                    line=line,
                    found=name,
                    expected="DEF names unique across the scene and its Inline files",
                )
            self.defs[name] = (str(path), line)

    def visit(self, node: Node, world: Floats, item: _Item | None, use: Node | None, depth: int) -> None:
        if depth > _MAX_WALK_DEPTH:
            raise IngestError(
                node.source, f"the scene nests deeper than {_MAX_WALK_DEPTH} levels", line=node.line
            )
        self.grow(1, use or node)
        if node.use_of is not None:
            use = use or node
            node = node.use_of
        kind = node.type
        if kind in _GROUPS:
            if kind == "Transform" and not _TRANSFORM_FIELDS.keys().isdisjoint(node.fields):
                world = world @ self.transform(node)
            if node.def_name is not None and (kind == "Transform" or not self.options.transforms_only):
                item = self.new_item(node, world, item, use)
            for child in self.children(node):
                self.visit(child, world, item, use, depth + 1)
        elif kind == "Shape":
            self.shape(node, world, item)
        elif kind == "Inline":
            self.inline(node, world, item, use, depth)
        elif kind not in _NOT_GEOMETRY and not kind.endswith(_NOT_GEOMETRY_SUFFIXES):
            _warn(node, f"{kind} node is not read (not a grouping, Shape or Inline node); skipped")

    def transform(self, node: Node) -> Floats:
        values: dict[str, Numbers] = {
            name: vector_of(node, name, default) if name in node.fields else default
            for name, default in _TRANSFORM_FIELDS.items()
        }
        for name in ("rotation", "scaleOrientation"):
            value = values[name]
            if value[0] == value[1] == value[2] == 0.0 and value[3] != 0.0:
                raise _bad_numbers(
                    node,
                    name,
                    f"{name!r} of {node.type} has a zero axis and a non-zero angle",
                    value,
                    "an axis x y z that is not 0 0 0, then the angle in radians",
                )
        if 0.0 in tuple(values["scale"]):
            # Legal, but it flattens everything below it: a slip in an export more often than not.
            _warn(node, f"'scale' of {node.type} has a zero factor; the geometry below it is flat")
        return transform_matrix(
            values["translation"],
            values["rotation"],
            values["scale"],
            values["scaleOrientation"],
            values["center"],
        )

    def children(self, node: Node) -> list[Node]:
        if node.type == "Switch":
            # VRML97 calls the field choice, X3D children; only the chosen one is shown.
            choices = node.nodes.get("choice") or node.nodes.get("children", [])
            which = ints_of(node, "whichChoice")
            chosen = int(which[0]) if which.size else -1
            return [choices[chosen]] if 0 <= chosen < len(choices) else []
        if node.type == "LOD":
            levels = node.nodes.get("level") or node.nodes.get("children", [])
            return levels[:1]
        return node.nodes.get("children", [])

    def new_item(self, node: Node, world: Floats, parent: _Item | None, use: Node | None) -> _Item:
        if use is not None:
            target = use.use_of.def_name if use.use_of is not None else None
            raise IngestError(
                use.source,
                f"USE {target} repeats item {node.def_name} (DEF at {node.source}:{node.line}); "
                "an item ID must name one thing",
                line=use.line,
                found=f"USE {target}",
                expected="USE only of nodes that are not and do not contain DEF-named Transforms or Groups",
            )
        rotation, _ = split_affine(world[:3, :3])
        rigid = rigid_matrix(rotation, world[:3, 3])
        relative = rigid if parent is None else parent.inverse @ rigid
        item = _Item(node, parent, invert_rigid(rigid), relative)
        self.items.append(item)
        return item

    def shape(self, node: Node, world: Floats, item: _Item | None) -> None:
        for geometry in node.nodes.get("geometry", []):
            target = geometry.use_of or geometry
            key = id(target)
            if key not in self.meshes:
                self.meshes[key] = self.mesh(target, item)
            part = self.meshes[key]
            if part is None:
                continue
            if item is None:
                self.loose.setdefault(node.source, []).append(node.line)
                continue
            vertices, faces = part
            self.grow(len(vertices), node)
            item.parts.append((apply_affine(item.inverse @ world, vertices), faces))

    def mesh(self, node: Node, item: _Item | None = None) -> Part | None:
        kind = node.type
        if kind == "Box":
            return box_mesh(self.sizes(node, "size", (2.0, 2.0, 2.0)))
        if kind == "Sphere":
            return sphere_mesh(*self.sizes(node, "radius", (1.0,)))
        if kind == "Cylinder":
            (radius,) = self.sizes(node, "radius", (1.0,))
            (height,) = self.sizes(node, "height", (2.0,))
            return cylinder_mesh(radius, height)
        if kind == "Cone":
            (radius,) = self.sizes(node, "bottomRadius", (1.0,))
            (height,) = self.sizes(node, "height", (2.0,))
            return cone_mesh(radius, height)
        if kind == "IndexedFaceSet":
            return self.indexed(node, "coordIndex", fan_triangulate, item)
        if kind == "IndexedTriangleSet":
            return self.indexed(node, "index", self.triangles, item)
        _warn(node, f"{kind} geometry is not read; skipped")
        return None

    def sizes(self, node: Node, name: str, default: tuple[float, ...]) -> tuple[float, ...]:
        values = vector_of(node, name, default)
        if (values < 0.0).any():
            raise _bad_numbers(node, name, f"negative {name!r} of {node.type}", values, "sizes of 0 or more")
        return tuple(float(v) for v in values)

    def triangles(self, index: Ints) -> Ints:
        return index[: index.size - index.size % 3].reshape(-1, 3)

    def indexed(
        self, node: Node, name: str, triangulate: Callable[[Ints], Ints], item: _Item | None = None
    ) -> Part | None:
        coords = [c.use_of or c for c in node.nodes.get("coord", [])]
        if not coords:
            if ints_of(node, name).size:
                _warn(node, f"{node.type} has a {name} but no coordinates; skipped")
            return None
        coord = coords[0]
        if coord.type not in _COORDINATES:
            _warn(coord, f"{coord.type} coordinates are not read; {node.type} skipped")
            return None
        broken: list[IngestError] = []
        if coord.redefines is not None:
            broken.append(
                IngestError(
                    coord.source,
                    f"DEF name {coord.def_name or '?'} given twice (first on line {coord.redefines})",
                    line=coord.line,
                )
            )
        try:
            points = floats_of(coord, "point")
        except IngestError as err:
            broken.append(err)
            points = None
        if points is not None and points.size % 3:
            broken.append(
                IngestError(
                    coord.source,
                    f"'point' of {coord.type} has {points.size} numbers",
                    line=coord.fields["point"].line,
                    expected="x y z triples (a multiple of 3 numbers)",
                )
            )
        try:
            index = ints_of(node, name)
        except IngestError as err:
            broken.append(err)
            index = np.empty(0, dtype=np.int64)
        # Unreadable points cannot be indexed: the index is not checked against them.
        readable = points is not None
        whole = np.empty(0) if points is None else points[: points.size - points.size % 3]
        points = whole.reshape(-1, 3)
        minimum = 0 if name == "index" else -1
        bad = index[(index < minimum) | (index >= len(points))]
        if bad.size and readable:
            broken.append(
                IngestError(
                    node.source,
                    f"{name} {int(bad[0])} of {node.type} is out of range",
                    line=node.fields[name].line,
                    found=int(bad[0]),
                    expected=f"{'-1 or ' if minimum < 0 else ''}an index below {len(points)} "
                    f"(the {coord.type} has {len(points)} points)",
                )
            )
        if broken:
            if not self.options.skip_broken_shapes:
                raise broken[0]
            owner = f" of item {item.node.def_name}" if item is not None else ""
            reasons = "; ".join(err.reason + (f" ({err.found!r})" if err.found else "") for err in broken)
            _warn(node, f"shape{owner} skipped, its item keeps its frame: {reasons}")
            return None
        faces = triangulate(index)
        if not len(faces):
            return None
        # Only the points the faces use are geometry: unused ones must not widen the box.
        used, faces = np.unique(faces, return_inverse=True)
        return points[used], faces.reshape(-1, 3).astype(np.int64)

    def inline(self, node: Node, world: Floats, item: _Item | None, use: Node | None, depth: int) -> None:
        cached = self.inlined.get(id(node))
        if cached is None:
            path = self.resolve(node)
            if path is None:
                return
            real = path.resolve()
            if real in self.chain:
                loop = [*self.chain[self.chain.index(real) :], real]
                names = [
                    str(p.relative_to(self.top_dir)) if p.is_relative_to(self.top_dir) else p.name
                    for p in loop
                ]
                raise IngestError(
                    node.source,
                    "Inline cycle: " + " → ".join(names),
                    line=node.line,
                    expected="Inline files that do not include themselves",
                )
            parser = self.parsers.get(path.suffix.lower())
            if parser is None:
                raise IngestError(
                    node.source,
                    "Inline file type is not read",
                    line=node.line,
                    found=path.name,
                    expected=f"a file ending in {' or '.join(sorted(self.parsers))}",
                )
            parsed = parser(path)
            self.add_file(path, parsed)
            cached = self.inlined[id(node)] = (real, parsed)
        real, parsed = cached
        self.chain.append(real)
        for root in parsed.roots:
            self.visit(root, world, item, use, depth + 1)
        self.chain.pop()

    def resolve(self, node: Node) -> Path | None:
        urls = [u.strip() for u in strings_of(node, "url") if u.strip()]
        if not urls:
            _warn(node, "Inline without url; skipped")
            return None
        base = Path(node.source).parent
        remote: list[str] = []
        missing: list[str] = []
        for text in urls:
            scheme = _SCHEME.match(text)
            if scheme and len(scheme.group(1)) > 1:
                remote.append(text)
                continue
            relative = unquote(text.split("#", 1)[0])
            if not relative or relative.startswith(("/", "\\")) or PureWindowsPath(relative).drive:
                raise IngestError(
                    node.source,
                    "Inline url is an absolute path",
                    line=node.line,
                    found=text,
                    expected="a path relative to the scene file",
                )
            candidate = (base / relative).resolve()
            if not candidate.is_relative_to(self.top_dir):
                raise IngestError(
                    node.source,
                    "Inline url leads outside the directory of the scene file",
                    line=node.line,
                    found=text,
                    expected=f"a file under {self.top_dir}",
                )
            if candidate.is_file():
                return self.display_dir / candidate.relative_to(self.top_dir)
            missing.append(text)
        if remote and not missing:
            raise IngestError(
                node.source,
                "Inline url is not a local file; network resources are never read",
                line=node.line,
                found=remote[0],
                expected="a relative path to a file beside the scene file",
            )
        raise IngestError(
            node.source,
            "Inline file not found",
            line=node.line,
            found=", ".join(missing),
            expected="an existing file relative to the file with the Inline",
        )

    def records(self) -> Iterator[SceneItem]:
        for item in self.items:
            mesh = merge_meshes(item.parts)
            low = high = None
            if mesh is not None:
                low, high = _vec3(mesh.vertices.min(axis=0)), _vec3(mesh.vertices.max(axis=0))
            yield SceneItem(
                item_id=str(item.node.def_name),
                parent_id=None if item.parent is None else item.parent.node.def_name,
                translation=_vec3(item.relative[:3, 3]),
                rotation=quaternion_from_matrix(item.relative[:3, :3]),
                bbox_min=low,
                bbox_max=high,
                mesh=mesh,
                source=item.node.source,
                line=item.node.line,
            )


def _vec3(values: Floats) -> Vec3:
    return (float(values[0]), float(values[1]), float(values[2]))


def read_scene(
    path: str | Path, parse: Parser, parsers: dict[str, Parser], options: WalkOptions = STRICT
) -> list[SceneItem]:
    """Read the scene file ``path`` with ``parse`` and any Inline files it names with the parser
    of their suffix in ``parsers``, as items."""
    top = Path(path)
    walk = _Walk(top, parsers, options)
    parsed = parse(top)
    walk.add_file(top, parsed)
    walk.chain.append(top.resolve())
    for root in parsed.roots:
        walk.visit(root, np.eye(4), None, None, 0)
    for source, lines in walk.loose.items():
        warnings.warn(
            IngestWarning(
                source,
                f"{len(lines)} shape(s) outside any DEF-named Transform or Group are not read",
                line=lines[0],
            ),
            stacklevel=3,
        )
    items = list(walk.records())
    if not items:
        warnings.warn(
            IngestWarning(path, "no items: the scene has no DEF-named Transform or Group"), stacklevel=3
        )
    return items
