"""ELVEZ records → triples: element models, harness components and structure, tools, action plan.

IRIs join those of the other files: ``model/0009`` is the model the WRI table's commercial
code names, ``component/G4`` the element its label names (an operation's spot),
``component/C10`` a connector and ``cable/W101`` a cable wherever they are mentioned, and
``operation/7`` the seventh operation of the plan (what ``cadkg assign`` addresses).

Harnesses use the same terms as every harness in the graph: ``ck:Harness ck:hasBranch
ck:Branch``, ``ck:containsCable ck:Cable``, a cable's ends ``ck:fromPin`` (main connector) and
``ck:toPin`` (branch connector) are ``ck:Pin`` contacts ``ck:inCavity`` a ``ck:Cavity`` of the
``ck:Connector`` they are ``ck:pinOf``.
"""

from __future__ import annotations

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
    placement_pose,
)
from cadkg.mapping.writer import TripleWriter, term
from cadkg.usecases.elvez.action_plan import PlannedOperation
from cadkg.usecases.elvez.element_models import ElementModel
from cadkg.usecases.elvez.harness_components import HarnessComponent
from cadkg.usecases.elvez.harness_structure import HarnessSpec
from cadkg.usecases.elvez.tools import ToolSpec

__all__ = ["OPERATION_CLASSES"]

t = term

OPERATION_CLASSES = {"insert": "InsertOperation", "route": "RouteOperation", "tape": "TapeOperation"}
"""The ontology class of each operation type of the action plan."""


@map_record.register
def _(record: ElementModel, w: TripleWriter, source_slug: str) -> None:
    node = model_node(w, record.number)
    w.add(node, t("sourceLine"), w.typed(record.line))
    if record.description:
        w.add(node, t("description"), w.text(record.description))
    dimensions(w, node, record.dimensions)
    frame = model_frame(w, node, record.number)
    for poi in record.frames:
        keypoint = w.iri("model", record.number, "keypoint", poi.name)
        w.add(node, t("definesKeypoint"), keypoint)
        w.add(keypoint, t("type"), t("Keypoint"))
        w.add(keypoint, t("label"), w.text(poi.name))
        w.add(keypoint, t("sourceLine"), w.typed(poi.placement.line))
        pose = w.iri("model", record.number, "keypoint", poi.name, "pose")
        w.add(keypoint, t("hasPose"), placement_pose(w, pose, poi.placement, frame))
    if record.key is not None:
        w.add(node, t("keyLength"), w.typed(record.key.length))
        w.add(node, t("keyGap"), w.typed(record.key.gap))
        w.add(node, t("keyHeight"), w.typed(record.key.height))
    if record.mesh is not None:
        rel = f"meshes/models/{record.number}.stl"
        w.files[rel] = record.mesh
        mesh = w.iri("mesh", "model", record.number)
        mesh_node(w, node, mesh, rel)
        if record.mesh_file:
            w.add(mesh, t("description"), w.text(f"from {record.mesh_file}"))


@map_record.register
def _(record: HarnessComponent, w: TripleWriter, source_slug: str) -> None:
    if record.kind == "cable":
        node = cable_node(w, record.name)
        if record.diameter_m is not None:
            w.add(node, t("diameterM"), w.typed(float(record.diameter_m)))
        if record.length_m is not None:
            w.add(node, t("lengthM"), w.typed(record.length_m))
    else:
        node = (
            connector_node(w, record.name) if record.kind == "connector" else component_node(w, record.name)
        )
        if record.kind == "capacitor":
            w.add(node, t("type"), t("Capacitor"))
        if record.dimensions_m is not None:
            dimensions(w, node, record.dimensions_m)
    w.add(node, t("sourceLine"), w.typed(record.line))
    if record.rgb is not None:
        w.add(node, t("colourRgb"), w.text(" ".join(str(c) for c in record.rgb)))
    if record.description:
        w.add(node, t("description"), w.text(record.description))


def _end(w: TripleWriter, connector: str, pin: int) -> str:
    node = pin_node(w, PinRef(connector, str(pin), None, f"{connector}:{pin}"))
    if w.once(node + "#cavity"):
        cavity = w.iri("cavity", connector, str(pin))
        w.add(node, t("pinIndex"), w.typed(pin))
        w.add(node, t("inCavity"), cavity)
        w.add(cavity, t("type"), t("Cavity"))
        w.add(cavity, t("pinIndex"), w.typed(pin))
        w.add(connector_node(w, connector), t("hasCavity"), cavity)
    return node


@map_record.register
def _(record: HarnessSpec, w: TripleWriter, source_slug: str) -> None:
    number = str(record.number)
    harness = w.iri("harness", number)
    main = connector_node(w, record.main_connector)
    w.add(harness, t("type"), t("Harness"))
    w.add(harness, t("label"), w.text(f"WH{number}"))
    w.add(harness, t("harnessNumber"), w.typed(record.number))
    w.add(harness, t("sourceLine"), w.typed(record.line))
    w.add(harness, t("mainConnector"), main)
    w.add(harness, t("hasConnector"), main)
    for position, spec in enumerate(record.branches, start=1):
        branch = w.iri("branch", number, str(position))
        w.add(harness, t("hasBranch"), branch)
        w.add(branch, t("type"), t("Branch"))
        w.add(branch, t("label"), w.text(f"WH{number}/{spec.connector}"))
        w.add(branch, t("sourceLine"), w.typed(spec.line))
        w.add(branch, t("hasConnector"), connector_node(w, spec.connector))
        for cable_spec in spec.cables:
            cable = cable_node(w, cable_spec.name)
            w.add(branch, t("containsCable"), cable)
            w.add(cable, t("partOf"), harness)
            w.add(cable, t("sourceLine"), w.typed(cable_spec.line))
            w.add(cable, t("fromPin"), _end(w, record.main_connector, cable_spec.main_pin))
            w.add(cable, t("toPin"), _end(w, spec.connector, cable_spec.pin))
        for capacitor in spec.capacitors:
            node = component_node(w, capacitor)
            w.add(node, t("type"), t("Capacitor"))
            w.add(node, t("partOf"), branch)


@map_record.register
def _(record: ToolSpec, w: TripleWriter, source_slug: str) -> None:
    tool = w.iri("tool", record.name)
    w.add(tool, t("type"), t("Tool"))
    w.add(tool, t("label"), w.text(record.name))
    w.add(tool, t("toolType"), w.text(record.kind))
    w.add(tool, t("sourceLine"), w.typed(record.line))
    w.add(tool, t("toolSlot"), component_node(w, record.atc_slot))
    dimensions(w, tool, record.dimensions)
    base = frame_node(w, f"{record.name}_base")
    wrist = frame_node(w, f"{record.name}_wrist")
    action = frame_node(w, f"{record.name}_action")
    for prop, frame in (("toolBaseFrame", base), ("wristFrame", wrist), ("actionFrame", action)):
        w.add(tool, t(prop), frame)
        w.add(tool, t("hasFrame"), frame)
    for frame, name, placement, parent in (
        (wrist, "wrist", record.base_to_wrist, base),
        (action, "action", record.wrist_to_action, wrist),
    ):
        w.add(
            frame, t("hasPose"), placement_pose(w, w.iri("pose", f"{record.name}_{name}"), placement, parent)
        )


@map_record.register
def _(record: PlannedOperation, w: TripleWriter, source_slug: str) -> None:
    plan = w.iri("plan", source_slug)
    if w.once(plan):
        w.add(plan, t("type"), t("ActionPlan"))
        w.add(plan, t("label"), w.text(source_slug))
    op = w.iri("operation", str(record.index))
    w.add(op, t("type"), t("Operation"))
    w.add(op, t("type"), t(OPERATION_CLASSES[record.kind]))
    w.add(op, t("inPlan"), plan)
    w.add(op, t("sequenceIndex"), w.typed(record.index))
    w.add(op, t("sourceLine"), w.typed(record.line))
    w.add(op, t("spotLabels"), w.text(";".join(record.spots)))
    w.add(op, t("involvedLabels"), w.text(";".join(record.components)))
    for label in record.spots:
        spot = component_node(w, label)
        if w.once(spot + "#spot"):
            w.add(spot, t("type"), t("Spot"))
        w.add(op, t("atSpot"), spot)
    for name in record.components:
        # An insert handles a connector; routing and taping handle cables. They are not typed
        # here: a name the harness files do not define stays an untyped node, which the
        # services report.
        w.add(op, t("involves"), w.iri("component" if record.kind == "insert" else "cable", name))
    tool = w.iri("tool", record.tool)
    w.add(op, t("usesTool"), tool)
