"""N-Triples writing for one named graph: IRIs, literals, poses, chunks for the store.

Triples are written as N-Triples lines rather than term objects: building Python
term objects costs several microseconds per triple, while the store parses
N-Triples natively, and the build benchmark is dominated by that difference.
Every IRI is built from percent-encoded parts, and every literal is escaped, so a
value read from a file can never break out of its term.
"""

from __future__ import annotations

import hashlib
import re
from collections.abc import Callable, Sequence
from datetime import UTC, datetime
from decimal import Decimal
from functools import cache, lru_cache
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import quote

from cadkg.ontology.terms import CK, RDF_TYPE

if TYPE_CHECKING:
    from cadkg.ingest.scene.records import TriangleMesh

__all__ = [
    "INTEGER",
    "TYPE",
    "XSD",
    "TripleWriter",
    "graph_iri",
    "literal",
    "map_provenance",
    "node_iri",
    "pose_lines",
    "sha256_of",
    "term",
    "write_pose",
]

_ESCAPES = str.maketrans({"\\": "\\\\", '"': '\\"', "\n": "\\n", "\r": "\\r"})
_XSD = "http://www.w3.org/2001/XMLSchema#"
_CHUNK_LINES = 250_000
# A file's first chunks are small and grow, so the loader, idle until the first, starts
# at once and then always has the next.
_FIRST_CHUNK_LINES = 16_000


def sha256_of(path: str | Path) -> str:
    digest = hashlib.sha256()
    with Path(path).open("rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def graph_iri(base_iri: str, rel_path: str) -> str:
    """The named graph of one input file: ``{base}graph/{path relative to the manifest}``."""
    return f"{base_iri}graph/{quote(rel_path, safe='/')}"


@cache
def _t(name: str) -> str:
    return f"<{CK[name].value}>"


_TYPE = f"<{RDF_TYPE.value}>"
_SOURCE_LINE = _t("sourceLine")
_INTEGER = f"<{_XSD}integer>"
_DOUBLE = f"<{_XSD}double>"


def term(name: str) -> str:
    """An ontology term as N-Triples (``"type"`` is rdf:type); misspelt names raise."""
    return _TYPE if name == "type" else _t(name)


_UNRESERVED = re.compile(r"[A-Za-z0-9_.~-]+")


@lru_cache(maxsize=1 << 17)
def _quoted(part: str) -> str:
    # Labels and pin names repeat across wires; quoting each once pays at 100k wires.
    return quote(part, safe="")


def _segment(part: str) -> str:
    # Most parts (wire numbers, pin names, labels) need no quoting at all.
    return part if _UNRESERVED.fullmatch(part) else _quoted(part)


@lru_cache(maxsize=1 << 16)
def _literal(value: str) -> str:
    # Colours, terminations, pages and zones repeat across thousands of wires.
    return '"' + value.translate(_ESCAPES) + '"'


@lru_cache(maxsize=1 << 14)
def _decimal(value: Decimal) -> str:
    # Sections and lengths repeat down a connection list.
    return f'"{format(value.normalize(), "f")}"^^<{_XSD}decimal>'


@lru_cache(maxsize=1 << 12)
def node_iri(base_iri: str, kind: str, *parts: str) -> str:
    """The IRI cadkg mints for a thing: ``{base}{kind}/{part}/...``, each part percent-encoded."""
    # Cached for the derivation's inputs, which a build collects right after mapping a record.
    return base_iri + kind + "/" + "/".join([_segment(p) for p in parts])


class TripleWriter:
    """Collects N-Triples lines for one named graph; IRIs are minted under ``base_iri``."""

    def __init__(self, base_iri: str) -> None:
        self.base = base_iri
        self.lines: list[str] = []
        self.files: dict[str, bytes] = {}
        # Meshes to write as STL files beside the graph, exported together (see stl_files).
        self.meshes: dict[str, TriangleMesh] = {}
        self.root_frame = "cabinet"
        self._seen: set[str] = set()
        # Nodes every row of a big file points at, minted once per writer.
        self.pins: dict[tuple[str, str, str | None], str] = {}
        self.plans: dict[str, str] = {}
        self.wires: set[str] = set()
        self.components: dict[str, str] = {}
        self._flushed = 0
        self._chunk = _FIRST_CHUNK_LINES
        self._most = _CHUNK_LINES
        # Lines held in multi-line entries of ``lines`` beyond one each (see add_block).
        self._extra = 0
        self._sink: Callable[[bytes], None] | None = None
        # Without a sink, the chunks mapped so far: a line as bytes costs a third of a line
        # as a string in a list, and the graph of a big file is held whole until it is loaded.
        self._held: list[bytes] = []

    def stream_to(self, sink: Callable[[bytes], None], most: int = _CHUNK_LINES) -> None:
        """Hand the lines to ``sink`` in chunks of at most ``most`` lines while mapping, so a
        store can load one chunk while the next is mapped; :meth:`data` then gives only what
        was not handed yet."""
        self._sink = sink
        self._most = most
        self._chunk = min(self._chunk, most)

    def maybe_flush(self) -> None:
        if len(self.lines) + self._extra >= self._chunk:
            chunk = "".join(self.lines).encode("utf-8")
            if self._sink is not None:
                self._sink(chunk)
            else:
                self._held.append(chunk)
            self._flushed += len(self.lines) + self._extra
            self.lines = []
            self._extra = 0
            self._chunk = min(2 * self._chunk, self._most)

    @property
    def triples(self) -> int:
        """Triples written so far, streamed or not."""
        return self._flushed + len(self.lines) + self._extra

    def iri(self, kind: str, *parts: str) -> str:
        return "<" + node_iri(self.base, kind, *parts) + ">"

    @staticmethod
    def under(node: str, *parts: str) -> str:
        """The IRI ``node``/part/...: ``under(iri(kind, a), b)`` is ``iri(kind, a, b)``.

        Things minted below one node (a component's pins, a route's waypoints) pay for
        quoting the node's parts once instead of once each.
        """
        return node[:-1] + "/" + "/".join([_segment(p) for p in parts]) + ">"

    def add(self, s: str, p: str, o: str) -> None:
        self.lines.append(f"{s} {p} {o} .\n")

    def add_block(self, text: str, count: int) -> None:
        """``count`` whole N-Triples lines in one string.

        The rows of a big file write one block each: a single formatted string per row
        costs a fraction of one call and one string per triple.
        """
        self.lines.append(text)
        self._extra += count - 1

    def once(self, key: str) -> bool:
        """True the first time ``key`` is seen, so shared nodes are described once per graph."""
        if key in self._seen:
            return False
        self._seen.add(key)
        return True

    @staticmethod
    def text(value: str) -> str:
        return _literal(value)

    @staticmethod
    def typed(value: int | float | Decimal | bool | datetime) -> str:
        if type(value) is Decimal:
            return _decimal(value)
        if isinstance(value, bool):
            return f'"{str(value).lower()}"^^<{_XSD}boolean>'
        if isinstance(value, int):
            return f'"{value}"^^<{_XSD}integer>'
        if isinstance(value, Decimal):
            return f'"{format(value.normalize(), "f")}"^^<{_XSD}decimal>'
        if isinstance(value, float):
            return f'"{value!r}"^^<{_XSD}double>'
        return f'"{value.isoformat()}"^^<{_XSD}dateTime>'

    def data(self) -> bytes:
        """The N-Triples not handed to a sink yet."""
        rest = "".join(self.lines).encode("utf-8")
        return b"".join([*self._held, rest]) if self._held else rest

    def all_files(self) -> dict[str, bytes]:
        """The files that come with this graph, the meshes as binary STL."""
        if not self.meshes:  # most graphs: no need to import numpy and the mesh code
            return dict(self.files)
        from cadkg.ingest.scene.records import stl_files

        return self.files | dict(zip(self.meshes, stl_files(list(self.meshes.values())), strict=True))


def map_provenance(w: TripleWriter, graph: str, rel_path: str, sha256: str, kind: str) -> None:
    g = f"<{graph}>"
    w.add(g, _TYPE, _t("SourceFile"))
    w.add(g, _t("sourcePath"), w.text(rel_path))
    w.add(g, _t("sha256"), w.text(sha256))
    w.add(g, _t("readerKind"), w.text(kind))
    w.add(g, _t("ingestedAt"), w.typed(datetime.now(UTC).replace(microsecond=0)))


_POSE_TERMS = tuple(_t(name) for name in ("tx", "ty", "tz", "qx", "qy", "qz", "qw"))
_POSE = _t("Pose")
_PARENT_FRAME = _t("parentFrame")
# Derived graphs hold millions of poses: their nine lines are one format call, {0} the
# node, {1} the parent frame, {2}..{8} the numbers.
_POSE_LINES = (
    f"{{0}} {_TYPE} {_POSE} .\n{{0}} {_PARENT_FRAME} {{1}} .\n"
    + "".join(f'{{0}} {p} "{{{i}!r}}"^^{_DOUBLE} .\n' for i, p in enumerate(_POSE_TERMS, start=2))
).format


def write_pose(
    w: TripleWriter, node: str, xyz: Sequence[float], quaternion: Sequence[float], parent: str
) -> str:
    """A ck:Pose ``node`` in frame ``parent``: translation in metres, quaternion (x, y, z, w)."""
    if len(xyz) != 3 or len(quaternion) != 4:
        raise ValueError(
            f"a pose needs 3 coordinates and 4 quaternion terms, not {len(xyz)} and {len(quaternion)}"
        )
    w.add_block(pose_lines(node, xyz, quaternion, parent), 9)
    return node


def pose_lines(node: str, xyz: Sequence[float], quaternion: Sequence[float], parent: str) -> str:
    """The nine N-Triples lines of the ck:Pose ``node`` (see :func:`write_pose`)."""
    x, y, z = xyz
    qx, qy, qz, qw = quaternion
    # float() also turns numpy scalars, whose repr is not a number, into floats.
    return _POSE_LINES(node, parent, float(x), float(y), float(z), float(qx), float(qy), float(qz), float(qw))


# The names other mapping modules write their hot rows with.
TYPE = _TYPE
INTEGER = _INTEGER
XSD = _XSD
literal = _literal
