"""ELVEZ records → triples: platform scenes, WRI tables and meshes, element definitions,
harnesses, components and the assembly sequence.

CAD IDs repeat between platforms, so a platform's element is ``element/PLATFORM/ID`` and its
frame ``IDPLATFORM`` (``ID0002platform``, the name the reference node gives it on TF), placed in
its parent element's frame or, for the root, in the frame the manifest gives the scene
(``platform_rf``). Definitions are ``model/CODE`` (the WRI's commercial code), their parts
keypoints ``model/CODE/KIND/ID`` with poses in the model's frame. Components and cables are
``component/LABEL`` and ``cable/LABEL`` wherever they are named; a harness is ``harness/ID``; an
operation ``operation/SEQUENCE/LINE`` with one ck:Spot per spot.
"""

from __future__ import annotations

from collections.abc import Sequence

from cadkg.confined import file_name
from cadkg.geometry.poses import Pose
from cadkg.ingest.eplan.labels import PinRef
from cadkg.mapping.dispatch import map_record
from cadkg.mapping.nodes import (
    cable_node,
    component_node,
    connector_node,
    dimensions,
    frame_node,
    mesh_node,
    model_frame,
    model_node,
    pin_node,
    texts,
)
from cadkg.mapping.writer import TripleWriter, term, write_pose
from cadkg.usecases.elvez.files.components import HarnessComponent
from cadkg.usecases.elvez.files.definitions import ElementDefinition, Key, PlacedBox
from cadkg.usecases.elvez.files.harnesses import HarnessCable, WiringHarness
from cadkg.usecases.elvez.files.platforms import ElementMesh, PlatformId, PlatformItem
from cadkg.usecases.elvez.files.sequence import SequenceStep
from cadkg.usecases.elvez.platform import element_frame

__all__ = ["OPERATION_CLASSES", "element_frame", "element_mesh_file", "pin_name"]

t = term

OPERATION_CLASSES = {
    "EC": "ExtractOperation",
    "PC": "InsertOperation",
    "RC": "RouteOperation",
    "T": "TapeOperation",
    "TJ": "TapeOperation",
}
"""The ontology class of each operation code."""


def element_mesh_file(platform: str, name: str) -> str:
    """Where a platform mesh is kept in the store's files."""
    return f"meshes/elvez/{file_name(platform)}/{file_name(name)}.stl"


def pin_name(cavity: tuple[int, int]) -> str:
    """The pin name of a connector cavity: row 3, column 0 → ``R3C0``."""
    return f"R{cavity[0]}C{cavity[1]}"


def _platform(w: TripleWriter, name: str) -> str:
    node = w.iri("platform", name)
    if w.once(node):
        w.add(node, t("type"), t("Platform"))
        w.add(node, t("label"), w.text(name))
    return node


def _element(w: TripleWriter, platform: str, cad_id: str) -> str:
    node = w.iri("element", platform, cad_id)
    if w.once(node):
        w.add(node, t("type"), t("Element"))
        w.add(node, t("cadId"), w.text(cad_id))
        w.add(node, t("onPlatform"), _platform(w, platform))
    return node


@map_record.register
def _(record: PlatformItem, w: TripleWriter, source_slug: str) -> None:
    element = _element(w, record.platform, record.cad_id)
    frame = frame_node(w, element_frame(record.cad_id, record.platform))
    w.add(element, t("hasFrame"), frame)
    parent = (
        frame_node(w, element_frame(record.parent_id, record.platform))
        if record.parent_id is not None
        else frame_node(w, w.root_frame)
    )
    pose = w.iri("pose", "elvez", record.platform, record.cad_id)
    w.add(frame, t("hasPose"), write_pose(w, pose, record.translation, record.rotation, parent))
    w.add(pose, t("sourceLine"), w.typed(record.line))
    if record.mesh is not None:
        # On the frame, not the element: the element's CAD ID is not a frame of the cell.
        rel = element_mesh_file(record.platform, record.cad_id)
        w.meshes[rel] = record.mesh
        mesh_node(w, frame, w.iri("mesh", "elvez", record.platform, record.cad_id), rel)


@map_record.register
def _(record: PlatformId, w: TripleWriter, source_slug: str) -> None:
    element = _element(w, record.platform, record.cad_id)
    w.add(element, t("label"), w.text(record.label))
    w.add(element, t("sourceLine"), w.typed(record.line))
    if record.element_type:
        w.add(element, t("elementType"), w.text(record.element_type))
    if record.model is not None:
        w.add(element, t("instanceOf"), model_node(w, record.model))
    if record.element_type == "atc_station":
        w.add(element, t("type"), t("AtcSlot"))
        name = record.label[1:]
        tool = w.iri("tool", name)
        w.add(tool, t("type"), t("Tool"))
        w.add(tool, t("label"), w.text(name))
        w.add(tool, t("toolSlot"), element)


@map_record.register
def _(record: ElementMesh, w: TripleWriter, source_slug: str) -> None:
    rel = element_mesh_file(record.platform, record.name)
    w.meshes[rel] = record.mesh
    mesh = w.iri("mesh", "elvez", record.platform, record.name)
    w.add(mesh, t("type"), t("Mesh"))
    w.add(mesh, t("meshUri"), f'"{rel}"^^<http://www.w3.org/2001/XMLSchema#anyURI>')
    w.add(mesh, t("label"), w.text(record.name))
    w.add(mesh, t("partOf"), _platform(w, record.platform))


def _extents(w: TripleWriter, node: str, extents: Sequence[float]) -> None:
    for name, value in zip(
        ("collisionXFrom", "collisionXTo", "collisionYFrom", "collisionYTo"), extents, strict=True
    ):
        w.add(node, t(name), w.typed(float(value)))


def _keypoint(
    w: TripleWriter, model: str, frame: str, code: str, kind: str, ident: str, pose: Pose | None, line: int
) -> str:
    node = w.iri("model", code, kind, ident) if ident else w.iri("model", code, kind)
    w.add(model, t("definesKeypoint"), node)
    w.add(node, t("type"), t("Keypoint"))
    w.add(node, t("keypointKind"), w.text(kind))
    w.add(node, t("sourceLine"), w.typed(line))
    if ident:
        w.add(node, t("label"), w.text(ident))
    if pose is not None:
        pose_node = w.under(node, "pose")
        w.add(node, t("hasPose"), write_pose(w, pose_node, pose.position, pose.orientation, frame))
    return node


def _placed(
    w: TripleWriter, model: str, frame: str, code: str, kind: str, box: PlacedBox, guide: str
) -> None:
    node = _keypoint(w, model, frame, code, kind, box.id or guide, box.corner, box.line)
    dimensions(w, node, box.size)
    if guide:
        w.add(node, t("guideId"), w.text(guide))


def _key(w: TripleWriter, model: str, frame: str, code: str, couple: str, key: Key) -> None:
    node = _keypoint(w, model, frame, code, "key", couple, key.corner, key.line)
    w.add(node, t("guideId"), w.text(couple))
    for name, value in (
        ("keyLength", key.length),
        ("keyGap", key.gap),
        ("keyHeight", key.height),
        ("keyHeightCorner", key.height_corner),
    ):
        w.add(node, t(name), w.typed(value))
    _extents(w, node, key.extents)


@map_record.register
def _(record: ElementDefinition, w: TripleWriter, source_slug: str) -> None:
    code = record.model
    model = model_node(w, code)
    w.add(model, t("modelKind"), w.text(record.kind))
    w.add(model, t("sourceLine"), w.typed(record.line))
    dimensions(w, model, record.size)
    if record.extents is not None:
        _extents(w, model, record.extents)
    frame = model_frame(w, model, code)
    if record.centre is not None and record.footprint is not None:
        centre = _keypoint(w, model, frame, code, "centre", "", Pose((*record.centre, 0.0)), record.line)
        dimensions(w, centre, (*record.footprint, 0.0))
    for guide in record.guides:
        _key(w, model, frame, code, guide.couple, guide.key)
        if guide.collision is not None:
            _placed(w, model, frame, code, "collision", guide.collision, guide.couple)
    for spot in record.tape_spots:
        _placed(w, model, frame, code, "tape_spot", spot, spot.guide)
    for tray in record.trays:
        _placed(w, model, frame, code, "tray", tray, "")
    tool = record.tool
    if tool is not None:
        w.add(model, t("stationTool"), w.text(tool.kind))
        for kind, pose in (("tool_base", tool.base), ("tool_end", tool.end), ("gripper_nail", tool.nail)):
            if pose is not None:
                _keypoint(w, model, frame, code, kind, "", pose, record.line)
        for kind, size in (("tool_size", tool.size), ("finger_size", tool.fingers)):
            if size is not None:
                dimensions(w, _keypoint(w, model, frame, code, kind, "", None, record.line), size)


def _cavity(w: TripleWriter, connector: str, cavity: tuple[int, int]) -> str:
    node = pin_node(w, PinRef(connector, pin_name(cavity), None, f"{connector}:{pin_name(cavity)}"))
    if w.once(node + "#cavity"):
        w.add(node, t("cavityRow"), w.typed(cavity[0]))
        w.add(node, t("cavityColumn"), w.typed(cavity[1]))
    return node


def _cable(w: TripleWriter, harness: str, first: str, end: str, cable: HarnessCable) -> str:
    node = cable_node(w, cable.label)
    w.add(node, t("partOf"), harness)
    w.add(node, t("sourceLine"), w.typed(cable.line))
    w.add(node, t("fromPin"), _cavity(w, first, cable.first_cavity))
    if cable.end_cavity is not None:
        w.add(node, t("toPin"), _cavity(w, end, cable.end_cavity))
    return node


@map_record.register
def _(record: WiringHarness, w: TripleWriter, source_slug: str) -> None:
    harness = w.iri("harness", record.id)
    main = connector_node(w, record.first_connector)
    w.add(harness, t("type"), t("Harness"))
    w.add(harness, t("label"), w.text(record.id))
    if record.id.isdigit():
        w.add(harness, t("harnessNumber"), w.typed(int(record.id)))
    w.add(harness, t("sourceLine"), w.typed(record.line))
    w.add(harness, t("mainConnector"), main)
    w.add(harness, t("hasConnector"), main)
    if record.tray:
        w.add(harness, t("trayLabel"), w.text(record.tray))
    for position, end in enumerate(record.end_connectors, start=1):
        branch = w.iri("branch", record.id, str(position))
        w.add(harness, t("hasBranch"), branch)
        w.add(branch, t("type"), t("Branch"))
        w.add(branch, t("label"), w.text(end.label))
        w.add(branch, t("sourceLine"), w.typed(end.line))
        w.add(branch, t("hasConnector"), connector_node(w, end.label))
        for cable in end.cables:
            w.add(branch, t("containsCable"), _cable(w, harness, record.first_connector, end.label, cable))


@map_record.register
def _(record: HarnessComponent, w: TripleWriter, source_slug: str) -> None:
    if record.kind == "cable":
        node = cable_node(w, record.label)
    elif record.kind == "connector":
        node = connector_node(w, record.label)
    else:
        node = component_node(w, record.label)
        w.add(node, t("type"), t("Device"))
    w.add(node, t("sourceLine"), w.typed(record.line))
    texts(w, node, colourName=record.colour, referenceCode=record.reference)
    if record.device_type:
        w.add(node, t("deviceType"), w.text(record.device_type))
    if record.model:
        w.add(node, t("instanceOf"), model_node(w, record.model))
    if record.rgb is not None:
        w.add(node, t("colourRgb"), w.text(" ".join(str(c) for c in record.rgb)))
    if record.length is not None:
        w.add(node, t("lengthM"), w.typed(record.length))
    if record.diameter is not None:
        w.add(node, t("diameterM"), w.typed(record.diameter))
    if record.size is not None:
        dimensions(w, node, record.size)


@map_record.register
def _(record: SequenceStep, w: TripleWriter, source_slug: str) -> None:
    plan = w.iri("plan", source_slug)
    if w.once(plan):
        w.add(plan, t("type"), t("ActionPlan"))
        w.add(plan, t("label"), w.text(source_slug))
    op = w.iri("operation", source_slug, str(record.line))
    w.add(op, t("type"), t("Operation"))
    w.add(op, t("type"), t(OPERATION_CLASSES[record.code.upper()]))
    w.add(op, t("operationCode"), w.text(record.code))
    w.add(op, t("inPlan"), plan)
    w.add(op, t("sequenceIndex"), w.typed(record.order))
    w.add(op, t("sourceLine"), w.typed(record.line))
    w.add(op, t("involvedLabels"), w.text(";".join(record.labels)))
    w.add(op, t("spotLabels"), w.text(";".join(f"{s.jig}.{s.guide}" for s in record.spots)))
    for label in record.labels:
        w.add(op, t("involves"), w.iri("component", label))
    for position, spot in enumerate(record.spots, start=1):
        node = w.under(op, "spot", str(position))
        w.add(op, t("atSpot"), node)
        w.add(node, t("type"), t("Spot"))
        w.add(node, t("label"), w.text(spot.jig))
        w.add(node, t("guideId"), w.text(spot.guide))
        w.add(node, t("sequenceIndex"), w.typed(position))
        if spot.side:
            w.add(node, t("side"), w.text(spot.side))
