"""ELIMCO records → triples: cable list and route design files.

IRIs join across the files: ``cable/A4351-1669`` is the same node whether the cable list
names it (as the cable of its cores), cable_info.xml (with its connectors and length)
or path_info.xml (as the cable a route is of); ``component/A1UZ3B`` is the connector the
cable list's contacts ``pin/A1UZ3B/5`` belong to and the one cable_info ends a cable at;
``bench-pin/A1UZ3B`` is the pin placed at that connector on the workbench. Pin positions
are poses in the frame ``drawing`` (the 2D drawing's origin), in metres.
"""

from __future__ import annotations

from cadkg.ingest.eplan.labels import PinRef
from cadkg.mapping.dispatch import map_record
from cadkg.mapping.nodes import cable_node, connector_node, frame_node, named_node, pin_node
from cadkg.mapping.writer import TripleWriter, term, write_pose
from cadkg.usecases.elimco.cable_list import CableListHarness, CableListWire, ShieldTermination
from cadkg.usecases.elimco.route_design import BenchPinSpec, RouteCable, RoutePathSpec

__all__ = ["DRAWING_FRAME"]

DRAWING_FRAME = "drawing"
"""The frame of the route-design drawing: its origin is the CAD origin, often metres from the pins."""

t = term


def _contact(w: TripleWriter, connector: str, contact: str) -> str:
    connector_node(w, connector)
    return pin_node(w, PinRef(connector, contact, None, f"{connector}:{contact}"))


def _harness_cable(w: TripleWriter, name: str, harness: str) -> str:
    """The cable ``name``, part of the harness ``harness`` (said once, whichever of its wires
    and shields comes first)."""
    cable = cable_node(w, name)
    if w.once(cable + "#harness"):
        w.add(cable, t("partOf"), w.iri("harness", harness))
    return cable


@map_record.register
def _(record: CableListHarness, w: TripleWriter, source_slug: str) -> None:
    node = named_node(w, "harness", record.part_number, "Harness")
    details = [
        f"{what} {value}" for what, value in (("revision", record.revision), ("index", record.index)) if value
    ]
    if details:
        w.add(node, t("description"), w.text(", ".join(details)))
    w.add(node, t("sourceLine"), w.typed(record.line))


@map_record.register
def _(record: CableListWire, w: TripleWriter, source_slug: str) -> None:
    cable = _harness_cable(w, record.cable, record.harness)
    wire = named_node(w, "wire", record.name, "Wire", by="wireNumber")
    w.add(wire, t("partOf"), cable)
    for name, end in (("fromPin", record.origin), ("toPin", record.destination)):
        assert end.contact is not None  # the reader rejects a wire end without a contact
        w.add(wire, t(name), _contact(w, end.connector, end.contact))
    if record.length_m is not None:
        w.add(wire, t("lengthM"), w.typed(record.length_m))
    if record.wire_type is not None:
        w.add(wire, t("cableName"), w.text(record.wire_type))
    for name, part in (
        ("originTermination", record.origin.contact_part),
        ("destinationTermination", record.destination.contact_part),
    ):
        if part is not None:
            w.add(wire, t(name), w.text(part))
    w.add(wire, t("sourceLine"), w.typed(record.rows[0]))


@map_record.register
def _(record: ShieldTermination, w: TripleWriter, source_slug: str) -> None:
    cable = _harness_cable(w, record.cable, record.harness)
    node = named_node(w, "shield", record.name, "ShieldTermination")
    w.add(node, t("partOf"), cable)
    w.add(node, t("terminatesAt"), _contact(w, record.connector, record.contact))
    if record.shield is not None:
        w.add(node, t("description"), w.text(f"shield {record.shield}"))
    w.add(node, t("sourceLine"), w.typed(record.rows[0]))


@map_record.register
def _(record: BenchPinSpec, w: TripleWriter, source_slug: str) -> None:
    node = w.iri("bench-pin", record.name)
    add, typed = w.add, w.typed
    add(node, t("type"), t("BenchPin"))
    add(node, t("label"), w.text(record.name))
    add(node, t("role"), w.text(record.role))
    add(node, t("benchX"), typed(record.x))
    add(node, t("benchY"), typed(record.y))
    add(node, t("isDoublePin"), typed(record.double))
    if record.double_distance_m is not None:
        add(node, t("doublePinDistanceM"), typed(record.double_distance_m))
    if record.connector_distance_m is not None:
        add(node, t("connectorDistanceM"), typed(record.connector_distance_m))
    pose = w.iri("pose", "bench-pin", record.name)
    add(node, t("hasPose"), pose)
    write_pose(w, pose, (record.x_m, record.y_m, 0.0), (0.0, 0.0, 0.0, 1.0), frame_node(w, DRAWING_FRAME))
    add(node, t("sourceLine"), typed(record.line))


@map_record.register
def _(record: RouteCable, w: TripleWriter, source_slug: str) -> None:
    cable = cable_node(w, record.name)
    w.add(cable, t("initialConnector"), connector_node(w, record.initial))
    w.add(cable, t("finalConnector"), connector_node(w, record.final))
    if record.length_m is not None:
        w.add(cable, t("lengthM"), w.typed(record.length_m))
    w.add(cable, t("sourceLine"), w.typed(record.line))


@map_record.register
def _(record: RoutePathSpec, w: TripleWriter, source_slug: str) -> None:
    index = str(record.index)
    path = w.iri("route", index)
    cable = cable_node(w, record.cable)
    w.add(path, t("type"), t("RoutePath"))
    w.add(path, t("label"), w.text(index))
    w.add(path, t("routeOf"), cable)
    if record.total_length_m is not None:
        w.add(path, t("lengthM"), w.typed(record.total_length_m))
    if record.cable_length_m is not None:
        w.add(cable, t("lengthM"), w.typed(record.cable_length_m))
    w.add(path, t("sourceLine"), w.typed(record.line))
    pins = record.pins
    for position, pin in enumerate(pins, start=1):
        stop = w.iri("waypoint", index, str(position))
        w.add(path, t("hasWaypoint"), stop)
        w.add(stop, t("type"), t("Waypoint"))
        w.add(stop, t("sequenceIndex"), w.typed(position))
        # The pin's name on the stop too: the pin may be missing from pin_info.
        w.add(stop, t("label"), w.text(pin))
        w.add(stop, t("atKeypoint"), w.iri("bench-pin", pin))
        role = "initial" if position == 1 else "final" if position == len(pins) else "intermediate"
        w.add(stop, t("role"), w.text(role))
        if position > 1 and record.segment_lengths_m:
            w.add(stop, t("lengthM"), w.typed(record.segment_lengths_m[position - 2]))
