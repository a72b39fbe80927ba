"""GraphML export of a harness for detection systems: the topology view and the wire view.

The views (:mod:`cadkg.usecases.vw.views`) are written straight to the file, element by element,
without building a networkx graph or a document tree: a 100k-wire harness writes in a second.
Keys are typed (``string``, ``long``, ``double``) and declared for every attribute a view may
carry; every value is a scalar (lists are ``;``-joined strings); node and edge ids are the
things' IRIs relative to the cell, written in id order, so the same graph always gives the same
file. With ``yed``, yEd's graphics extension is added: each node's geometry (from its position,
else from a layout of the graph) and label, so yEd draws the harness as it opens it.
See docs/formats/graphml.md.
"""

from __future__ import annotations

import io
import math
import re
from collections import defaultdict, deque
from collections.abc import Callable, Sequence
from operator import itemgetter
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

from cadkg.errors import QueryError
from cadkg.loading import paused_gc
from cadkg.usecases.vw.harness_data import find_harness, topology_data, wire_data
from cadkg.usecases.vw.views import View, choose_modules, networkx_graph, topology_view, wire_view

if TYPE_CHECKING:
    import networkx as nx

    from cadkg.graph import KnowledgeGraph

__all__ = [
    "VIEWS",
    "graphml_text",
    "harness_graph",
    "harness_graphml",
    "harness_view",
    "write_graphml",
    "write_harness_graphml",
]

VIEWS = ("topology", "wires")
"""``topology``: nodes are harness nodes, edges segments; ``wires``: nodes are cavities, edges wires."""

_GRAPH_KEYS = (
    ("harness", "string"),
    ("harness_id", "string"),
    ("view", "string"),
    ("modules", "string"),
    ("frame", "string"),
)
_KEYS = {
    "topology": (
        (
            ("label", "string"),
            ("node_name", "string"),
            ("kind", "string"),
            ("degree", "long"),
            ("connectors", "string"),
            ("fixings", "string"),
            ("x", "double"),
            ("y", "double"),
            ("z", "double"),
        ),
        (
            ("label", "string"),
            ("from_node", "string"),
            ("to_node", "string"),
            ("length_m", "double"),
            ("length_source", "string"),
            ("diameter_m", "double"),
            ("section_mm2", "double"),
            ("wires", "string"),
            ("wire_ids", "string"),
            ("wire_count", "long"),
            ("fixings", "string"),
            ("protections", "string"),
        ),
    ),
    "wires": (
        (("label", "string"), ("connector", "string"), ("cavity", "string"), ("harness_node", "string")),
        (
            ("label", "string"),
            ("wire_number", "string"),
            ("from_cavity", "string"),
            ("to_cavity", "string"),
            ("section_mm2", "double"),
            ("length_m", "double"),
            ("diameter_m", "double"),
            ("colour", "string"),
            ("cable", "string"),
            ("signal", "string"),
            ("segments", "string"),
        ),
    ),
}
_HEAD = (
    "<?xml version='1.0' encoding='utf-8'?>\n"
    '<graphml xmlns="http://graphml.graphdrawing.org/xmlns"'
    ' xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance"{yed}'
    ' xsi:schemaLocation="http://graphml.graphdrawing.org/xmlns'
    ' http://graphml.graphdrawing.org/xmlns/1.0/graphml.xsd">\n'
)
_YED_NS = ' xmlns:y="http://www.yworks.com/xml/graphml"'
# yEd's canvas: one unit per millimetre of the harness, seen from above with the front to the left.
_PER_METRE = 1000.0
_SIZE = 20.0
_COLOURS = {
    "connector": "#FF9900",
    "fixing": "#3366CC",
    "branch": "#999999",
    "end": "#CCCCCC",
    "inline": "#E0E0E0",
}
_CHUNK = 20_000


# Characters XML 1.0 does not allow, even as references: replaced by U+FFFD, so the file stays
# well-formed. Tab, line feed and carriage return are written as references, which a parser
# keeps as they are (it would turn them into spaces in an attribute, \r into \n in text).
_FORBIDDEN = re.compile("[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]")
_REFERENCES = str.maketrans(
    {"&": "&amp;", "<": "&lt;", ">": "&gt;", '"': "&quot;", "\t": "&#9;", "\n": "&#10;", "\r": "&#13;"}
)


def _escape(text: str) -> str:
    if text.isprintable() and "&" not in text and "<" not in text and ">" not in text and '"' not in text:
        return text
    return _FORBIDDEN.sub("\ufffd", text).translate(_REFERENCES)


Row = tuple[Any, ...]


class _Lines:
    """The lines of the nodes or edges of a view, from one ``%`` template per set of attributes
    a row carries: a row's values are formatted in one call, its texts checked at once (one
    join, then a scan for what XML needs escaped) and escaped only where needed."""

    def __init__(
        self, element: str, head: str, keys: Sequence[tuple[str, str]], ids: dict[tuple[str, str], str]
    ) -> None:
        self.element, self.head = element, head
        self.fixed = head.count("%s")
        self.types = dict(keys)
        self.ids = {name: ids[(element, name)] for name, _ in keys}
        self.templates: dict[tuple[str, ...], tuple[str, Callable[[Row], tuple[Any, ...]]]] = {}

    def template(self, names: tuple[str, ...]) -> tuple[str, Callable[[Row], tuple[Any, ...]]]:
        parts = [self.head]
        texts = list(range(self.fixed))
        for index, name in enumerate(names, start=self.fixed):
            kind = self.types.get(name)
            if kind is None:
                raise TypeError(f"a {self.element} attribute GraphML does not declare: {name!r}")
            parts.append(f'<data key="{self.ids[name]}">{"%r" if kind == "double" else "%s"}</data>')
            if kind == "string":
                texts.append(index)
        pick = itemgetter(*texts)
        picker: Callable[[Row], tuple[Any, ...]] = pick if len(texts) > 1 else lambda v: (pick(v),)
        entry = self.templates[names] = ("".join(parts) + f"</{self.element}>\n", picker)
        return entry

    def line(self, names: tuple[str, ...], values: Row) -> str:
        """The row's line: its texts joined once and scanned for what XML needs escaped, and
        escaped (one by one) only when something is."""
        text, pick = self.templates.get(names) or self.template(names)
        try:
            joined = "".join(pick(values))
        except TypeError:
            values = self.checked(names, values)
        else:
            if not joined.isprintable() or "&" in joined or "<" in joined or ">" in joined or '"' in joined:
                values = self.checked(names, values)
        return text % values

    def checked(self, names: tuple[str, ...], values: Row) -> Row:
        """``values`` with their texts escaped; raises TypeError when one is not a text."""
        where = f"{self.element} {values[self.fixed - 1]}"  # the node's id, the edge's key
        texts = set(range(self.fixed)) | {
            i for i, name in enumerate(names, start=self.fixed) if self.types[name] == "string"
        }
        for i in sorted(texts):
            if not isinstance(values[i], str):
                # GraphML has no list type; a list would be written as its Python repr.
                wrong = names[i - self.fixed] if i >= self.fixed else "id"
                raise TypeError(f"{where}: attribute {wrong!r} is not a text")
        return tuple(_escape(v) if i in texts else v for i, v in enumerate(values))


def write_graphml(view: View, out: TextIO, *, yed: bool = False) -> None:
    """Write ``view`` as GraphML to ``out``, streaming: keys, graph data, nodes, edges.

    Raises
    ------
    TypeError
        When an attribute is not a scalar of its key's type (a list ...), or has no key.
    """
    node_keys, edge_keys = _KEYS[view.graph["view"]]
    ids: dict[tuple[str, str], str] = {}
    lines = [_HEAD.format(yed=_YED_NS if yed else "")]
    for scope, keys in (("graph", _GRAPH_KEYS), ("node", node_keys), ("edge", edge_keys)):
        for name, kind in keys:
            ident = ids[(scope, name)] = f"d{len(ids)}"
            lines.append(f'  <key id="{ident}" for="{scope}" attr.name="{name}" attr.type="{kind}"/>\n')
    graphics = f"d{len(ids)}"
    if yed:
        lines.append(f'  <key id="{graphics}" for="node" yfiles.type="nodegraphics"/>\n')
    lines.append('  <graph edgedefault="undirected">\n')
    for name, kind in _GRAPH_KEYS:
        if name in view.graph:
            value = view.graph[name]
            shown = repr(float(value)) if kind == "double" else _escape(str(value))
            lines.append(f'    <data key="{ids[("graph", name)]}">{shown}</data>\n')
    write = out.write
    write("".join(lines))
    nodes = _Lines("node", '    <node id="%s">', node_keys, ids)
    places = _places(view) if yed else {}
    kind = view.graph["view"]
    # Hot loops (a row per node and per edge): a line a row, written a chunk at a time.
    for start in range(0, len(view.nodes), _CHUNK):
        lines = []
        append = lines.append
        for node, attributes in view.nodes[start : start + _CHUNK]:
            line = nodes.line(tuple(attributes), (node, *attributes.values()))
            if yed:
                line = (
                    line[: -len("</node>\n")] + _shape(graphics, places[node], attributes, kind) + "</node>\n"
                )
            append(line)
        write("".join(lines))
    edges = _Lines("edge", '    <edge source="%s" target="%s" id="%s">', edge_keys, ids)
    for start in range(0, len(view.edges), _CHUNK):
        lines = []
        append = lines.append
        for u, v, key, attributes in view.edges[start : start + _CHUNK]:
            values = (u, v, key, *attributes.values()) if u <= v else (v, u, key, *attributes.values())
            append(edges.line(tuple(attributes), values))
        write("".join(lines))
    write("  </graph>\n</graphml>\n")


# -- yEd -----------------------------------------------------------------------------------------------


def _shape(key: str, place: tuple[float, float], attributes: dict[str, Any], view: str) -> str:
    x, y = place
    colour = _COLOURS.get(attributes.get("kind", ""), "#FFCC66" if view == "wires" else "#CCCCCC")
    return (
        f'<data key="{key}"><y:ShapeNode><y:Geometry x="{x - _SIZE / 2:.1f}" y="{y - _SIZE / 2:.1f}"'
        f' width="{_SIZE:.1f}" height="{_SIZE:.1f}"/><y:Fill color="{colour}" transparent="false"/>'
        f"<y:NodeLabel>{_escape(str(attributes.get('label', '')))}</y:NodeLabel>"
        '<y:Shape type="ellipse"/></y:ShapeNode></data>'
    )


def _places(view: View) -> dict[str, tuple[float, float]]:
    """Where yEd draws each node: the top view of its position, else a layered layout."""
    nodes = dict(view.nodes)
    if view.graph["view"] == "topology":
        if nodes and all("x" in a for a in nodes.values()):
            return {n: (-a["x"] * _PER_METRE, a["y"] * _PER_METRE) for n, a in nodes.items()}
        return _layers(list(nodes), [(u, v) for u, v, _, _ in view.edges])
    # Wires: a connector's cavities in a row at its harness node, or connectors on a grid.
    by_connector: dict[str, list[str]] = defaultdict(list)
    for node, attributes in view.nodes:
        by_connector[attributes.get("connector", "")].append(node)
    columns = max(1, math.ceil(math.sqrt(len(by_connector))))
    places = {}
    for index, (_, cavities) in enumerate(sorted(by_connector.items())):
        row, column = divmod(index, columns)
        for offset, node in enumerate(cavities):
            places[node] = (column * 400.0 + offset * (_SIZE + 5), row * 120.0)
    return places


def _layers(nodes: list[str], edges: Sequence[tuple[str, str]]) -> dict[str, tuple[float, float]]:
    """Breadth-first layers from the first node of each connected part: one column per layer."""
    neighbours: dict[str, list[str]] = defaultdict(list)
    for u, v in edges:
        neighbours[u].append(v)
        neighbours[v].append(u)
    depth: dict[str, int] = {}
    rows: dict[int, int] = defaultdict(int)
    places = {}
    offset = 0
    for root in nodes:
        if root in depth:
            continue
        depth[root] = 0
        queue = deque([root])
        deepest = 0
        while queue:
            node = queue.popleft()
            level = depth[node]
            deepest = max(deepest, level)
            places[node] = ((offset + level) * 120.0, rows[offset + level] * 60.0)
            rows[offset + level] += 1
            for other in sorted(neighbours[node]):
                if other not in depth:
                    depth[other] = level + 1
                    queue.append(other)
        offset += deepest + 1
    return places


# -- one view of a harness in the graph -------------------------------------------------------------------


def harness_view(
    kg: KnowledgeGraph, view: str = "topology", harness: str | None = None, modules: Sequence[str] = ()
) -> View:
    """One view of a harness (of the variant of ``modules``, when given).

    Raises
    ------
    QueryError
        On an unknown view or module; when no harness is named and the graph holds several.
    NotFound
        When the graph holds no harness of that name.
    """
    if view not in VIEWS:
        raise QueryError(f"unknown harness view {view!r}; one of {', '.join(VIEWS)}")
    ref = find_harness(kg, harness)
    # Millions of rows, lists and dicts, none in a reference cycle: see paused_gc.
    with paused_gc():
        if view == "topology":
            data = topology_data(kg, ref)
            return topology_view(data, choose_modules(data, modules))
        wires = wire_data(kg, ref)
        return wire_view(wires, choose_modules(wires.topology, modules))


def harness_graph(
    kg: KnowledgeGraph, view: str = "topology", harness: str | None = None, modules: Sequence[str] = ()
) -> nx.MultiGraph:
    """The networkx graph of one view of a harness.

    Raises
    ------
    QueryError, NotFound
        As :func:`harness_view`.
    """
    return networkx_graph(harness_view(kg, view, harness, modules))


def graphml_text(view: View, *, yed: bool = False) -> str:
    """The GraphML document of ``view``."""
    out = io.StringIO()
    write_graphml(view, out, yed=yed)
    return out.getvalue()


def harness_graphml(
    kg: KnowledgeGraph,
    view: str = "topology",
    harness: str | None = None,
    modules: Sequence[str] = (),
    *,
    yed: bool = False,
) -> str:
    """One view of a harness as GraphML text.

    Raises
    ------
    QueryError, NotFound
        As :func:`harness_view`.
    """
    return graphml_text(harness_view(kg, view, harness, modules), yed=yed)


def write_harness_graphml(
    kg: KnowledgeGraph,
    path: str | Path,
    view: str = "topology",
    harness: str | None = None,
    modules: Sequence[str] = (),
    *,
    yed: bool = False,
) -> View:
    """Write one view of a harness to ``path`` as GraphML (UTF-8); returns the view written.

    Raises
    ------
    QueryError, NotFound
        As :func:`harness_view`.
    """
    written = harness_view(kg, view, harness, modules)
    path = Path(path)
    # Written beside and renamed, so a failed export leaves no half-written file.
    partial = path.with_name(path.name + ".part")
    try:
        with partial.open("w", encoding="utf-8", newline="\n") as out, paused_gc():
            write_graphml(written, out, yed=yed)
        partial.replace(path)
    finally:
        partial.unlink(missing_ok=True)
    return written
