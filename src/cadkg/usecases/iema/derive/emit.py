"""The derived geometry as triples, for the ``{base}derived`` named graph."""

from __future__ import annotations

from collections.abc import Callable

from cadkg.geometry.poses import Pose
from cadkg.mapping.nodes import dimensions
from cadkg.mapping.writer import TripleWriter, pose_lines, term
from cadkg.usecases.iema.derive.cabinet import CellModel

__all__ = ["derived_graph", "derived_ntriples"]


def derived_graph(model: CellModel) -> str:
    """The named graph the derived geometry of ``model`` is stored in: ``{base}derived``."""
    return model.base + "derived"


_POSE_OF = {kind: term(f"{kind}Pose") for kind in ("original", "corner", "target", "screw", "hole")}
# A route's waypoint, four lines before its pose's nine: {0} the route, {1} the waypoint,
# {2} its index (a typed literal), {3} its pose.
_WAYPOINT_LINES = (
    f"{{0}} {term('hasWaypoint')} {{1}} .\n{{1}} {term('type')} {term('Waypoint')} .\n"
    f"{{1}} {term('sequenceIndex')} {{2}} .\n{{1}} {term('hasPose')} {{3}} .\n"
).format


def derived_ntriples(model: CellModel, base: str, sink: Callable[[bytes], None] | None = None) -> bytes:
    """Poses, dimensions, pin frames, rails, clusters, keypoints and missing-data flags.

    With ``sink``, the N-Triples go to it in chunks as they are written (so a store can load
    one while the next is written) and what is returned is the rest.
    """
    w = TripleWriter(base)
    if sink is not None:
        w.stream_to(sink)
    t = term
    cell_frame = w.iri("frame", model.frame)
    frames = {model.frame: cell_frame}
    # One flag per pin without model data and per wire with such an end: 280k at 100k wires.
    flag = f" {t('missingPinData')} {w.typed(True)} .\n"
    for label, g in model.components.items():
        w.maybe_flush()
        node = w.iri("component", label)
        here = w.iri("derived", label)
        frame = frames.get(g.frame) or frames.setdefault(g.frame, w.iri("frame", g.frame))
        for kind, pose in (("original", g.original), ("corner", g.corner), ("target", g.target)):
            if pose is not None:
                _pose(w, node, kind, w.under(here, kind), pose, frame)
        if g.dimensions is not None:
            dimensions(w, node, g.dimensions)
        if g.rail is not None and g.rail_position is not None:
            w.add(node, t("onRail"), w.iri("component", g.rail))
            w.add(node, t("railPosition"), w.typed(float(g.rail_position)))
        for pin in g.pins.values():
            minted = w.under(here, "pin", pin.pin)
            pin_node = minted if pin.iri is None else f"<{pin.iri}>"
            if pin.iri is None:
                w.add(pin_node, t("type"), t("Pin"))
                w.add(pin_node, t("pinName"), w.text(pin.pin))
                w.add(pin_node, t("pinOf"), node)
                w.add(node, t("hasPin"), pin_node)
            for kind, pose in (("screw", pin.screw), ("hole", pin.hole)):
                if pose is not None:
                    _pose(w, pin_node, kind, w.under(minted, kind), pose, cell_frame)
            if pin.missing:
                w.lines.append(pin_node + flag)
    for rail in model.rails:
        w.add(w.iri("component", rail.label), t("type"), t("Rail"))
    for label, (horizontal, vertical) in model.clusters.items():
        pins = model.components[label].pins
        here = w.iri("derived", label)
        for i, cluster in enumerate([*horizontal, *vertical]):
            node = w.under(here, "cluster", str(i + 1))
            w.add(node, t("type"), t("PinCluster"))
            w.add(node, t("clusterOf"), w.iri("component", label))
            w.add(node, t("clusterAxis"), w.text(cluster.axis))
            for name in cluster.pins:
                pin = pins[name]
                member = f"<{pin.iri}>" if pin.iri else w.under(here, "pin", name)
                w.add(node, t("hasMember"), member)
    for number, step in enumerate(model.steps, start=1):
        w.maybe_flush()
        wire = f"<{step.iri}>"
        if step.origin.missing or step.destination.missing:
            w.lines.append(wire + flag)
        if step.reason:
            # A rule, not an assignment, gave the wire to its performer (robot_scope).
            w.add(wire, t("assignedTo"), t(step.performer))
            w.add(wire, t("assignmentReason"), w.text(step.reason))
        if not step.keypoints:
            continue
        route = w.iri("derived", "route", str(number))
        stem = route[:-1]
        w.add(route, t("type"), t("RoutePath"))
        w.add(route, t("routeOf"), wire)
        for i, pose in enumerate(step.keypoints, start=1):
            # As w.under(route, str(i)) mints it: a number needs no quoting.
            point = f"{stem}/{i}>"
            pose_node = f"{stem}/{i}/pose>"
            w.add_block(
                _WAYPOINT_LINES(route, point, w.typed(i), pose_node)
                + pose_lines(pose_node, pose.position, pose.orientation, cell_frame),
                13,
            )
    return w.data()


def _pose(w: TripleWriter, owner: str, kind: str, node: str, pose: Pose, frame: str) -> None:
    w.add_block(
        f"{owner} {_POSE_OF[kind]} {node} .\n" + pose_lines(node, pose.position, pose.orientation, frame), 10
    )
