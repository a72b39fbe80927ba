"""Records → triples, in the terms of the cadkg ontology.

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
from functools import cache, lru_cache, singledispatch
from operator import attrgetter
from pathlib import Path
from urllib.parse import quote

from cadkg.geometry.frames import quaternion_from_rpy
from cadkg.usecases.iema.component_model import Placement
from cadkg.ingest.eplan.connection_list import Connection, ConnectionListInfo
from cadkg.ingest.eplan.labels import PinRef
from cadkg.ingest.manifest import FrameSpec, Manifest
from cadkg.ingest.scene.records import TriangleMesh, stl_files
from cadkg.ingest.wri import IdEntry
from cadkg.ontology.terms import CK, RDF_TYPE

__all__ = [
    "TripleWriter",
    "component_node",
    "frame_node",
    "graph_iri",
    "item_mesh_file",
    "map_manifest",
    "map_record",
    "mapper",
    "node_iri",
    "pin_iri",
    "pin_node",
    "pose_lines",
    "sha256_of",
    "term",
    "wire_iri",
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
        # Lines held in multi-line entries of ``lines`` beyond one each (see add_block).
        self._extra = 0
        self._sink: Callable[[bytes], None] | None = None

    def stream_to(self, sink: Callable[[bytes], None]) -> None:
        """Hand the lines to ``sink`` in chunks while mapping, so a store can load one chunk
        while the next is mapped; :meth:`data` then gives only what was not handed yet."""
        self._sink = sink

    def maybe_flush(self) -> None:
        if self._sink is not None and len(self.lines) + self._extra >= self._chunk:
            self._sink(self.data())
            self._flushed += len(self.lines) + self._extra
            self.lines = []
            self._extra = 0
            self._chunk = min(2 * self._chunk, _CHUNK_LINES)

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
        return "".join(self.lines).encode("utf-8")

    def all_files(self) -> dict[str, bytes]:
        """The files that come with this graph, the meshes as binary STL."""
        return self.files | dict(zip(self.meshes, stl_files(list(self.meshes.values())), strict=True))


def map_provenance(w: TripleWriter, graph: str, rel_path: str, sha256: str, kind: str) -> None:
    g = f"<{graph}>"
    w.add(g, _TYPE, _t("SourceFile"))
    w.add(g, _t("sourcePath"), w.text(rel_path))
    w.add(g, _t("sha256"), w.text(sha256))
    w.add(g, _t("readerKind"), w.text(kind))
    w.add(g, _t("ingestedAt"), w.typed(datetime.now(UTC).replace(microsecond=0)))


def mapper(record_type: type) -> Callable[[object, TripleWriter, str], None]:
    """The mapping of one record type (what :func:`map_record` dispatches to), looked up once."""
    found = _MAPPERS.get(record_type)
    if found is None:
        found = map_record.dispatch(record_type)
        if found is not map_record.dispatch(object):  # a mapping registered later still counts
            _MAPPERS[record_type] = found
    return found


_MAPPERS: dict[type, Callable[[object, TripleWriter, str], None]] = {}


@singledispatch
def map_record(record: object, w: TripleWriter, source_slug: str) -> None:
    raise TypeError(f"no mapping for records of type {type(record).__name__}")


def component_node(w: TripleWriter, label: str) -> str:
    """The component labelled ``label``, typed and labelled once per graph."""
    return _component(w, label)


def pin_node(w: TripleWriter, ref: PinRef) -> str:
    return _pin(w, ref)


def _component(w: TripleWriter, label: str, kind: str = "Component") -> str:
    """The component ``label``; typed ``kind`` when this graph describes it first."""
    node = w.components.get(label)
    if node is not None:
        return node  # described, or found described, by its first call
    node = w.components[label] = w.iri("component", label)
    if w.once(node):
        w.add(node, _TYPE, _t(kind))
        w.add(node, _t("label"), w.text(label))
    return node


_CAD_ITEM, _CAD_ID, _HAS_ITEM, _NAMES, _INSTANCE_OF = (
    _t(n) for n in ("CadItem", "cadId", "hasItem", "names", "instanceOf")
)


@map_record.register
def _(record: IdEntry, w: TripleWriter, source_slug: str) -> None:
    item = w.iri("item", record.cad_id)
    component = _component(w, record.label)
    label = w.iri("label", record.label)
    lines = [
        f"{item} {_TYPE} {_CAD_ITEM} .\n{item} {_CAD_ID} {_literal(record.cad_id)} .\n"
        f'{item} {_SOURCE_LINE} "{record.line}"^^{_INTEGER} .\n{component} {_HAS_ITEM} {item} .\n'
        f"{label} {_NAMES} {item} .\n"
    ]
    count = 5
    if w.once(label):
        lines.append(
            f"{label} {_TYPE} {_t('Label')} .\n{label} {_t('label')} {_literal(record.label)} .\n"
            f"{label} {_NAMES} {component} .\n"
        )
        count += 3
    if record.raw_label != record.label and w.once(label + record.raw_label):
        lines.append(f"{label} {_t('rawLabel')} {_literal(record.raw_label)} .\n")
        count += 1
    if record.commercial is not None:
        model = w.iri("model", record.commercial)
        if w.once(model):
            lines.append(
                f"{model} {_TYPE} {_t('CommercialModel')} .\n"
                f"{model} {_t('commercialCode')} {_literal(record.commercial)} .\n"
            )
            count += 2
        lines.append(f"{item} {_INSTANCE_OF} {model} .\n")
        count += 1
    w.add_block("".join(lines), count)


@map_record.register
def _(record: ConnectionListInfo, w: TripleWriter, source_slug: str) -> None:
    plan = w.iri("plan", source_slug)
    w.add(plan, _TYPE, _t("ActionPlan"))
    w.add(plan, _t("label"), w.text(record.project or source_slug))
    if record.job:
        w.add(plan, _t("description"), w.text(f"job {record.job}"))


def pin_iri(base_iri: str, ref: PinRef) -> str:
    """The IRI of the pin ``ref`` names: component, pin and, on a terminal, its level."""
    if ref.level is None:
        return node_iri(base_iri, "pin", ref.component, ref.pin)
    return node_iri(base_iri, "pin", ref.component, ref.pin, ref.level)


def wire_iri(base_iri: str, number: str, taken: set[str]) -> str:
    """The IRI of the wire ``number`` not in ``taken`` (the wires of its file so far), added to it.

    A number a list repeats gets ``~2``, ``~3`` ... so that no row is lost.
    """
    iri = node_iri(base_iri, "wire", number)
    occurrence = 1
    while iri in taken:
        occurrence += 1
        iri = node_iri(base_iri, "wire", f"{number}~{occurrence}")
    taken.add(iri)
    return iri


def item_mesh_file(item_id: str) -> str:
    """Where the STL mesh of scene item ``item_id`` is kept, relative to the store's files."""
    return f"meshes/{item_id}.stl"


_PIN, _PIN_NAME, _LEVEL, _PIN_OF, _HAS_PIN = (_t(n) for n in ("Pin", "pinName", "level", "pinOf", "hasPin"))


def _pin(w: TripleWriter, ref: PinRef) -> str:
    key = (ref.component, ref.pin, ref.level)
    node = w.pins.get(key)
    if node is not None:
        return node
    node = w.pins[key] = f"<{pin_iri(w.base, ref)}>"
    if w.once(node):
        component = _component(w, ref.component)
        level = "" if ref.level is None else f"{node} {_LEVEL} {_literal(ref.level)} .\n"
        w.add_block(
            f"{node} {_TYPE} {_PIN} .\n{node} {_PIN_NAME} {_literal(ref.pin)} .\n{level}"
            f"{node} {_PIN_OF} {component} .\n{component} {_HAS_PIN} {node} .\n",
            4 if ref.level is None else 5,
        )
    return node


# Connection fields written as plain literals, with the ontology term of each.
_WIRE_TEXT = (
    ("colour", "colour"),
    ("potential_type", "potentialType"),
    ("potential_name", "potentialName"),
    ("origin_termination", "originTermination"),
    ("destination_termination", "destinationTermination"),
    ("origin_page", "originPage"),
    ("origin_zone", "originZone"),
    ("destination_page", "destinationPage"),
    ("destination_zone", "destinationZone"),
    ("cable_name", "cableName"),
    ("job_key", "jobKey"),
    ("origin_direction", "originDirection"),
    ("destination_direction", "destinationDirection"),
    ("bundling_side", "bundlingSide"),
)
_WIRE_VALUES = attrgetter(*(field_name for field_name, _ in _WIRE_TEXT))
_WIRE_PREDICATES = tuple(_t(name) for _, name in _WIRE_TEXT)


_WIRE, _WIRE_NUMBER, _FROM_PIN, _TO_PIN, _IN_PLAN, _SEQUENCE_INDEX = (
    _t(n) for n in ("Wire", "wireNumber", "fromPin", "toPin", "inPlan", "sequenceIndex")
)
_SECTION, _LENGTH, _DUCT_PATH, _PASSES_THROUGH = (
    _t(n) for n in ("crossSectionMm2", "lengthM", "ductPath", "passesThrough")
)


@map_record.register
def _(record: Connection, w: TripleWriter, source_slug: str) -> None:
    wire = f"<{wire_iri(w.base, record.wire_number, w.wires)}>"
    plan = w.plans.get(source_slug)
    if plan is None:
        plan = w.plans[source_slug] = w.iri("plan", source_slug)
    origin, destination = _pin(w, record.origin), _pin(w, record.destination)
    parts = [
        f"{wire} {_TYPE} {_WIRE} .\n{wire} {_WIRE_NUMBER} {_literal(record.wire_number)} .\n"
        f"{wire} {_FROM_PIN} {origin} .\n{wire} {_TO_PIN} {destination} .\n{wire} {_IN_PLAN} {plan} .\n"
        f'{wire} {_SEQUENCE_INDEX} "{record.index}"^^{_INTEGER} .\n'
        f'{wire} {_SOURCE_LINE} "{record.line}"^^{_INTEGER} .\n'
    ]
    if record.section_mm2 is not None:
        parts.append(f"{wire} {_SECTION} {w.typed(record.section_mm2)} .\n")
    if record.length_m is not None:
        parts.append(f"{wire} {_LENGTH} {w.typed(record.length_m)} .\n")
    parts.extend(
        [
            f"{wire} {predicate} {_literal(value)} .\n"
            for predicate, value in zip(_WIRE_PREDICATES, _WIRE_VALUES(record), strict=True)
            if value is not None
        ]
    )
    if record.duct_path:
        parts.append(f"{wire} {_DUCT_PATH} {_literal(';'.join(record.duct_path))} .\n")
        for duct_label in dict.fromkeys(record.duct_path):
            parts.append(f"{wire} {_PASSES_THROUGH} {_component(w, duct_label, 'Duct')} .\n")
    w.add_block("".join(parts), 6 + len(parts))  # seven lines in the first part, one in each other


def map_manifest(w: TripleWriter, manifest: Manifest) -> None:
    """The cell itself and its static frames, stated by the manifest."""
    cell = w.iri("cell", "this")
    w.add(cell, _TYPE, _t("Cell"))
    w.add(cell, _t("label"), w.text(manifest.cell.name))
    w.add(cell, _t("profile"), w.text(manifest.cell.profile))
    if manifest.cell.description:
        w.add(cell, _t("description"), w.text(manifest.cell.description))
    w.add(cell, _t("approachDistance"), w.typed(manifest.derive.approach_distance))
    w.add(cell, _t("railPattern"), w.text(manifest.derive.rail_pattern))
    w.add(cell, _t("clusterTolerance"), w.typed(manifest.derive.cluster_tolerance))
    for frame in manifest.frames:
        _map_frame(w, frame)


def _frame(w: TripleWriter, name: str) -> str:
    node = w.iri("frame", name)
    if w.once(node):
        w.add(node, _TYPE, _t("Frame"))
        w.add(node, _t("label"), w.text(name))
    return node


def frame_node(w: TripleWriter, name: str) -> str:
    """The frame called ``name`` (a ROS frame id), described once per graph."""
    return _frame(w, name)


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


def placement_pose(w: TripleWriter, node: str, placement: Placement, parent: str) -> str:
    """A pose read from a file (roll, pitch, yaw) in frame ``parent``, with its line."""
    pose = write_pose(w, node, placement.xyz, quaternion_from_rpy(*placement.rpy), parent)
    w.add(pose, _t("sourceLine"), w.typed(placement.line))
    return pose


def model_node(w: TripleWriter, key: str) -> str:
    """The commercial model ``key`` (a component model, a WRI commercial code, a model number)."""
    node = w.iri("model", key)
    if w.once(node):
        w.add(node, _TYPE, _t("CommercialModel"))
        w.add(node, _t("commercialCode"), w.text(key))
    return node


def model_frame(w: TripleWriter, model: str, key: str) -> str:
    """The frame of the commercial model ``key`` (node ``model``), in which its poses are given."""
    frame = w.iri("model", key, "frame")
    w.add(frame, _TYPE, _t("Frame"))
    w.add(frame, _t("label"), w.text(f"model {key}"))
    w.add(model, _t("hasFrame"), frame)
    return frame


def dimensions(w: TripleWriter, node: str, sizes: Sequence[float | Decimal]) -> None:
    """Size along x, y, z in metres."""
    for name, value in zip(("xDim", "yDim", "zDim"), sizes, strict=True):
        w.add(node, _t(name), w.typed(float(value)))


def mesh_node(w: TripleWriter, owner: str, mesh: str, rel: str) -> None:
    """``owner`` has the mesh node ``mesh`` whose STL file is ``rel`` in the store's files."""
    w.add(owner, _t("hasMesh"), mesh)
    w.add(mesh, _TYPE, _t("Mesh"))
    w.add(mesh, _t("meshUri"), f'"{rel}"^^<{_XSD}anyURI>')


def connector_node(w: TripleWriter, label: str) -> str:
    """The component ``label``, typed a connector."""
    node = component_node(w, label)
    if w.once(node + "#connector"):
        w.add(node, _TYPE, _t("Connector"))
    return node


def cable_node(w: TripleWriter, name: str) -> str:
    """The cable ``name``, one node whichever file mentions it."""
    node = w.iri("cable", name)
    if w.once(node):
        w.add(node, _TYPE, _t("Cable"))
        w.add(node, _t("label"), w.text(name))
    return node


def _map_frame(w: TripleWriter, frame: FrameSpec) -> None:
    child = _frame(w, frame.child)
    pose = w.iri("pose", frame.child)
    w.add(child, _t("hasPose"), pose)
    write_pose(w, pose, frame.xyz, frame.quaternion, _frame(w, frame.parent))
    w.add(pose, _t("sourceLine"), w.typed(frame.line))
