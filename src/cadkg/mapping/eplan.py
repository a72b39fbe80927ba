"""EPLAN's own exports → triples: parts-management connection points and bills of materials.

A bill-of-materials line is a parts entry of its device (``ck:PartEntry``, as a row of the
component list), keyed by its file and row (``bom/SOURCE/ROW``).

A part's connection points are pins of the commercial model its part number names
(``model/CODE``, the node the WRI table and the component models share), kept apart from
the couples of the component models (``model/CODE/point/NAME``, linked by
``ck:definesConnectionPoint``): where a model has a couple of that name, the couple counts.
"""

from __future__ import annotations

from cadkg.ingest.eplan.bill_of_materials import BomInfo, BomLine
from cadkg.ingest.eplan.parts import PartPins
from cadkg.mapping.dispatch import map_record
from cadkg.mapping.nodes import component_node, model_frame, model_node, model_pin, texts
from cadkg.mapping.writer import TripleWriter, term, write_pose

__all__: list[str] = []

t = term


@map_record.register
def _(record: PartPins, w: TripleWriter, source_slug: str) -> None:
    model = model_node(w, record.part)
    frame = model_frame(w, model, record.part)
    w.add(model, t("sourceLine"), w.typed(record.line))
    for point in record.points:
        pin = model_pin(w, model, record.part, "point", t("definesConnectionPoint"), point.name, point.line)
        pose = w.iri("model", record.part, "point", point.name, "hole")
        w.add(pin, t("holePose"), write_pose(w, pose, point.position, point.orientation, frame))
        w.add(pose, t("sourceLine"), w.typed(point.line))
        for predicate, value in (
            ("connectionDirection", point.direction_code),
            ("connectionLevel", point.level),
            ("pinDeviceTag", point.device_tag),
        ):
            if value is not None:
                w.add(pin, t(predicate), w.text(value))


@map_record.register
def _(record: BomInfo, w: TripleWriter, source_slug: str) -> None:
    pass  # the project, job and customer are already the connection list's and the cell's


@map_record.register
def _(record: BomLine, w: TripleWriter, source_slug: str) -> None:
    entry = w.iri("bom", source_slug, str(record.line))
    if record.label is not None:
        w.add(component_node(w, record.label), t("hasPartEntry"), entry)
    w.add(entry, t("type"), t("PartEntry"))
    w.add(entry, t("sourceLine"), w.typed(record.line))
    if record.part_number:
        w.add(entry, t("instanceOf"), model_node(w, record.part_number))
    if record.quantity is not None:
        whole = record.quantity == record.quantity.to_integral_value()
        w.add(entry, t("quantity"), w.typed(int(record.quantity) if whole else record.quantity))
    texts(
        w,
        entry,
        description=record.description,
        typeNumber=record.type_number,
        manufacturer=record.manufacturer,
        mountingZone=record.zone,
        functionText=record.function,
    )
