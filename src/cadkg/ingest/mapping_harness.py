"""Harness records (KBL and harness text) → triples in the ontology's harness terms.

IRIs are scoped by the harness, whose identifier is the first part: ``harness/H``,
``connector/H/X1``, ``cavity/H/X1/3``, ``contact/H/X1/3`` (the contact in that cavity, a
``ck:Pin``), ``node/H/N``, ``segment/H/S``, ``wire/H/W``, ``cable/H/C``, ``fixing/H/F``,
``protection/H/P``. So two harnesses in one graph never share a node, and a re-read file
gives the same IRIs. Everything a harness holds is ``ck:partOf`` it (a core also of its cable),
which is how the harness queries find it whatever file it came from.
"""

from __future__ import annotations

from cadkg.ingest.harness_records import (
    Harness,
    HarnessCable,
    HarnessConnector,
    HarnessFixing,
    HarnessNode,
    HarnessProtection,
    HarnessSegment,
    HarnessWire,
    WireEnd,
)
from cadkg.ingest.mapping import TripleWriter, map_record, term

__all__: list[str] = []

t = term


def _part_of(w: TripleWriter, node: str, harness: str) -> None:
    w.add(node, t("partOf"), w.iri("harness", harness))


def _contact(w: TripleWriter, harness: str, end: WireEnd) -> str:
    pin = w.iri("contact", harness, end.connector, end.cavity)
    if w.once(pin):
        connector = w.iri("connector", harness, end.connector)
        w.add(pin, t("type"), t("Pin"))
        w.add(pin, t("pinName"), w.text(end.cavity))
        w.add(pin, t("pinOf"), connector)
        w.add(connector, t("hasPin"), pin)
        w.add(pin, t("inCavity"), w.iri("cavity", harness, end.connector, end.cavity))
    return pin


@map_record.register
def _(record: Harness, w: TripleWriter, source_slug: str) -> None:
    node = w.iri("harness", record.ident)
    w.add(node, t("type"), t("Harness"))
    w.add(node, t("label"), w.text(record.ident))
    w.add(node, t("fileFormat"), w.text(record.file_format))
    w.add(node, t("sourceLine"), w.typed(record.line))
    if record.description:
        w.add(node, t("description"), w.text(record.description))


@map_record.register
def _(record: HarnessConnector, w: TripleWriter, source_slug: str) -> None:
    node = w.iri("connector", record.harness, record.ident)
    w.add(node, t("type"), t("Connector"))
    w.add(node, t("label"), w.text(record.ident))
    w.add(node, t("sourceLine"), w.typed(record.line))
    w.add(w.iri("harness", record.harness), t("hasConnector"), node)
    _part_of(w, node, record.harness)
    if record.description:
        w.add(node, t("description"), w.text(record.description))
    for name in record.cavities:
        cavity = w.iri("cavity", record.harness, record.ident, name)
        w.add(cavity, t("type"), t("Cavity"))
        w.add(cavity, t("label"), w.text(name))
        w.add(node, t("hasCavity"), cavity)


@map_record.register
def _(record: HarnessNode, w: TripleWriter, source_slug: str) -> None:
    node = w.iri("node", record.harness, record.ident)
    w.add(node, t("type"), t("HarnessNode"))
    w.add(node, t("label"), w.text(record.label))
    w.add(node, t("sourceLine"), w.typed(record.line))
    _part_of(w, node, record.harness)
    for connector in record.connectors:
        w.add(w.iri("connector", record.harness, connector), t("atNode"), node)


@map_record.register
def _(record: HarnessSegment, w: TripleWriter, source_slug: str) -> None:
    node = w.iri("segment", record.harness, record.ident)
    w.add(node, t("type"), t("Segment"))
    w.add(node, t("label"), w.text(record.label))
    w.add(node, t("sourceLine"), w.typed(record.line))
    _part_of(w, node, record.harness)
    w.add(node, t("segmentFrom"), w.iri("node", record.harness, record.start))
    w.add(node, t("segmentTo"), w.iri("node", record.harness, record.end))
    if record.length_m is not None:
        w.add(node, t("lengthM"), w.typed(record.length_m))
    if record.diameter_m is not None:
        w.add(node, t("diameterM"), w.typed(record.diameter_m))
    if record.section_mm2 is not None:
        w.add(node, t("bundleSectionMm2"), w.typed(record.section_mm2))


@map_record.register
def _(record: HarnessWire, w: TripleWriter, source_slug: str) -> None:
    node = w.iri("wire", record.harness, record.ident)
    add = w.add
    add(node, t("type"), t("Wire"))
    add(node, t("label"), w.text(record.ident))
    add(node, t("wireNumber"), w.text(record.label))
    add(node, t("sourceLine"), w.typed(record.line))
    _part_of(w, node, record.harness)
    if record.ends:
        add(node, t("fromPin"), _contact(w, record.harness, record.ends[0]))
    if len(record.ends) > 1:
        add(node, t("toPin"), _contact(w, record.harness, record.ends[-1]))
    for end in record.ends[1:-1]:
        add(node, t("intermediatePin"), _contact(w, record.harness, end))
    for segment in dict.fromkeys(record.route):
        add(node, t("routedThrough"), w.iri("segment", record.harness, segment))
    if record.cable is not None:
        add(node, t("partOf"), w.iri("cable", record.harness, record.cable))
        add(node, t("cableName"), w.text(record.cable))
    if record.section_mm2 is not None:
        add(node, t("crossSectionMm2"), w.typed(record.section_mm2))
    if record.length_m is not None:
        add(node, t("lengthM"), w.typed(record.length_m))
    if record.diameter_m is not None:
        add(node, t("diameterM"), w.typed(record.diameter_m))
    if record.colour is not None:
        add(node, t("colour"), w.text(record.colour))
    if record.signal is not None:
        add(node, t("potentialName"), w.text(record.signal))


@map_record.register
def _(record: HarnessCable, w: TripleWriter, source_slug: str) -> None:
    node = w.iri("cable", record.harness, record.ident)
    w.add(node, t("type"), t("Cable"))
    w.add(node, t("label"), w.text(record.ident))
    w.add(node, t("sourceLine"), w.typed(record.line))
    _part_of(w, node, record.harness)
    if record.length_m is not None:
        w.add(node, t("lengthM"), w.typed(record.length_m))
    if record.diameter_m is not None:
        w.add(node, t("diameterM"), w.typed(record.diameter_m))


@map_record.register
def _(record: HarnessFixing, w: TripleWriter, source_slug: str) -> None:
    node = w.iri("fixing", record.harness, record.ident)
    w.add(node, t("type"), t("Fixing"))
    w.add(node, t("label"), w.text(record.ident))
    w.add(node, t("sourceLine"), w.typed(record.line))
    _part_of(w, node, record.harness)
    if record.description:
        w.add(node, t("description"), w.text(record.description))
    for name in record.nodes:
        w.add(node, t("placedOn"), w.iri("node", record.harness, name))
    for name in record.segments:
        w.add(node, t("placedOn"), w.iri("segment", record.harness, name))


@map_record.register
def _(record: HarnessProtection, w: TripleWriter, source_slug: str) -> None:
    node = w.iri("protection", record.harness, record.ident)
    w.add(node, t("type"), t("Protection"))
    w.add(node, t("label"), w.text(record.ident))
    w.add(node, t("sourceLine"), w.typed(record.line))
    _part_of(w, node, record.harness)
    if record.description:
        w.add(node, t("description"), w.text(record.description))
    if record.length_m is not None:
        w.add(node, t("lengthM"), w.typed(record.length_m))
    for name in record.segments:
        w.add(node, t("placedOn"), w.iri("segment", record.harness, name))
