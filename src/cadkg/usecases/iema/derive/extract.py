"""What the derivation needs, read out of the source graphs one predicate at a time
(:class:`cadkg.query.tables.SourceTables`). The derived graph is not read, so deriving twice
gives the same answer.
"""

from __future__ import annotations

from collections import defaultdict
from dataclasses import dataclass, field
from itertools import product
from typing import TYPE_CHECKING, Any

from cadkg.geometry.poses import Pose, Vec3
from cadkg.ingest.eplan.labels import duct_labels
from cadkg.query.placements import frames_of, meshes_of
from cadkg.query.tables import SourceTables, source_tables
from cadkg.usecases.iema.robot_scope import DEFAULT_ZONES

if TYPE_CHECKING:
    from cadkg.graph import KnowledgeGraph

__all__ = [
    "CellInputs",
    "ModelInfo",
    "PinInfo",
    "WireInfo",
    "extract",
]

_ZONES = "SELECT DISTINCT ?z WHERE { ?c a ck:Cell ; ck:robotZone ?z }"


@dataclass
class ModelInfo:
    key: str
    role: str | None = None
    dimensions: Vec3 | None = None
    screws: dict[str, Pose] = field(default_factory=dict)
    holes: dict[str, Pose] = field(default_factory=dict)
    children: dict[str, Pose] = field(default_factory=dict)
    items: dict[str, Pose] = field(default_factory=dict)
    mounting: Pose | None = None
    # Connection points of EPLAN's parts management: the hole of a pin no couple places.
    points: dict[str, Pose] = field(default_factory=dict)

    @property
    def couples(self) -> list[str]:
        return list(dict.fromkeys([*self.screws, *self.holes, *self.points]))

    def frames(self, couple: str) -> tuple[Pose | None, Pose | None]:
        """The screw and hole of ``couple``: a component model's couple, else a connection point."""
        screw, hole = self.screws.get(couple), self.holes.get(couple)
        if screw is None and hole is None:
            hole = self.points.get(couple)
        return screw, hole


# Not frozen: a build makes one per pin and one per wire, and a frozen dataclass pays a
# guarded setattr per field (1.6 µs a pin, 2.5 µs a wire); nothing changes them after.
@dataclass(slots=True)
class PinInfo:
    iri: str
    label: str
    name: str
    level: str | None
    item: str | None


@dataclass(slots=True)
class WireInfo:
    iri: str
    number: str
    position: int
    source: str
    origin: str
    destination: str
    ducts: tuple[str, ...]
    section_mm2: float | None
    colour: str | None
    length_m: float | None
    terminations: tuple[str | None, str | None] = (None, None)
    # The duct path as the list writes it, and the zones of the wire's origin and destination
    # (the list's two 'Zona' columns).
    path: str = ""
    zone: str | None = None
    destination_zone: str | None = None


@dataclass
class CellInputs:
    base: str
    approach_distance: float
    rail_pattern: str
    cluster_tolerance: float
    items_of: dict[str, list[str]]
    item_model: dict[str, str]
    frames: dict[str, tuple[str, Pose]]
    bboxes: dict[str, tuple[Vec3, Vec3]]
    meshes: dict[str, str]
    models: dict[str, ModelInfo]
    blocks: dict[str, list[tuple[int, str, str | None]]]
    # (position, row kind, terminal) of each strip a terminal diagram describes
    diagrams: dict[str, list[tuple[int, str, str | None]]]
    pins: dict[str, PinInfo]
    wires: list[WireInfo]
    assignments: list[tuple[str, str, str]]
    duct_labels: set[str]
    robot_zones: tuple[str, ...] = DEFAULT_ZONES


def _settings(kg: KnowledgeGraph) -> dict[str, Any]:
    cell = kg.query(
        """SELECT ?cell ?d ?p ?t ?profile WHERE { ?cell a ck:Cell .
             OPTIONAL { ?cell ck:approachDistance ?d } OPTIONAL { ?cell ck:railPattern ?p }
             OPTIONAL { ?cell ck:clusterTolerance ?t } OPTIONAL { ?cell ck:profile ?profile } } LIMIT 1"""
    ).rows
    return {**cell[0], "base": cell[0]["cell"].removesuffix("cell/this")} if cell else {}


def extract(kg: KnowledgeGraph) -> CellInputs:
    """Read the source graphs of a store into :class:`CellInputs`."""
    settings = _settings(kg)
    base = settings.get("base", "")
    # Pins and wires are the cabinet's wiring; a harness cell's cables end at connector
    # cavities, which the cabinet geometry must not take for component pins.
    wiring = (settings.get("profile") or "iema") == "iema"
    tables = source_tables(kg, base)
    return CellInputs(
        base=base,
        approach_distance=float(settings.get("d") or 0.15),
        rail_pattern=str(settings.get("p") or "^RAIL"),
        cluster_tolerance=float(settings.get("t") or 0.005),
        items_of=_items(tables),
        item_model={
            ident: key
            for item, ids in tables.values("cadId").items()
            for ident in ids
            for key in tables.follow(item, "instanceOf", "commercialCode")
        },
        frames=frames_of(tables),
        bboxes=_bboxes(tables),
        meshes=meshes_of(tables),
        models=_models(tables),
        blocks=_blocks(tables),
        diagrams=_diagrams(tables),
        pins=_pins(tables, base) if wiring else {},
        wires=_wires(tables) if wiring else [],
        assignments=[
            (row["g"], row["target"], row["who"].rsplit("#", 1)[-1])
            for row in kg.query(
                """SELECT ?g ?target ?who ?line WHERE { GRAPH ?g { ?a ck:assignmentOf ?target ;
                     ck:assignedTo ?who . OPTIONAL { ?a ck:sourceLine ?line } } } ORDER BY ?g ?line"""
            )
        ],
        duct_labels={
            row["label"]
            for row in kg.query("SELECT DISTINCT ?label WHERE { ?d a ck:Duct ; ck:label ?label }")
        },
        robot_zones=tuple(sorted(row["z"] for row in kg.query(_ZONES))) or DEFAULT_ZONES,
    )


def _items(tables: SourceTables) -> dict[str, list[str]]:
    items_of: dict[str, list[str]] = defaultdict(list)
    item_lines: dict[str, int] = {}
    labels, ids_of, lines = (tables.values(name) for name in ("label", "cadId", "sourceLine"))
    for component, items in tables.values("hasItem").items():
        for label, item in product(labels.get(component, ()), items):
            for ident in ids_of.get(item, ()):
                if ident not in items_of[label]:
                    items_of[label].append(ident)
                for line in lines.get(item, ()):
                    item_lines[ident] = min(item_lines.get(ident, line), line)
    for ids in items_of.values():
        ids.sort(key=lambda i: (item_lines.get(i, 1 << 30), i))
    return dict(items_of)


def _bboxes(tables: SourceTables) -> dict[str, tuple[Vec3, Vec3]]:
    columns = [tables.values(name) for name in ("minX", "minY", "minZ", "maxX", "maxY", "maxZ")]
    boxes: dict[str, tuple[Vec3, Vec3]] = {}
    for item, ids in tables.values("cadId").items():
        box: list[Any] = [column.get(item, (None,))[0] for column in columns]
        if None not in box:
            a, b, c, d, e, f = (float(value) for value in box)
            for ident in ids:
                boxes[ident] = ((a, b, c), (d, e, f))
    return boxes


def _models(tables: SourceTables) -> dict[str, ModelInfo]:
    models: dict[str, ModelInfo] = {}
    poses, codes = tables.poses(), tables.values("commercialCode")
    dims = [tables.values(name) for name in ("xDim", "yDim", "zDim")]
    for node, keys in codes.items():
        size: list[Any] = [column.get(node, (None,))[0] for column in dims]
        for key in keys:
            model = models.setdefault(key, ModelInfo(key))
            model.role = model.role or tables.first(node, "modelRole")
            if None not in size:
                model.dimensions = (float(size[0]), float(size[1]), float(size[2]))
    names = tables.values("pinName")
    for node, pins in tables.values("definesPin").items():
        for key, pin in product(codes.get(node, ()), pins):
            model = models.setdefault(key, ModelInfo(key))
            for name, (kind, into) in product(
                names.get(pin, ()), (("screwPose", model.screws), ("holePose", model.holes))
            ):
                for pose in tables.values(kind).get(pin, ()):
                    if pose in poses:
                        into[name] = poses[pose]
    for node, points in tables.values("definesConnectionPoint").items():
        for key, point in product(codes.get(node, ()), points):
            model = models.setdefault(key, ModelInfo(key))
            for name, pose in product(names.get(point, ()), tables.values("holePose").get(point, ())):
                if pose in poses:
                    model.points[name] = poses[pose]
    labels = tables.values("label")
    for node, frames in tables.values("hasItemFrame").items():
        for key, frame in product(codes.get(node, ()), frames):
            for name, pose in product(labels.get(frame, ()), tables.values("hasPose").get(frame, ())):
                if pose in poses:
                    models.setdefault(key, ModelInfo(key)).items[name] = poses[pose]
    for node, mountings in tables.values("mountingPose").items():
        for key, pose in product(codes.get(node, ()), mountings):
            if pose in poses:
                models.setdefault(key, ModelInfo(key)).mounting = poses[pose]
    for node, placements in tables.values("hasChildPlacement").items():
        for key, placement in product(codes.get(node, ()), placements):
            children = tables.follow(placement, "childModel", "commercialCode")
            for child, pose in product(children, tables.values("hasPose").get(placement, ())):
                if pose in poses:
                    models.setdefault(key, ModelInfo(key)).children[child] = poses[pose]
    return models


def _blocks(tables: SourceTables) -> dict[str, list[tuple[int, str, str | None]]]:
    rows: set[tuple[str, int, str, str | None]] = set()
    labels, ids_of, positions = tables.values("label"), tables.values("cadId"), tables.values("blockPosition")
    for block in tables.instances("TerminalBlock"):
        for label, item in product(labels.get(block, ()), tables.values("hasTerminalItem").get(block, ())):
            for ident, position in product(ids_of.get(item, ()), positions.get(item, ())):
                for term in tables.values("terminalName").get(item) or [None]:
                    rows.add((label, int(position), ident, term))
    blocks: dict[str, list[tuple[int, str, str | None]]] = defaultdict(list)
    for label, position, ident, term in sorted(rows, key=lambda r: (r[0], r[1], r[2], r[3] or "")):
        blocks[label].append((position, ident, term))
    return dict(blocks)


def _diagrams(tables: SourceTables) -> dict[str, list[tuple[int, str, str | None]]]:
    # One file per strip: when several describe it, the one whose path sorts first.
    paths, labels = tables.values("sourcePath"), tables.values("label")
    found: dict[str, dict[str, list[tuple[int, str, str | None]]]] = {}
    for graph, block, row in tables.triples("hasDiagramRow"):
        position, kind = tables.first(row, "diagramPosition"), tables.first(row, "rowKind")
        if position is None or kind is None or kind == "summary":
            continue
        for label, path in product(labels.get(block, ()), paths.get(graph, ())):
            rows = found.setdefault(label, {}).setdefault(path, [])
            rows.append((int(position), kind, tables.first(row, "diagramTerminal")))
    return {label: sorted(by_path[min(by_path)]) for label, by_path in found.items()}


def _pins(tables: SourceTables, base: str) -> dict[str, PinInfo]:
    # Pins the derivation itself added (a model's pins no wire names) are its output, not input.
    derived = base + "derived/"
    names = tables.values("pinName")
    pins: dict[str, PinInfo] = {}
    for pin in tables.instances("Pin"):
        if pin.startswith(derived):
            continue
        levels = tables.values("level").get(pin) or [None]
        items = tables.follow(pin, "onItem", "cadId") or [None]
        for label, name in product(tables.follow(pin, "pinOf", "label"), names.get(pin, ())):
            for level, item in product(levels, items):
                pins[pin] = PinInfo(pin, label, name, level, item)
    return pins


def _wires(tables: SourceTables) -> list[WireInfo]:
    def in_graph(predicate: str) -> dict[tuple[str, Any], list[Any]]:
        table: dict[tuple[str, Any], list[Any]] = defaultdict(list)
        for graph, subject, value in tables.triples(predicate):
            table[graph, subject].append(value)
        return table

    required = [in_graph(name) for name in ("wireNumber", "sequenceIndex", "fromPin", "toPin")]
    optional = [
        in_graph(name)
        for name in (
            "ductPath",
            "crossSectionMm2",
            "colour",
            "lengthM",
            "originTermination",
            "destinationTermination",
            "originZone",
            "destinationZone",
        )
    ]
    paths = tables.values("sourcePath")
    wires = []
    for graph, wire, _ in tables.triples("", "Wire"):
        key = (graph, wire)
        columns = [table.get(key, []) for table in required]
        columns += [table.get(key) or [None] for table in optional]
        for number, idx, origin, destination, ducts, section, colour, length, t1, t2, zone, far in product(
            *columns
        ):
            for path in paths.get(graph, ()):
                wires.append(
                    WireInfo(
                        iri=wire,
                        number=number,
                        # The list's rows count from 0 in the services, as in the cell's software.
                        position=int(idx) - 1,
                        source=path,
                        origin=origin,
                        destination=destination,
                        ducts=duct_labels(ducts) if ducts else (),
                        section_mm2=float(section) if section is not None else None,
                        colour=colour,
                        length_m=float(length) if length is not None else None,
                        terminations=(t1, t2),
                        path=ducts or "",
                        zone=zone,
                        destination_zone=far,
                    )
                )
    wires.sort(key=lambda w: (w.source, w.position))
    return wires
