"""Records of the formats no single use case owns → triples: WRI tables, connection lists,
scenes, assignments, and the manifest's cell and frames.

IRIs join across files: ``item/ID000041`` is the same node whether the WRI, the scene or a
terminal schema names it, ``model/CODE`` is keyed by the WRI's commercial code, pins are
``pin/COMPONENT/PIN`` (``pin/BLOCK/TERMINAL/LEVEL`` on a terminal) as connection lists write them.
"""

from __future__ import annotations

from operator import attrgetter

import cadkg.registry as registry
from cadkg.ingest.assignments import Assignment
from cadkg.ingest.eplan.connection_list import Connection, ConnectionListInfo
from cadkg.ingest.manifest import FrameSpec, Manifest
from cadkg.ingest.scene.records import SceneItem
from cadkg.ingest.wri import IdEntry
from cadkg.mapping.dispatch import map_record
from cadkg.mapping.nodes import component_node, frame_node, item_mesh_file, mesh_node, pin_node, wire_iri
from cadkg.mapping.writer import INTEGER, TYPE, TripleWriter, literal, term, write_pose

__all__ = ["map_manifest"]

t = term
SOURCE_LINE = term("sourceLine")


_CAD_ITEM, _CAD_ID, _HAS_ITEM, _NAMES, _INSTANCE_OF = (
    term(n) for n in ("CadItem", "cadId", "hasItem", "names", "instanceOf")
)


@map_record.register
def _(record: IdEntry, w: TripleWriter, source_slug: str) -> None:
    item = w.iri("item", record.cad_id)
    component = component_node(w, record.label)
    label = w.iri("label", record.label)
    lines = [
        f"{item} {TYPE} {_CAD_ITEM} .\n{item} {_CAD_ID} {literal(record.cad_id)} .\n"
        f'{item} {SOURCE_LINE} "{record.line}"^^{INTEGER} .\n{component} {_HAS_ITEM} {item} .\n'
        f"{label} {_NAMES} {item} .\n"
    ]
    count = 5
    if w.once(label):
        lines.append(
            f"{label} {TYPE} {term('Label')} .\n{label} {term('label')} {literal(record.label)} .\n"
            f"{label} {_NAMES} {component} .\n"
        )
        count += 3
    if record.raw_label != record.label and w.once(label + record.raw_label):
        lines.append(f"{label} {term('rawLabel')} {literal(record.raw_label)} .\n")
        count += 1
    if record.commercial is not None:
        model = w.iri("model", record.commercial)
        if w.once(model):
            lines.append(
                f"{model} {TYPE} {term('CommercialModel')} .\n"
                f"{model} {term('commercialCode')} {literal(record.commercial)} .\n"
            )
            count += 2
        lines.append(f"{item} {_INSTANCE_OF} {model} .\n")
        count += 1
    w.add_block("".join(lines), count)


@map_record.register
def _(record: ConnectionListInfo, w: TripleWriter, source_slug: str) -> None:
    plan = w.iri("plan", source_slug)
    w.add(plan, TYPE, term("ActionPlan"))
    w.add(plan, term("label"), w.text(record.project or source_slug))
    if record.job:
        w.add(plan, term("description"), w.text(f"job {record.job}"))


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
_WIRE_PREDICATES = tuple(term(name) for _, name in _WIRE_TEXT)


_WIRE, _WIRE_NUMBER, _FROM_PIN, _TO_PIN, _IN_PLAN, _SEQUENCE_INDEX = (
    term(n) for n in ("Wire", "wireNumber", "fromPin", "toPin", "inPlan", "sequenceIndex")
)
_SECTION, _LENGTH, _DUCT_PATH, _PASSES_THROUGH = (
    term(n) for n in ("crossSectionMm2", "lengthM", "ductPath", "passesThrough")
)


@map_record.register
def _(record: Connection, w: TripleWriter, source_slug: str) -> None:
    wire = f"<{wire_iri(w.base, record.wire_number, w.wires)}>"
    plan = w.plans.get(source_slug)
    if plan is None:
        plan = w.plans[source_slug] = w.iri("plan", source_slug)
    origin, destination = pin_node(w, record.origin), pin_node(w, record.destination)
    parts = [
        f"{wire} {TYPE} {_WIRE} .\n{wire} {_WIRE_NUMBER} {literal(record.wire_number)} .\n"
        f"{wire} {_FROM_PIN} {origin} .\n{wire} {_TO_PIN} {destination} .\n{wire} {_IN_PLAN} {plan} .\n"
        f'{wire} {_SEQUENCE_INDEX} "{record.index}"^^{INTEGER} .\n'
        f'{wire} {SOURCE_LINE} "{record.line}"^^{INTEGER} .\n'
    ]
    measures = ((_SECTION, record.section_mm2), (_LENGTH, record.length_m))
    parts.extend(
        f"{wire} {predicate} {w.typed(value)} .\n" for predicate, value in measures if value is not None
    )
    parts.extend(
        [
            f"{wire} {predicate} {literal(value)} .\n"
            for predicate, value in zip(_WIRE_PREDICATES, _WIRE_VALUES(record), strict=True)
            if value is not None
        ]
    )
    if record.duct_path:
        # As the list writes it ('=-U3;=-U5', "=-CN2'=-CN3"): what the cell's software hands on.
        parts.append(f"{wire} {_DUCT_PATH} {literal(record.duct_text or ';'.join(record.duct_path))} .\n")
        for duct_label in dict.fromkeys(record.duct_path):
            parts.append(f"{wire} {_PASSES_THROUGH} {component_node(w, duct_label, 'Duct')} .\n")
    w.add_block("".join(parts), 6 + len(parts))  # seven lines in the first part, one in each other


def map_manifest(w: TripleWriter, manifest: Manifest) -> None:
    """The cell itself and its static frames, stated by the manifest."""
    cell = w.iri("cell", "this")
    w.add(cell, TYPE, term("Cell"))
    w.add(cell, term("label"), w.text(manifest.cell.name))
    w.add(cell, term("profile"), w.text(manifest.cell.profile))
    if manifest.cell.description:
        w.add(cell, term("description"), w.text(manifest.cell.description))
    settings = registry.derive_settings(manifest.cell.profile)
    if settings is not None and manifest.derive is not None:
        for name, value in settings.state(manifest.derive):
            w.add(cell, term(name), w.text(value) if isinstance(value, str) else w.typed(value))
    if manifest.plan_rules is not None:
        # The text itself, so that a store planned elsewhere plans by the manifest's rules.
        w.add(cell, term("planRules"), w.text(manifest.plan_rules.name))
        w.add(cell, term("planRulesText"), w.text(manifest.plan_rules.read_text(encoding="utf-8")))
    for frame in manifest.frames:
        _map_frame(w, frame)


def _map_frame(w: TripleWriter, frame: FrameSpec) -> None:
    child = frame_node(w, frame.child)
    pose = w.iri("pose", frame.child)
    w.add(child, term("hasPose"), pose)
    write_pose(w, pose, frame.xyz, frame.quaternion, frame_node(w, frame.parent))
    w.add(pose, term("sourceLine"), w.typed(frame.line))


@map_record.register
def _(record: SceneItem, w: TripleWriter, source_slug: str) -> None:
    item = w.iri("item", record.item_id)
    w.add(item, t("type"), t("CadItem"))
    w.add(item, t("cadId"), w.text(record.item_id))
    frame = frame_node(w, record.item_id)
    w.add(item, t("hasFrame"), frame)
    parent = frame_node(w, record.parent_id or w.root_frame)
    pose = w.iri("pose", record.item_id)
    w.add(frame, t("hasPose"), write_pose(w, pose, record.translation, record.rotation, parent))
    w.add(pose, t("sourceLine"), w.typed(record.line))
    if record.bbox_min is not None and record.bbox_max is not None:
        for name, value in zip(
            ("minX", "minY", "minZ", "maxX", "maxY", "maxZ"),
            (*record.bbox_min, *record.bbox_max),
            strict=True,
        ):
            w.add(item, t(name), w.typed(float(value)))
    if record.mesh is not None:
        rel = item_mesh_file(record.item_id)
        w.meshes[rel] = record.mesh
        mesh_node(w, item, w.iri("mesh", record.item_id), rel)


@map_record.register
def _(record: Assignment, w: TripleWriter, source_slug: str) -> None:
    node = w.iri("assignment", record.kind, record.ident)
    w.add(node, t("type"), t("Assignment"))
    w.add(node, t("assignmentOf"), w.iri(record.kind, record.ident))
    w.add(node, t("assignedTo"), t(record.performer))
    w.add(node, t("sourceLine"), w.typed(record.line))
