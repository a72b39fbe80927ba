"""ENKI records → triples: hose products (``hose/PRODUCT``), lengths in metres."""

from __future__ import annotations

from cadkg.mapping.dispatch import map_record
from cadkg.mapping.nodes import named_node
from cadkg.mapping.writer import TripleWriter, term
from cadkg.usecases.enki.hose import HoseProduct

__all__: list[str] = []

t = term


@map_record.register
def _(record: HoseProduct, w: TripleWriter, source_slug: str) -> None:
    node = named_node(w, "hose", record.product, "Hose")
    w.add(node, t("diameterM"), w.typed(record.diameter_m))
    if record.length_m is not None:
        w.add(node, t("lengthM"), w.typed(record.length_m))
    if record.material is not None:
        w.add(node, t("material"), w.text(record.material))
    if record.bend_radius_m is not None:
        w.add(node, t("bendRadiusM"), w.typed(record.bend_radius_m))
    w.add(node, t("sourceLine"), w.typed(record.line))
