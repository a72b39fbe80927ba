"""The derivation's inputs gathered from the records of a build, beside their triples.

A build has every record in hand before the store has indexed it, so the cabinet
geometry can be derived while the store is still loading instead of being read back
out of it afterwards (which at 100k wires cost as much as the load). Each record
type here adds to :class:`CellInputs` exactly what its mapping writes and
:func:`cadkg.usecases.iema.derive.extract.extract` reads back; tests build both ways on every
example cell and compare. A record type not listed makes the collector give up
(:attr:`InputCollector.complete`), and the build then reads the graph as before.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import Any

from cadkg.geometry.poses import Pose
from cadkg.ingest.assignments import Assignment
from cadkg.ingest.eplan.bill_of_materials import BomInfo, BomLine
from cadkg.ingest.eplan.connection_list import Connection, ConnectionListInfo
from cadkg.ingest.eplan.labels import PinRef
from cadkg.ingest.eplan.parts import PartPins
from cadkg.ingest.manifest import Manifest
from cadkg.ingest.placement import Placement
from cadkg.ingest.scene.records import SceneItem
from cadkg.ingest.wri import IdEntry
from cadkg.mapping.nodes import item_mesh_file, pin_iri, wire_iri
from cadkg.mapping.writer import graph_iri, node_iri
from cadkg.usecases.iema.component_list import ComponentListEntry
from cadkg.usecases.iema.component_model import ComponentModel
from cadkg.usecases.iema.derive.extract import CellInputs, ModelInfo, PinInfo, WireInfo
from cadkg.usecases.iema.derive.settings import DeriveSpec
from cadkg.usecases.iema.marker_table import QrMarker
from cadkg.usecases.iema.terminal_diagram import DiagramRow
from cadkg.usecases.iema.terminal_schema import TerminalSlot

__all__ = ["InputCollector"]

_NO_LINE = 1 << 30


def _pose(xyz: Iterable[float], quaternion: Iterable[float]) -> Pose:
    x, y, z = (float(v) for v in xyz)
    qx, qy, qz, qw = (float(v) for v in quaternion)
    return Pose((x, y, z), (qx, qy, qz, qw))


def _placement(placement: Placement) -> Pose:
    return _pose(placement.xyz, placement.quaternion())


class _Source:
    """What one file's mapping de-duplicates within its own graph."""

    def __init__(self, rel: str, frame: str | None) -> None:
        self.rel = rel
        self.root_frame = frame or "cabinet"
        self.wires: set[str] = set()
        self.described: set[str] = set()


class InputCollector:
    """Feed it the manifest's sources in order (:meth:`source`), then take :meth:`inputs`."""

    def __init__(self, manifest: Manifest) -> None:
        cell = manifest.cell
        self.base = cell.base_iri
        # Only a cabinet cell's derivation reads pins and wires (see extract).
        self.complete = cell.profile == "iema"
        self._items: dict[str, dict[str, None]] = {}
        self._item_lines: dict[str, int] = {}
        self._item_model: dict[str, str] = {}
        self._frames = {f.child: (f.parent, _pose(f.xyz, f.quaternion)) for f in manifest.frames}
        self._bboxes: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {}
        self._meshes: dict[str, str] = {}
        self._models: dict[str, ModelInfo] = {}
        self._blocks: dict[str, dict[tuple[int, str, str | None], None]] = {}
        self._diagrams: dict[str, dict[str, list[tuple[int, str, str | None]]]] = {}
        self._pins: dict[str, PinInfo] = {}
        self._pin_iris: dict[tuple[str, str, str | None], str] = {}
        self._wires: list[WireInfo] = []
        self._assignments: list[tuple[str, int | None, str, str]] = []
        self._ducts: set[str] = set()
        # A manifest made in code, not read, has no settings: the defaults then.
        self._settings: DeriveSpec = manifest.derive or DeriveSpec()
        self._root_frames = {source.rel: source.frame for source in manifest.sources}

    def source(self, rel: str) -> Callable[[object], None]:
        """The function that takes the records of source ``rel`` one by one, in file order."""
        source = _Source(rel, self._root_frames.get(rel))
        handlers = _HANDLERS

        def take(record: object) -> None:
            if not self.complete:
                return
            handler = handlers.get(type(record))
            if handler is None:
                self.complete = False
            else:
                handler(self, record, source)

        return take

    def wants(self, record: object) -> bool:
        """Whether :meth:`source`'s function needs ``record``: records of a type it gathers,
        and of a type it does not know (which makes it give up), while it is complete."""
        return self.complete and _HANDLERS.get(type(record)) is not InputCollector._nothing

    def add_edits(self, edits: Iterable[tuple[str, str]]) -> None:
        """Assignments (target IRI, performer) kept in the store's edits graph."""
        graph = self.base + "assignments"
        self._assignments.extend((graph, None, target, who) for target, who in edits)

    def inputs(self) -> CellInputs:
        items_of = {
            label: sorted(ids, key=lambda i: (self._item_lines.get(i, _NO_LINE), i))
            for label, ids in self._items.items()
        }
        settings = self._settings
        return CellInputs(
            base=self.base,
            approach_distance=float(settings.approach_distance),
            rail_pattern=settings.rail_pattern,
            cluster_tolerance=float(settings.cluster_tolerance),
            items_of=items_of,
            item_model=dict(self._item_model),
            frames=dict(self._frames),
            bboxes=dict(self._bboxes),
            meshes=dict(self._meshes),
            models=self._models,
            blocks={label: sorted(rows, key=lambda r: (r[0], r[1])) for label, rows in self._blocks.items()},
            diagrams={label: sorted(by_path[min(by_path)]) for label, by_path in self._diagrams.items()},
            pins=self._pins,
            wires=sorted(self._wires, key=lambda w: (w.source, w.position)),
            # As the graph is read: by graph IRI, then by line (none first).
            assignments=[
                (g, target, who)
                for g, _, target, who in sorted(
                    self._assignments, key=lambda a: (a[0], -1 if a[1] is None else a[1])
                )
            ],
            duct_labels=set(self._ducts),
            robot_zones=tuple(sorted(settings.robot_zones)),
        )

    # -- one method per record type, mirroring its mapping ----------------------------
    def _id_entry(self, record: IdEntry, source: _Source) -> None:
        self._item(record.label, record.cad_id)
        line = self._item_lines.get(record.cad_id)
        self._item_lines[record.cad_id] = record.line if line is None else min(line, record.line)
        if record.commercial is not None:
            self._model(record.commercial)
            self._item_model[record.cad_id] = record.commercial

    def _nothing(self, record: object, source: _Source) -> None:
        """Records whose triples the derivation does not read (project data, BOM lines, markers)."""

    def _connection(self, record: Connection, source: _Source) -> None:
        wire = wire_iri(self.base, record.wire_number, source.wires)
        section, length = record.section_mm2, record.length_m
        self._wires.append(
            WireInfo(
                iri=wire,
                number=record.wire_number,
                position=record.index - 1,
                source=source.rel,
                origin=self._pin(record.origin),
                destination=self._pin(record.destination),
                ducts=record.duct_path,
                section_mm2=float(section) if section is not None else None,
                colour=record.colour,
                length_m=float(length) if length is not None else None,
                terminations=(record.origin_termination, record.destination_termination),
                path=record.duct_text or ";".join(record.duct_path),
                zone=record.origin_zone,
                destination_zone=record.destination_zone,
            )
        )
        self._ducts.update(record.duct_path)

    def _component_model(self, record: ComponentModel, source: _Source) -> None:
        self._describe(record, source)

    def _component_list_entry(self, record: ComponentListEntry, source: _Source) -> None:
        if record.part_number:
            self._model(record.part_number)
        for model in record.models:
            self._describe(model, source)

    def _part_pins(self, record: PartPins, source: _Source) -> None:
        model = self._model(record.part)
        for point in record.points:
            model.points[point.name] = _pose(point.position, point.orientation)

    def _diagram_row(self, record: DiagramRow, source: _Source) -> None:
        if record.kind != "summary":
            rows = self._diagrams.setdefault(record.strip, {}).setdefault(source.rel, [])
            rows.append((record.position, record.kind, record.terminal))

    def _terminal_slot(self, record: TerminalSlot, source: _Source) -> None:
        self._item(record.block, record.cad_id)
        self._blocks.setdefault(record.block, {})[(record.position, record.cad_id, record.terminal)] = None
        if record.commercial:
            self._model(record.commercial)
            self._item_model[record.cad_id] = record.commercial
        if record.terminal is not None:
            for level in record.levels:
                iri = self._pin(PinRef(record.block, record.terminal, level, ""))
                pin = self._pins[iri]
                self._pins[iri] = PinInfo(pin.iri, pin.label, pin.name, pin.level, record.cad_id)

    def _scene_item(self, record: SceneItem, source: _Source) -> None:
        parent = record.parent_id or source.root_frame
        self._frames[record.item_id] = (parent, _pose(record.translation, record.rotation))
        if record.bbox_min is not None and record.bbox_max is not None:
            low = tuple(float(v) for v in record.bbox_min)
            high = tuple(float(v) for v in record.bbox_max)
            self._bboxes[record.item_id] = (low, high)  # type: ignore[assignment]
        if record.mesh is not None:
            self._meshes[record.item_id] = item_mesh_file(record.item_id)

    def _assignment(self, record: Assignment, source: _Source) -> None:
        target = node_iri(self.base, record.kind, record.ident)
        self._assignments.append((graph_iri(self.base, source.rel), record.line, target, record.performer))

    # -- shared nodes ----------------------------------------------------------------
    def _item(self, label: str, cad_id: str) -> None:
        self._items.setdefault(label, {})[cad_id] = None

    def _model(self, key: str) -> ModelInfo:
        model = self._models.get(key)
        if model is None:
            model = self._models[key] = ModelInfo(key)
        return model

    def _pin(self, ref: PinRef) -> str:
        key = (ref.component, ref.pin, ref.level)
        iri = self._pin_iris.get(key)
        if iri is None:
            iri = self._pin_iris[key] = pin_iri(self.base, ref)
            if iri not in self._pins:
                self._pins[iri] = PinInfo(iri, ref.component, ref.pin, ref.level, None)
        return iri

    def _describe(self, record: ComponentModel, source: _Source) -> None:
        model = self._model(record.key)
        # The mapping describes a model once per graph: the first description in a file counts.
        if record.key in source.described:
            return
        source.described.add(record.key)
        model.role = model.role or record.role
        if record.dimensions:
            x, y, z = (float(v) for v in record.dimensions)
            model.dimensions = (x, y, z)
        for couple in record.couples:
            if couple.screw is not None:
                model.screws[couple.name] = _placement(couple.screw)
            if couple.hole is not None:
                model.holes[couple.name] = _placement(couple.hole)
        for child in record.children:
            self._model(child.name)
            model.children[child.name] = _placement(child.relative)
        for item in record.items:
            model.items[item.name] = _placement(item.placement)
        if record.mounting is not None:
            model.mounting = _placement(record.mounting)


_HANDLERS: dict[type, Callable[[InputCollector, Any, _Source], None]] = {
    IdEntry: InputCollector._id_entry,
    ConnectionListInfo: InputCollector._nothing,
    BomInfo: InputCollector._nothing,
    BomLine: InputCollector._nothing,
    QrMarker: InputCollector._nothing,
    Connection: InputCollector._connection,
    ComponentModel: InputCollector._component_model,
    ComponentListEntry: InputCollector._component_list_entry,
    TerminalSlot: InputCollector._terminal_slot,
    PartPins: InputCollector._part_pins,
    DiagramRow: InputCollector._diagram_row,
    SceneItem: InputCollector._scene_item,
    Assignment: InputCollector._assignment,
}
