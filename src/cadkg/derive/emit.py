"""The derived geometry as triples, for the ``{base}derived`` named graph."""

from __future__ import annotations

from collections.abc import Callable

from cadkg.derive.cabinet import CellModel
from cadkg.derive.geometry import Pose
from cadkg.ingest.mapping import TripleWriter, dimensions, term, write_pose

__all__ = ["derived_graph", "derived_ntriples"]


def derived_graph(model: CellModel) -> str:
    """The named graph the derived geometry of ``model`` is stored in: ``{base}derived``."""
    return model.base + "derived"


def _pose(w: TripleWriter, node: str, pose: Pose, frame: str) -> str:
    return write_pose(w, node, pose.position, pose.orientation, w.iri("frame", frame))


def derived_ntriples(model: CellModel, base: str, sink: Callable[[bytes], None] | None = None) -> bytes:
    """Poses, dimensions, pin frames, rails, clusters, keypoints and missing-data flags.

    With ``sink``, the N-Triples go to it in chunks as they are written (so a store can load
    one while the next is written) and what is returned is the rest.
    """
    w = TripleWriter(base)
    if sink is not None:
        w.stream_to(sink)
    t = term
    frame = model.frame
    # One flag per pin without model data and per wire with such an end: 280k at 100k wires.
    flag = f" {t('missingPinData')} {w.typed(True)} .\n"
    for label, g in model.components.items():
        w.maybe_flush()
        node = w.iri("component", label)
        for kind, pose in (("original", g.original), ("corner", g.corner), ("target", g.target)):
            if pose is not None:
                w.add(node, t(f"{kind}Pose"), _pose(w, w.iri("derived", label, kind), pose, g.frame))
        if g.dimensions is not None:
            dimensions(w, node, g.dimensions)
        if g.rail is not None and g.rail_position is not None:
            w.add(node, t("onRail"), w.iri("component", g.rail))
            w.add(node, t("railPosition"), w.typed(float(g.rail_position)))
        for pin in g.pins.values():
            pin_node = f"<{pin.iri}>" if pin.iri else w.iri("derived", label, "pin", pin.pin)
            if pin.iri is None:
                w.add(pin_node, t("type"), t("Pin"))
                w.add(pin_node, t("pinName"), w.text(pin.pin))
                w.add(pin_node, t("pinOf"), node)
                w.add(node, t("hasPin"), pin_node)
            for kind, pose in (("screw", pin.screw), ("hole", pin.hole)):
                if pose is not None:
                    pose_node = w.iri("derived", label, "pin", pin.pin, kind)
                    w.add(pin_node, t(f"{kind}Pose"), _pose(w, pose_node, pose, frame))
            if pin.missing:
                w.lines.append(pin_node + flag)
    for rail in model.rails:
        w.add(w.iri("component", rail.label), t("type"), t("Rail"))
    for label, (horizontal, vertical) in model.clusters.items():
        pins = model.components[label].pins
        for i, cluster in enumerate([*horizontal, *vertical]):
            node = w.iri("derived", label, "cluster", str(i + 1))
            w.add(node, t("type"), t("PinCluster"))
            w.add(node, t("clusterOf"), w.iri("component", label))
            w.add(node, t("clusterAxis"), w.text(cluster.axis))
            for name in cluster.pins:
                pin = pins[name]
                member = f"<{pin.iri}>" if pin.iri else w.iri("derived", label, "pin", name)
                w.add(node, t("hasMember"), member)
    for number, step in enumerate(model.steps, start=1):
        w.maybe_flush()
        wire = f"<{step.iri}>"
        if step.origin.missing or step.destination.missing:
            w.lines.append(wire + flag)
        if not step.keypoints:
            continue
        route = w.iri("derived", "route", str(number))
        w.add(route, t("type"), t("RoutePath"))
        w.add(route, t("routeOf"), wire)
        for i, pose in enumerate(step.keypoints, start=1):
            point = w.iri("derived", "route", str(number), str(i))
            w.add(route, t("hasWaypoint"), point)
            w.add(point, t("type"), t("Waypoint"))
            w.add(point, t("sequenceIndex"), w.typed(i))
            pose_node = w.iri("derived", "route", str(number), str(i), "pose")
            w.add(point, t("hasPose"), _pose(w, pose_node, pose, frame))
    return w.data()
