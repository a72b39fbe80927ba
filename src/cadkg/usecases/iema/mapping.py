"""Cabinet records → triples: component models, parts lists, terminal schemas, scenes, assignments.

IRIs join those of the WRI and the connection list: ``item/ID000041`` is the same
node whether the WRI, the scene or the terminal schema names it, ``model/CODE`` is
keyed by the commercial code the WRI uses, and terminal pins are
``pin/BLOCK/TERMINAL/LEVEL`` as the connection list writes them.
"""

from __future__ import annotations

from cadkg.ingest.eplan.labels import PinRef
from cadkg.mapping.dispatch import map_record
from cadkg.mapping.nodes import (
    component_node,
    dimensions,
    frame_node,
    model_frame,
    model_node,
    model_pin,
    pin_node,
    placement_pose,
    texts,
)
from cadkg.mapping.writer import TripleWriter, term, write_pose
from cadkg.usecases.iema.component_list import ComponentListEntry
from cadkg.usecases.iema.component_model import ComponentModel
from cadkg.usecases.iema.marker_table import QrMarker
from cadkg.usecases.iema.terminal_diagram import DiagramRow
from cadkg.usecases.iema.terminal_schema import TerminalSlot

__all__: list[str] = []

t = term


def _map_model(w: TripleWriter, model: ComponentModel) -> str:
    node = model_node(w, model.key)
    if not w.once(node + "#described"):
        return node
    w.add(node, t("label"), w.text(model.code))
    w.add(node, t("sourceLine"), w.typed(model.line))
    if model.role:
        w.add(node, t("modelRole"), w.text(model.role))
    if model.dimensions:
        dimensions(w, node, model.dimensions)
    frame = model_frame(w, node, model.key)
    for couple in model.couples:
        pin = model_pin(w, node, model.key, "pin", t("definesPin"), couple.name, couple.line)
        for kind, placement in (("screw", couple.screw), ("hole", couple.hole)):
            if placement is not None:
                pose = w.iri("model", model.key, "pin", couple.name, kind)
                w.add(pin, t(f"{kind}Pose"), placement_pose(w, pose, placement, frame))
    for item in model.items:
        node_item = w.iri("model", model.key, "item", item.name)
        w.add(node, t("hasItemFrame"), node_item)
        w.add(node_item, t("type"), t("ModelItemFrame"))
        w.add(node_item, t("label"), w.text(item.name))
        pose = w.iri("model", model.key, "item", item.name, "pose")
        w.add(node_item, t("hasPose"), placement_pose(w, pose, item.placement, frame))
    if model.mounting is not None:
        # In the frame of the root item it is mounted on, which only the cabinet tells.
        pose = w.iri("model", model.key, "mounting")
        w.add(node, t("mountingPose"), placement_pose(w, pose, model.mounting, frame))
    for child in model.children:
        place = w.iri("model", model.key, "child", child.name)
        w.add(node, t("hasChildPlacement"), place)
        w.add(place, t("type"), t("ModelChild"))
        w.add(place, t("childModel"), model_node(w, child.name))
        pose = w.iri("model", model.key, "child", child.name, "pose")
        w.add(place, t("hasPose"), placement_pose(w, pose, child.relative, frame))
    return node


@map_record.register
def _(record: ComponentModel, w: TripleWriter, source_slug: str) -> None:
    _map_model(w, record)


@map_record.register
def _(record: ComponentListEntry, w: TripleWriter, source_slug: str) -> None:
    component = component_node(w, record.label)
    entry = w.iri("part", record.label, str(record.line))
    w.add(component, t("hasPartEntry"), entry)
    w.add(entry, t("type"), t("PartEntry"))
    w.add(entry, t("sourceLine"), w.typed(record.line))
    if record.description:
        w.add(entry, t("description"), w.text(record.description))
        if w.once(component + "#description"):
            w.add(component, t("description"), w.text(record.description))
    if record.quantity is not None:
        w.add(entry, t("quantity"), w.typed(record.quantity))
    if record.part_number:
        w.add(entry, t("instanceOf"), model_node(w, record.part_number))
    for model in record.models:
        _map_model(w, model)


@map_record.register
def _(record: TerminalSlot, w: TripleWriter, source_slug: str) -> None:
    block = component_node(w, record.block)
    if w.once(block + "#block"):
        w.add(block, t("type"), t("TerminalBlock"))
    item = w.iri("item", record.cad_id)
    w.add(item, t("type"), t("CadItem"))
    w.add(item, t("type"), t("TerminalItem"))
    w.add(item, t("cadId"), w.text(record.cad_id))
    w.add(item, t("blockPosition"), w.typed(record.position))
    w.add(block, t("hasItem"), item)
    w.add(block, t("hasTerminalItem"), item)
    if record.commercial:
        w.add(item, t("instanceOf"), model_node(w, record.commercial))
    if record.terminal is None:
        return
    w.add(item, t("terminalName"), w.text(record.terminal))
    for level in record.levels:
        pin = pin_node(
            w, PinRef(record.block, record.terminal, level, f"{record.block}:{record.terminal}:{level}")
        )
        w.add(pin, t("onItem"), item)


@map_record.register
def _(record: DiagramRow, w: TripleWriter, source_slug: str) -> None:
    block = component_node(w, record.strip)
    if w.once(block + "#block"):
        w.add(block, t("type"), t("TerminalBlock"))
    row = w.iri("diagram", source_slug, record.sheet, str(record.line))
    w.add(block, t("hasDiagramRow"), row)
    w.add(row, t("type"), t("TerminalDiagramRow"))
    w.add(row, t("sourceLine"), w.typed(record.line))
    w.add(row, t("diagramPosition"), w.typed(record.position))
    w.add(row, t("rowKind"), w.text(record.kind))
    texts(
        w,
        row,
        diagramTerminal=record.terminal,
        diagramZone=record.zone,
        functionText=record.function,
        terminalType=record.terminal_type,
    )
    for number, (ref, zone) in enumerate(record.destinations, start=1):
        destination = w.iri("diagram", source_slug, record.sheet, str(record.line), str(number))
        w.add(row, t("hasDiagramDestination"), destination)
        w.add(destination, t("diagramDestination"), w.text(ref))
        if zone:
            w.add(destination, t("diagramZone"), w.text(zone))


@map_record.register
def _(record: QrMarker, w: TripleWriter, source_slug: str) -> None:
    item = w.iri("item", record.cad_id)
    w.add(item, t("type"), t("CadItem"))
    w.add(item, t("cadId"), w.text(record.cad_id))
    pose = w.iri("item", record.cad_id, "marker")
    # The table gives no orientation: the marker is turned as its item.
    w.add(
        item,
        t("markerPose"),
        write_pose(w, pose, record.position, (0.0, 0.0, 0.0, 1.0), frame_node(w, record.cad_id)),
    )
    w.add(pose, t("sourceLine"), w.typed(record.line))
