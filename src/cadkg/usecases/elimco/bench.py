"""The ELIMCO workbench as the services see it: bench pins, cables and routes, read from the graph.

:func:`elimco_model` builds :class:`ElimcoModel` with SPARQL over the graph (the route
design files and the cable list as mapped by :mod:`cadkg.usecases.elimco.mapping`); the
geometry the services answer with is computed here:

* the **centroid frame** ``pins_centroid``: at the mean of the nominal positions of all
  pins, axes parallel to the drawing's. The drawing's origin is the CAD origin, metres
  from the workbench; the centroid is on it.
* the **route direction** at a pin: the sum of the unit vectors of the route segments
  arriving at and leaving the pin, over every route through it. A pin's pose has its x
  axis along that direction and z along the drawing's normal, so the two pins of a double
  pin lie on the pose's y axis, ``± double_distance / 2`` from it, and the wires pass
  between them.
* the **connector distance**: an initial or final pin stands at its connector's point in
  the drawing; the physical pin is set that far from it, towards the pin next to it along
  the route (the sum of the unit vectors towards its neighbours when several routes
  start or end there).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any

from cadkg.geometry.frames import quaternion_from_rpy
from cadkg.geometry.poses import Pose, Vec3
from cadkg.ingest.text import small_integer

__all__ = [
    "CENTROID_FRAME",
    "DRAWING_FRAME",
    "BenchPin",
    "CableRecord",
    "ElimcoModel",
    "RouteRecord",
    "consistency_problems",
    "elimco_model",
    "frame_id",
]

DRAWING_FRAME = "drawing"
CENTROID_FRAME = "pins_centroid"
_EPSILON = 1e-12


@dataclass(frozen=True)
class BenchPin:
    """A pin as placed in pin_info.xml: nominal ``position`` in the drawing frame (metres)."""

    name: str
    role: str
    position: Vec3
    double: bool
    double_distance: float | None
    connector_distance: float | None


@dataclass(frozen=True)
class RouteRecord:
    """The route of one cable over the pins, lengths in metres."""

    index: int
    cable: str
    pins: tuple[str, ...]
    segment_lengths: tuple[float, ...]
    total_length: float | None


@dataclass(frozen=True)
class CableRecord:
    """A cable: its connectors (cable_info, else its cores' ends), length, cores from the cable list."""

    name: str
    initial_connector: str
    final_connector: str
    length: float | None
    wires: tuple[str, ...]


@dataclass(frozen=True)
class ElimcoModel:
    """Pins (in pin_info order), cables and routes of the served graph, and what does not fit."""

    pins: dict[str, BenchPin]
    cables: dict[str, CableRecord]
    routes: dict[int, RouteRecord]
    placed_by_manifest: frozenset[str] = frozenset()
    problems: tuple[str, ...] = ()
    _directions: dict[str, Vec3 | None] = field(default_factory=dict, init=False, repr=False, compare=False)

    @property
    def centroid(self) -> Vec3:
        """The mean nominal position of the pins in the drawing frame; the origin when there are none."""
        if not self.pins:
            return (0.0, 0.0, 0.0)
        n = len(self.pins)
        xs, ys, zs = zip(*(p.position for p in self.pins.values()), strict=True)
        return (math.fsum(xs) / n, math.fsum(ys) / n, math.fsum(zs) / n)

    def route_of(self, cable: str) -> RouteRecord | None:
        """The route of ``cable``; a path index (``"2"``) also names its route."""
        for route in self.routes.values():
            if route.cable == cable:
                return route
        index = small_integer(cable)
        return None if index is None else self.routes.get(index)

    def direction(self, name: str) -> Vec3 | None:
        """The unit route direction at a pin (see the module notes); None off every route."""
        if name not in self._directions:
            total = (0.0, 0.0, 0.0)
            for route in self.routes.values():
                if name not in route.pins:
                    continue
                at = route.pins.index(name)
                if at > 0:
                    total = _add(total, self._unit_between(route.pins[at - 1], name))
                if at + 1 < len(route.pins):
                    total = _add(total, self._unit_between(name, route.pins[at + 1]))
            self._directions[name] = _normalized(total)
        return self._directions[name]

    def connector_direction(self, name: str) -> Vec3 | None:
        """Unit vector from a pin towards its neighbours on the routes it starts or ends; None if none."""
        total = (0.0, 0.0, 0.0)
        for route in self.routes.values():
            if len(route.pins) < 2:
                continue
            if route.pins[0] == name:
                total = _add(total, self._unit_between(name, route.pins[1]))
            if route.pins[-1] == name:
                total = _add(total, self._unit_between(name, route.pins[-2]))
        return _normalized(total)

    def is_route_end(self, name: str) -> bool:
        return any(r.pins[0] == name or r.pins[-1] == name for r in self.routes.values())

    def pose(self, name: str, connector_distance: float | None, *, in_centroid: bool) -> tuple[Pose, float]:
        """The pose of a pin and how far it was moved from its connector's point.

        ``connector_distance`` > 0 applies to every route end; otherwise each pin's own
        distance from pin_info is used.
        """
        pin = self.pins[name]
        distance = connector_distance if connector_distance and connector_distance > 0 else None
        distance = distance if distance is not None else (pin.connector_distance or 0.0)
        x, y, z = pin.position
        moved = 0.0
        if distance > 0 and self.is_route_end(name):
            towards = self.connector_direction(name)
            if towards is not None:
                x, y, moved = x + distance * towards[0], y + distance * towards[1], distance
        if in_centroid:
            cx, cy, cz = self.centroid
            x, y, z = x - cx, y - cy, z - cz
        heading = self.direction(name)
        yaw = math.atan2(heading[1], heading[0]) if heading is not None else 0.0
        return Pose((x, y, z), quaternion_from_rpy(0.0, 0.0, yaw)), moved

    def _unit_between(self, start: str, end: str) -> Vec3:
        a, b = self.pins.get(start), self.pins.get(end)
        if a is None or b is None:
            return (0.0, 0.0, 0.0)
        (ax, ay, az), (bx, by, bz) = a.position, b.position
        return _normalized((bx - ax, by - ay, bz - az)) or (0.0, 0.0, 0.0)


def _add(a: Vec3, b: Vec3) -> Vec3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _normalized(v: Vec3) -> Vec3 | None:
    norm = math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)
    if norm < _EPSILON:
        return None
    return (v[0] / norm, v[1] / norm, v[2] / norm)


def frame_id(pin: str) -> str:
    """The tf frame of a pin: ``pin_`` and its name, characters a frame id cannot hold as ``_``."""
    return "pin_" + re.sub(r"[^A-Za-z0-9_.-]", "_", pin)


def consistency_problems(
    pins: set[str], cables: dict[str, tuple[str, str]] | None, routes: list[tuple[int, str, tuple[str, ...]]]
) -> list[str]:
    """What does not fit between pins, cables (name → initial, final connector) and routes.

    A route that names a pin no pin file places, or a cable the cable file does not
    list, cannot be served; a route whose ends are not its cable's connectors is
    reported too. ``cables`` is None when no cable file is loaded.
    """
    problems = []
    for index, cable, route_pins in routes:
        unplaced = [p for p in route_pins if p not in pins]
        if unplaced:
            problems.append(f"path {index} names pin(s) {', '.join(unplaced)} that no pin_info places")
        if cables is None:
            continue
        ends = cables.get(cable)
        if ends is None:
            problems.append(f"path {index} is of cable {cable}, which cable_info does not list")
        elif ends != (route_pins[0], route_pins[-1]):
            problems.append(
                f"path {index} runs {route_pins[0]} to {route_pins[-1]}, "
                f"but cable {cable} runs {ends[0]} to {ends[1]}"
            )
    return problems


def elimco_model(kg: Any) -> ElimcoModel:
    """Read the bench pins, cables and routes of a graph (a :class:`~cadkg.graph.KnowledgeGraph`).

    Raises
    ------
    QueryError
        When the graph cannot be queried.
    """
    pins: dict[str, BenchPin] = {}
    for row in kg.query(
        f"""SELECT DISTINCT ?name ?role ?x ?y ?z ?double ?dd ?cd ?line WHERE {{
              ?pin a ck:BenchPin ; ck:label ?name ; ck:hasPose ?pose .
              ?pose ck:parentFrame/ck:label "{DRAWING_FRAME}" ; ck:tx ?x ; ck:ty ?y ; ck:tz ?z .
              OPTIONAL {{ ?pin ck:role ?role }} OPTIONAL {{ ?pin ck:isDoublePin ?double }}
              OPTIONAL {{ ?pin ck:doublePinDistanceM ?dd }} OPTIONAL {{ ?pin ck:connectorDistanceM ?cd }}
              OPTIONAL {{ ?pin ck:sourceLine ?line }} }}
            ORDER BY ?line ?name"""
    ):
        name = str(row["name"])
        if name not in pins:
            pins[name] = BenchPin(
                name=name,
                role=str(row["role"] or ""),
                position=(float(row["x"]), float(row["y"]), float(row["z"])),
                double=bool(row["double"]),
                double_distance=None if row["dd"] is None else float(row["dd"]),
                connector_distance=None if row["cd"] is None else float(row["cd"]),
            )

    stops: dict[int, dict[int, tuple[str, float | None]]] = {}
    route_cable: dict[int, str] = {}
    route_total: dict[int, float | None] = {}
    for row in kg.query(
        """SELECT DISTINCT ?index ?cable ?total ?seq ?pin ?length WHERE {
              ?route a ck:RoutePath ; ck:label ?index ; ck:routeOf/ck:label ?cable ; ck:hasWaypoint ?stop .
              ?stop ck:sequenceIndex ?seq ; ck:label ?pin .
              OPTIONAL { ?route ck:lengthM ?total } OPTIONAL { ?stop ck:lengthM ?length } }"""
    ):
        index = int(row["index"])
        route_cable[index] = str(row["cable"])
        route_total[index] = None if row["total"] is None else float(row["total"])
        stops.setdefault(index, {})[int(row["seq"])] = (
            str(row["pin"]),
            None if row["length"] is None else float(row["length"]),
        )
    routes = {}
    for index in sorted(stops):
        ordered = [stops[index][seq] for seq in sorted(stops[index])]
        lengths = tuple(length for _, length in ordered[1:] if length is not None)
        routes[index] = RouteRecord(
            index=index,
            cable=route_cable[index],
            pins=tuple(pin for pin, _ in ordered),
            segment_lengths=lengths if len(lengths) == len(ordered) - 1 else (),
            total_length=route_total[index],
        )

    cables, stated, problems = _cables(kg, routes)
    placed = frozenset(
        str(row["name"])
        for row in kg.query(
            """SELECT DISTINCT ?name WHERE { ?frame a ck:Frame ; ck:label ?name ; ck:hasPose ?pose .
                 ?pose ck:parentFrame ?parent . VALUES ?name { "drawing" "pins_centroid" } }"""
        )
    )
    problems += consistency_problems(set(pins), stated, [(r.index, r.cable, r.pins) for r in routes.values()])
    return ElimcoModel(pins, cables, routes, placed, tuple(problems))


def _cables(
    kg: Any, routes: dict[int, RouteRecord]
) -> tuple[dict[str, CableRecord], dict[str, tuple[str, str]] | None, list[str]]:
    """Cables by name, the connectors cable_info states (None without one), and length conflicts."""
    lengths: dict[str, set[float]] = {}
    ends: dict[str, tuple[str, str]] = {}
    names: list[str] = []
    for row in kg.query(
        """SELECT DISTINCT ?name ?length ?initial ?final ?line WHERE { ?cable a ck:Cable ; ck:label ?name .
             OPTIONAL { ?cable ck:lengthM ?length } OPTIONAL { ?cable ck:sourceLine ?line }
             OPTIONAL { ?cable ck:initialConnector/ck:label ?initial ; ck:finalConnector/ck:label ?final } }
           ORDER BY ?line ?name"""
    ):
        name = str(row["name"])
        if name not in names:
            names.append(name)
        if row["length"] is not None:
            lengths.setdefault(name, set()).add(round(float(row["length"]), 9))
        if row["initial"] is not None:
            ends[name] = (str(row["initial"]), str(row["final"]))
    cores: dict[str, list[tuple[str, str, str]]] = {}
    for row in kg.query(
        """SELECT DISTINCT ?name ?wire ?from ?to WHERE {
             ?w a ck:Wire ; ck:partOf ?cable ; ck:wireNumber ?wire . ?cable a ck:Cable ; ck:label ?name .
             OPTIONAL { ?w ck:fromPin/ck:pinOf/ck:label ?from }
             OPTIONAL { ?w ck:toPin/ck:pinOf/ck:label ?to } }
           ORDER BY ?wire"""
    ):
        cores.setdefault(str(row["name"]), []).append((str(row["wire"]), str(row["from"]), str(row["to"])))
    problems = []
    route_order = {r.cable: r.index for r in routes.values()}
    first_seen = {name: position for position, name in enumerate(names)}
    names.sort(key=lambda n: (route_order.get(n, 1 << 30), first_seen[n]))
    cables = {}
    for name in names:
        found = sorted(lengths.get(name, ()))
        if len(found) > 1:
            problems.append(f"cable {name} has {len(found)} lengths: {', '.join(f'{v:g} m' for v in found)}")
        wires = cores.get(name, [])
        # The connectors as cable_info states them, else the ends of the cable's route,
        # else those of its first core in the cable list.
        route = next((r for r in routes.values() if r.cable == name), None)
        if name in ends:
            initial, final = ends[name]
        elif route is not None:
            initial, final = route.pins[0], route.pins[-1]
        elif wires:
            initial, final = wires[0][1], wires[0][2]
        else:
            initial, final = "", ""
        cables[name] = CableRecord(
            name=name,
            initial_connector=initial,
            final_connector=final,
            length=found[0] if found else None,
            wires=tuple(w for w, _, _ in wires),
        )
    return cables, (ends or None), problems
