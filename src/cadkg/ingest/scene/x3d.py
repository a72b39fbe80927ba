"""Reader of X3D scenes in the XML encoding (``.x3d``).

The file is untrusted XML: no DTD is loaded (real files name the web3d.org DTD), nothing is
fetched, and documents declaring entities are refused before parsing, so entity expansion
attacks cannot start. See docs/formats/scene.md for what is read.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from pathlib import Path
from typing import Any

from lxml import etree

from cadkg.errors import IngestError
from cadkg.ingest.scene.nodes import MAX_NESTING, Field, Node, ParsedFile
from cadkg.ingest.text import xml_document
from cadkg.ingest.xml_input import attributes_of, parse_untrusted_xml

__all__ = ["ITEM_NODES", "X3D_NAMESPACE", "parse_x3d", "x3d_parser"]

X3D_NAMESPACE = "http://www.web3d.org/specifications/x3d-namespace"
_EXPECTED = "an X3D document: <X3D> holding a <Scene>"
# Statements that are not nodes; the scene they describe (routes, prototypes) is not read.
_STATEMENTS = frozenset(
    {"ROUTE", "ProtoDeclare", "ExternProtoDeclare", "IMPORT", "EXPORT", "IS", "field", "fieldValue"}
)
_NOT_FIELDS = frozenset({"DEF", "USE", "containerField"})
# Nodes whose DEF name may name an item (or hold items); a name given twice on one of them
# is always an error, whatever the mode.
ITEM_NODES = frozenset(
    {"Group", "Transform", "Collision", "Anchor", "Switch", "LOD", "Billboard", "StaticGroup", "Inline"}
)
_DEFAULT_CONTAINER = {
    "Appearance": "appearance",
    "Coordinate": "coord",
    "CoordinateDouble": "coord",
    "Normal": "normal",
    "Color": "color",
    "ColorRGBA": "color",
    "TextureCoordinate": "texCoord",
}


def parse_x3d(path: Path, *, tolerate_geometry_defs: bool = False) -> ParsedFile:
    """Parse one X3D file into scene nodes (Inline files are not followed here).

    With ``tolerate_geometry_defs``, a DEF name given again on a node that cannot be an item
    (a ``Coordinate``, as Blender's exporter writes for shared meshes) is not an error here:
    the node records the first DEF's line and the walk skips its shape with a warning.
    """
    try:
        data = path.read_bytes()
    except OSError as err:
        raise IngestError(path, f"cannot read the file: {err.strerror}") from err
    document = xml_document(path, data, expected=_EXPECTED)
    root = parse_untrusted_xml(path, document, what="X3D", expected=_EXPECTED, allow_doctype=True)
    return _Builder(path, tolerate_geometry_defs).document(root)


def x3d_parser(*, tolerate_geometry_defs: bool = False) -> Callable[[Path], ParsedFile]:
    """:func:`parse_x3d` with its options bound, as the walk calls parsers."""
    return partial(parse_x3d, tolerate_geometry_defs=tolerate_geometry_defs)


def _local(element: Any) -> str:
    return str(etree.QName(element).localname)


class _Builder:
    def __init__(self, path: Path, tolerate_geometry_defs: bool = False) -> None:
        self.path = path
        self.source = str(path)
        self.defs: dict[str, Node] = {}
        self.tolerate = tolerate_geometry_defs

    def document(self, root: Any) -> ParsedFile:
        namespace = etree.QName(root).namespace
        if _local(root) != "X3D" or namespace not in (None, X3D_NAMESPACE):
            raise IngestError(
                self.path,
                "not an X3D document",
                line=root.sourceline,
                found=f"<{root.tag}>",
                expected=_EXPECTED,
            )
        children = [c for c in root if isinstance(c.tag, str)]
        scenes = [c for c in children if _local(c) == "Scene"]
        if not scenes:
            found = ", ".join(f"<{_local(c)}>" for c in children) or "nothing"
            raise IngestError(
                self.path, "no <Scene> in <X3D>", line=root.sourceline, found=found, expected=_EXPECTED
            )
        for head in (c for c in children if _local(c) == "head"):
            self.check_units(head)
        roots = [n for n in (self.node(c, "Scene", 1) for c in scenes[0] if isinstance(c.tag, str)) if n]
        return ParsedFile(roots, {name: node.line for name, node in self.defs.items()})

    def check_units(self, head: Any) -> None:
        # Lengths are read as metres; a declared length unit would make every number wrong.
        for unit in head:
            if not isinstance(unit.tag, str) or _local(unit) != "unit" or unit.get("category") != "length":
                continue
            factor = unit.get("conversionFactor", "1").strip()
            try:
                is_metre = float(factor) == 1.0
            except ValueError:
                is_metre = False
            if not is_metre:
                raise IngestError(
                    self.path,
                    "a length unit other than metres is declared",
                    line=unit.sourceline,
                    found=f"conversionFactor={factor}",
                    expected="lengths in metres (no length <unit>, or conversionFactor 1)",
                )

    def node(self, element: Any, parent: str, depth: int) -> Node | None:
        kind = _local(element)
        if kind in _STATEMENTS or kind.startswith("Metadata"):
            return None
        line = element.sourceline or 0
        if depth > MAX_NESTING:
            raise IngestError(self.path, f"elements nest deeper than {MAX_NESTING} levels", line=line)
        use = element.get("USE")
        if use is not None:
            target = self.defs.get(use.strip())
            if target is None:
                raise IngestError(
                    self.path,
                    f"USE of an undefined name in <{kind}>",
                    line=line,
                    found=use,
                    expected="the DEF name of an earlier element",
                )
            return Node(kind, self.source, line, use_of=target)
        fields = {k: Field(line, v) for k, v in attributes_of(element).items() if k not in _NOT_FIELDS}
        node = Node(kind, self.source, line, fields=fields)
        for child in element:
            if not isinstance(child.tag, str):
                continue
            sub = self.node(child, kind, depth + 1)
            if sub is not None:
                node.nodes.setdefault(self.container(child, sub.type, kind), []).append(sub)
        name = element.get("DEF")
        if name is not None and name.strip():
            self.define(node, name.strip())
        return node

    def container(self, element: Any, kind: str, parent: str) -> str:
        explicit = element.get("containerField")
        if explicit:
            return str(explicit)
        if kind in _DEFAULT_CONTAINER:
            return _DEFAULT_CONTAINER[kind]
        return "geometry" if parent == "Shape" else "children"

    def define(self, node: Node, name: str) -> None:
        first = self.defs.get(name)
        if first is not None and self.tolerate and node.type not in ITEM_NODES:
            node.def_name, node.redefines = name, first.line
            return
        if first is not None:
            raise IngestError(
                self.path,
                f"DEF name {name} given twice (first on line {first.line})",
                line=node.line,
                found=name,
                expected="each DEF name once",
            )
        node.def_name = name
        self.defs[name] = node
