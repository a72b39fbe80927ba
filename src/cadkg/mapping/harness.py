"""Harness records (KBL, VEC and harness text) → triples in the ontology's harness terms.

IRIs are scoped by the harness, whose identifier is the first part: ``harness/H``,
``connector/H/X1``, ``cavity/H/X1/3``, ``contact/H/X1/3`` (the contact in that cavity, a
``ck:Pin``), ``node/H/N``, ``segment/H/S``, ``wire/H/W``, ``routing/H/R``, ``cable/H/C``,
``fixing/H/F``, ``protection/H/P``, ``module/H/M``, ``module-family/H/F``,
``configuration/H/C``; the last parts are the records' idents (a KBL or VEC file's XML ids).
So two harnesses in one graph never share a node, and a re-read file gives the same IRIs.
Everything a harness holds is ``ck:partOf`` it (a core also of its cable), which is how the
harness queries find it whatever file it came from.
"""

from __future__ import annotations

from decimal import Decimal
from functools import lru_cache
from urllib.parse import quote

from cadkg.ingest.harness.records import (
    Harness,
    HarnessCable,
    HarnessConfiguration,
    HarnessConnector,
    HarnessFixing,
    HarnessModule,
    HarnessNode,
    HarnessProtection,
    HarnessSegment,
    HarnessWire,
    WireEnd,
)
from cadkg.mapping.dispatch import map_record
from cadkg.mapping.nodes import named_node
from cadkg.mapping.writer import TripleWriter, term

__all__: list[str] = []

t = term


@lru_cache(maxsize=1 << 16)
def _last_part(ident: str) -> str:
    """The last part of the IRI of the thing ``ident`` (as TripleWriter.iri encodes it)."""
    return quote(ident, safe="")


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
    node = named_node(w, "harness", record.ident, "Harness")
    w.add(node, t("fileFormat"), w.text(record.file_format))
    w.add(node, t("sourceLine"), w.typed(record.line))
    _description(w, node, record.description)


def _part(w: TripleWriter, kind: str, cls: str, harness: str, ident: str, label: str, line: int) -> str:
    """A thing harness ``harness`` holds: typed, labelled, with its line, and part of it."""
    node = w.iri(kind, harness, ident)
    w.add(node, t("type"), t(cls))
    w.add(node, t("label"), w.text(label))
    w.add(node, t("sourceLine"), w.typed(line))
    _part_of(w, node, harness)
    return node


def _modules(w: TripleWriter, node: str, harness: str, modules: tuple[str, ...]) -> None:
    for module in modules:
        w.add(node, t("inModule"), w.iri("module", harness, module))


def _placed_on(w: TripleWriter, node: str, kind: str, harness: str, names: tuple[str, ...]) -> None:
    """A fixing or a protection sits on the harness's nodes or segments ``names``."""
    for name in names:
        w.add(node, t("placedOn"), w.iri(kind, harness, name))


def _numbers(w: TripleWriter, node: str, **values: float | Decimal | None) -> None:
    """The given numeric properties (ontology term → value) that are not None."""
    for name, value in values.items():
        if value is not None:
            w.add(node, t(name), w.typed(value))


def _description(w: TripleWriter, node: str, text: str | None) -> None:
    if text:
        w.add(node, t("description"), w.text(text))


@map_record.register
def _(record: HarnessConnector, w: TripleWriter, source_slug: str) -> None:
    h = record.harness
    node = _part(w, "connector", "Connector", h, record.ident, record.label, record.line)
    w.add(w.iri("harness", h), t("hasConnector"), node)
    _description(w, node, record.description)
    _modules(w, node, h, record.modules)
    for name in record.cavities:
        cavity = w.iri("cavity", h, record.ident, name)
        w.add(cavity, t("type"), t("Cavity"))
        w.add(cavity, t("label"), w.text(name))
        w.add(node, t("hasCavity"), cavity)


@map_record.register
def _(record: HarnessNode, w: TripleWriter, source_slug: str) -> None:
    node = _part(w, "node", "HarnessNode", record.harness, record.ident, record.label, record.line)
    for connector in record.connectors:
        w.add(w.iri("connector", record.harness, connector), t("atNode"), node)
    if record.position is not None:
        x, y, z = record.position
        _numbers(w, node, nodeX=float(x), nodeY=float(y), nodeZ=float(z))
    _modules(w, node, record.harness, record.modules)


@map_record.register
def _(record: HarnessSegment, w: TripleWriter, source_slug: str) -> None:
    h = record.harness
    node = _part(w, "segment", "Segment", h, record.ident, record.label, record.line)
    w.add(node, t("segmentFrom"), w.iri("node", h, record.start))
    w.add(node, t("segmentTo"), w.iri("node", h, record.end))
    _numbers(
        w, node, lengthM=record.length_m, diameterM=record.diameter_m, bundleSectionMm2=record.section_mm2
    )
    if record.length_source is not None:
        w.add(node, t("lengthSource"), w.text(record.length_source))
    _modules(w, node, h, record.modules)


@map_record.register
def _(record: HarnessWire, w: TripleWriter, source_slug: str) -> None:
    h = record.harness
    node = _part(w, "wire", "Wire", h, record.ident, record.label, record.line)
    add = w.add
    add(node, t("wireNumber"), w.text(record.label))
    _modules(w, node, h, record.modules)
    if record.ends:
        add(node, t("fromPin"), _contact(w, h, record.ends[0]))
    if len(record.ends) > 1:
        add(node, t("toPin"), _contact(w, h, record.ends[-1]))
    for end in record.ends[1:-1]:
        add(node, t("intermediatePin"), _contact(w, h, end))
    for segment in dict.fromkeys(s for route in record.routes for s in route.segments):
        add(node, t("routedThrough"), w.iri("segment", h, segment))
    for route in record.routes:
        routing = _part(w, "routing", "Routing", h, route.ident, record.label, record.line)
        add(routing, t("routingOf"), node)
        # The path as the segments' last IRI parts: one literal, read back without a join per step.
        order = " ".join([_last_part(s) for s in route.segments])
        add(routing, t("segmentOrder"), w.text(order))
        _modules(w, routing, h, route.modules)
    if record.cable is not None:
        add(node, t("partOf"), w.iri("cable", h, record.cable))
        add(node, t("cableName"), w.text(record.cable))
    _numbers(
        w, node, crossSectionMm2=record.section_mm2, lengthM=record.length_m, diameterM=record.diameter_m
    )
    if record.colour is not None:
        add(node, t("colour"), w.text(record.colour))
    if record.signal is not None:
        add(node, t("potentialName"), w.text(record.signal))


@map_record.register
def _(record: HarnessCable, w: TripleWriter, source_slug: str) -> None:
    node = _part(w, "cable", "Cable", record.harness, record.ident, record.label, record.line)
    _numbers(w, node, lengthM=record.length_m, diameterM=record.diameter_m)
    _modules(w, node, record.harness, record.modules)


@map_record.register
def _(record: HarnessFixing, w: TripleWriter, source_slug: str) -> None:
    h = record.harness
    node = _part(w, "fixing", "Fixing", h, record.ident, record.label, record.line)
    _description(w, node, record.description)
    _modules(w, node, h, record.modules)
    _placed_on(w, node, "node", h, record.nodes)
    _placed_on(w, node, "segment", h, record.segments)


@map_record.register
def _(record: HarnessProtection, w: TripleWriter, source_slug: str) -> None:
    h = record.harness
    node = _part(w, "protection", "Protection", h, record.ident, record.label, record.line)
    _description(w, node, record.description)
    _numbers(w, node, lengthM=record.length_m)
    _modules(w, node, h, record.modules)
    _placed_on(w, node, "segment", h, record.segments)


@map_record.register
def _(record: HarnessModule, w: TripleWriter, source_slug: str) -> None:
    h = record.harness
    node = _part(w, "module", "HarnessModule", h, record.ident, record.label, record.line)
    w.add(node, t("moduleKind"), w.text(record.kind))
    _description(w, node, record.description)
    if record.control is not None:
        w.add(node, t("controlExpression"), w.text(record.control))
    if record.family is not None:
        family = w.iri("module-family", h, record.family)
        w.add(node, t("moduleFamily"), family)
        if w.once(family):
            w.add(family, t("type"), t("ModuleFamily"))
            w.add(family, t("label"), w.text(record.family_label or record.family))
            _description(w, family, record.family_description)
            _part_of(w, family, h)


@map_record.register
def _(record: HarnessConfiguration, w: TripleWriter, source_slug: str) -> None:
    h = record.harness
    node = _part(w, "configuration", "HarnessConfiguration", h, record.ident, record.label, record.line)
    for module in record.modules:
        w.add(node, t("configurationModule"), w.iri("module", h, module))
