"""Latency of the IEMA services (Table 1) on synthetic cabinets, against answering them with SPARQL.

For each size (number of wires) a complete synthetic cabinet is written with
``benchmarks/synthetic.py`` (``write_cabinet_files``: WRI, component models, terminal
schema, X3D scene, connection list, assignments) and, in this process:

1. **build**: ``KnowledgeGraph.build(manifest)`` in memory (reading, mapping, loading,
   and the derivation with its ``derived`` graph), wall-clock seconds;
2. **cell model**: what ``kg.cell_model()`` computes when its cache is empty,
   ``derive_cell(extract(kg))``, split into the SPARQL extraction and the derivation,
   and ``Session(model)``;
3. **services**: every IEMA service of ``cadkg.services.table``, timed per call
   with ``time.perf_counter_ns`` over many calls with varied parameters (random
   components, random terminal blocks, random detected poses, random wire numbers;
   the cursor services walk their cursor and are rewound, untimed, at the end):

   * ``call()``: ``services.call(session, name, params)`` with text parameters, as the
     CLI and the ROS adapter pass them (conversion and checks included);
   * direct: the plain function of ``cadkg.usecases.iema.answers`` or the ``Session`` method;
   * SPARQL baseline: the same answer obtained from the store with ``kg.query(...)``
     and a bound parameter (the derived graph holds the poses, pins, clusters, rails
     and routes), plus the Python that shapes the rows into that answer. The baseline
     answers are checked against the services' on the first calls; a difference is
     printed as a note.

The table per size gives p50 and p95 in µs and the ratio SPARQL p50 / ``call()`` p50:
what answering from the in-process cell model buys. The targets are printed beside
the figures (p50 ≤ 250 µs for every service at 100k wires; build ≤ 10 s at 100k).
Nothing is asserted.

Usage::

    python benchmarks/bench_services.py [--sizes 1000,10000,100000] [--calls 2000]
                                        [--baseline-calls 200] [--budget 10] [--seed 0]
    python benchmarks/bench_services.py --quick    # a smoke test (its settings: --help)
"""

from __future__ import annotations

import argparse
import gc
import math
import os
import platform
import random
import re
import shutil
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pyoxigraph import NamedNode

sys.path.insert(0, str(Path(__file__).resolve().parent))

import cadkg.usecases.iema.cursors as cursors
from cadkg.geometry.poses import Pose
from cadkg.graph import KnowledgeGraph
from cadkg.services.session import Session
from cadkg.services.table import call, services_for
from cadkg.usecases.iema import answers as iema
from cadkg.usecases.iema.derive.cabinet import CellModel
from quick import add_quick, parse
from synthetic import CabinetFiles, write_cabinet_files

TARGET_P50_US = 250.0
TARGET_BUILD_SECONDS = 10.0
TARGET_WIRES = 100_000
FIRST_CHECKS = 20  # baseline answers compared with the services' on this many calls

Key = Any


# -- the SPARQL baseline ---------------------------------------------------------------


def _pose_pattern(var: str) -> str:
    return (
        f"?{var} ck:tx ?{var}_x ; ck:ty ?{var}_y ; ck:tz ?{var}_z ; "
        f"ck:qx ?{var}_qx ; ck:qy ?{var}_qy ; ck:qz ?{var}_qz ; ck:qw ?{var}_qw ."
    )


def _pose_vars(*names: str) -> str:
    return " ".join(f"?{v}_{c}" for v in names for c in ("x", "y", "z", "qx", "qy", "qz", "qw"))


def _pose(row: dict[str, Any], var: str) -> Pose | None:
    if row.get(f"{var}_x") is None:
        return None
    return Pose(
        (float(row[f"{var}_x"]), float(row[f"{var}_y"]), float(row[f"{var}_z"])),
        (float(row[f"{var}_qx"]), float(row[f"{var}_qy"]), float(row[f"{var}_qz"]), float(row[f"{var}_qw"])),
    )


# How the baseline queries are written, after trying the obvious forms on pyoxigraph 0.5:
# - the bound variable (?label, ?idx, ?num, ?rl) is not projected, so kg.query binds it
#   with a trailing VALUES block, which is joined first; substituting a projected
#   variable filters after the evaluation and is several times slower here;
# - no OPTIONAL: pyoxigraph evaluates the optional part over the whole store and then
#   left-joins it (one pin's pose as OPTIONAL costs 20 ms at 1k wires and grows with the
#   store). Attributes that may be absent come as rows of their own from UNION branches
#   that share the bound variables (?kind tells them apart) and Python puts them together.
Q_COMPONENT = f"""SELECT DISTINCT ?kind {_pose_vars("q")} ?dx ?dy ?dz WHERE {{
  ?c ck:label ?label ; a ck:Component .
  {{ ?c ck:originalPose ?q . {_pose_pattern("q")} BIND("original" AS ?kind) }}
  UNION {{ ?c ck:cornerPose ?q . {_pose_pattern("q")} BIND("corner" AS ?kind) }}
  UNION {{ ?c ck:targetPose ?q . {_pose_pattern("q")} BIND("target" AS ?kind) }}
  UNION {{ ?c ck:xDim ?dx ; ck:yDim ?dy ; ck:zDim ?dz BIND("dimensions" AS ?kind) }} }}"""

Q_REFERENCE = f"""SELECT DISTINCT ?kind {_pose_vars("q")} WHERE {{
  ?c ck:label ?label ; a ck:Component .
  {{ ?c ck:cornerPose ?q BIND("corner" AS ?kind) }} UNION {{ ?c ck:targetPose ?q BIND("target" AS ?kind) }}
  {_pose_pattern("q")} }}"""

Q_PINS = f"""SELECT DISTINCT ?p ?name ?kind ?level ?ipos {_pose_vars("q")} WHERE {{
  ?c ck:label ?label ; a ck:Component . ?p ck:pinOf ?c ; ck:pinName ?name .
  {{ ?p ck:level ?level BIND("level" AS ?kind) }}
  UNION {{ ?p ck:screwPose ?q . {_pose_pattern("q")} BIND("screw" AS ?kind) }}
  UNION {{ ?p ck:holePose ?q . {_pose_pattern("q")} BIND("hole" AS ?kind) }}
  UNION {{ ?p ck:missingPinData ?missing BIND("missing" AS ?kind) }}
  UNION {{ ?p ck:onItem ?item . ?item ck:blockPosition ?ipos BIND("item" AS ?kind) }} }}"""

Q_PIN_WIRES = """SELECT DISTINCT ?p ?kind ?w ?wire ?idx ?term WHERE {
  ?c ck:label ?label ; a ck:Component . ?p ck:pinOf ?c .
  { ?w ck:fromPin ?p ; ck:wireNumber ?wire ; ck:sequenceIndex ?idx ; ck:originTermination ?term
    BIND("from" AS ?kind) }
  UNION { ?w ck:toPin ?p ; ck:wireNumber ?wire ; ck:sequenceIndex ?idx ; ck:destinationTermination ?term
    BIND("to" AS ?kind) } }"""

Q_CONNECTIONS = """SELECT DISTINCT ?w ?wire ?idx ?path ?end ?ql ?name ?kind ?level WHERE {
  ?c ck:label ?label ; a ck:Component . ?p ck:pinOf ?c .
  { ?w ck:fromPin ?p } UNION { ?w ck:toPin ?p }
  ?w a ck:Wire ; ck:wireNumber ?wire ; ck:sequenceIndex ?idx .
  GRAPH ?g { ?w a ck:Wire } ?g ck:sourcePath ?path .
  { ?w ck:fromPin ?e BIND("origin" AS ?end) } UNION { ?w ck:toPin ?e BIND("destination" AS ?end) }
  ?e ck:pinName ?name ; ck:pinOf ?ec . ?ec ck:label ?ql .
  { ?e ck:pinName ?n2 BIND("pin" AS ?kind) } UNION { ?e ck:level ?level BIND("level" AS ?kind) }
  UNION { ?e ck:missingPinData ?missing BIND("missing" AS ?kind) } }"""

Q_TERMINAL = f"""SELECT DISTINCT ?kind ?pos ?minx ?miny ?maxx ?maxy {_pose_vars("q")} WHERE {{
  ?b ck:label ?label ; a ck:TerminalBlock .
  {{ ?b ck:cornerPose ?q . {_pose_pattern("q")} BIND("corner" AS ?kind) }}
  UNION {{ ?b ck:hasTerminalItem ?item . ?item ck:blockPosition ?pos ; ck:minX ?minx ; ck:minY ?miny ;
           ck:maxX ?maxx ; ck:maxY ?maxy BIND("item" AS ?kind) }} }}"""

Q_CLUSTERS = """SELECT DISTINCT ?cl ?axis ?p ?name ?kind ?level ?x ?y ?z WHERE {
  ?c ck:label ?label ; a ck:Component . ?cl ck:clusterOf ?c ; ck:clusterAxis ?axis ; ck:hasMember ?p .
  ?p ck:pinName ?name .
  { ?p ck:level ?level BIND("level" AS ?kind) }
  UNION { ?p ck:holePose ?q . ?q ck:tx ?x ; ck:ty ?y ; ck:tz ?z BIND("hole" AS ?kind) }
  UNION { ?p ck:screwPose ?q . ?q ck:tx ?x ; ck:ty ?y ; ck:tz ?z BIND("screw" AS ?kind) } }"""

Q_WIRE_END = """SELECT DISTINCT ?wire ?path ?label ?name ?kind ?level WHERE {{
  GRAPH ?list {{ ?w ck:sequenceIndex ?idx ; ck:wireNumber ?wire ; {end} ?p }} ?list ck:sourcePath ?path .
  ?p ck:pinOf ?c ; ck:pinName ?name . ?c ck:label ?label .
  {{ ?p ck:pinName ?n2 BIND("pin" AS ?kind) }} UNION {{ ?p ck:level ?level BIND("level" AS ?kind) }}
  UNION {{ ?p ck:missingPinData ?missing BIND("missing" AS ?kind) }} }}"""
Q_WIRE_ORIGIN = Q_WIRE_END.format(end="ck:fromPin")
Q_WIRE_DESTINATION = Q_WIRE_END.format(end="ck:toPin")
Q_END_POSE = """SELECT DISTINCT {pose_vars} WHERE {{
  GRAPH ?list {{ ?w ck:sequenceIndex ?idx ; {end} ?p }} ?p ck:pinOf ?c . ?c ck:originalPose ?q . {pose} }}"""
Q_ORIGIN_POSE = Q_END_POSE.format(end="ck:fromPin", pose_vars=_pose_vars("q"), pose=_pose_pattern("q"))
Q_DESTINATION_POSE = Q_END_POSE.format(end="ck:toPin", pose_vars=_pose_vars("q"), pose=_pose_pattern("q"))

Q_WIRE_BOTH = f"""SELECT DISTINCT ?wire ?end ?label ?name ?kind ?level {_pose_vars("q")} WHERE {{
  GRAPH ?list {{ ?w ck:sequenceIndex ?idx ; ck:wireNumber ?wire }}
  {{ ?w ck:fromPin ?p BIND("origin" AS ?end) }} UNION {{ ?w ck:toPin ?p BIND("destination" AS ?end) }}
  ?p ck:pinName ?name ; ck:pinOf ?c . ?c ck:label ?label .
  {{ ?p ck:pinName ?n2 BIND("pin" AS ?kind) }} UNION {{ ?p ck:level ?level BIND("level" AS ?kind) }}
  UNION {{ ?p ck:screwPose ?q . {_pose_pattern("q")} BIND("screw" AS ?kind) }}
  UNION {{ ?p ck:holePose ?q . {_pose_pattern("q")} BIND("hole" AS ?kind) }} }}"""

Q_ROUTE = f"""SELECT ?kind ?ducts ?i {_pose_vars("q")} WHERE {{ GRAPH ?list {{ ?w ck:sequenceIndex ?idx }}
  {{ ?w ck:ductPath ?ducts BIND("ducts" AS ?kind) }}
  UNION {{ ?r ck:routeOf ?w ; ck:hasWaypoint ?pt . ?pt ck:sequenceIndex ?i ; ck:hasPose ?q .
           {_pose_pattern("q")} BIND("point" AS ?kind) }} }} ORDER BY ?i"""

Q_WIRE_NUMBER = """SELECT ?idx ?path WHERE {
  ?w ck:wireNumber ?num ; a ck:Wire ; ck:sequenceIndex ?idx .
  GRAPH ?g { ?w a ck:Wire } ?g ck:sourcePath ?path } ORDER BY ?idx LIMIT 1"""

Q_RAIL = f"""SELECT DISTINCT ?kind ?c ?label ?x ?dx ?dy ?dz {_pose_vars("q")} WHERE {{
  ?rail ck:label ?rl ; a ck:Rail .
  {{ ?rail ck:originalPose ?q . {_pose_pattern("q")} BIND("rail" AS ?kind) }}
  UNION {{ ?c ck:onRail ?rail ; ck:railPosition ?x ; ck:label ?label ; ck:originalPose ?q ;
           ck:xDim ?dx ; ck:yDim ?dy ; ck:zDim ?dz . {_pose_pattern("q")} BIND("component" AS ?kind) }}
  UNION {{ ?c ck:onRail ?rail . ?a ck:assignmentOf ?c ; ck:assignedTo ck:human BIND("human" AS ?kind) }}
}} ORDER BY ?x"""


def _r(values: Sequence[float] | None) -> tuple[float, ...] | None:
    return None if values is None else tuple(round(v, 7) + 0.0 for v in values)


def _rp(pose: Pose | None) -> tuple[float, ...] | None:
    return None if pose is None else _r(pose.position)


def _by_kind(rows: Sequence[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    return {row["kind"]: row for row in rows}


def _named(name: str, level: str | None) -> str:
    return name if level is None else f"{name}:{level}"


@dataclass
class PinRows:
    """One pin put together from its rows: name, level, poses, block position, flags."""

    iri: str
    name: str
    level: str | None = None
    screw: Pose | None = None
    hole: Pose | None = None
    position: int | None = None
    missing: bool = False

    @property
    def key(self) -> str:
        return _named(self.name, self.level)


class Baseline:
    """Each service's answer from the store with SPARQL; returns the key the check compares."""

    def __init__(self, kg: KnowledgeGraph) -> None:
        self.kg = kg
        # A list position means something within one connection list: its named graph.
        self.graphs = {
            row["path"]: NamedNode(row["g"])
            for row in kg.query("SELECT ?g ?path WHERE { ?g a ck:SourceFile ; ck:sourcePath ?path }")
        }

    def _pins(self, label: str) -> dict[str, PinRows]:
        pins: dict[str, PinRows] = {}
        for row in self.kg.query(Q_PINS, label=label):
            pin = pins.setdefault(row["p"], PinRows(row["p"], row["name"]))
            kind = row["kind"]
            if kind == "level":
                pin.level = row["level"]
            elif kind == "screw":
                pin.screw = _pose(row, "q")
            elif kind == "hole":
                pin.hole = _pose(row, "q")
            elif kind == "item":
                pin.position = row["ipos"]
            else:
                pin.missing = True
        return {pin.key: pin for pin in pins.values()}

    def _original(self, label: str) -> Pose | None:
        row = _by_kind(self.kg.query(Q_COMPONENT, label=label).rows).get("original")
        return _pose(row, "q") if row else None

    def cad_service(self, label: str) -> Key:
        rows = _by_kind(self.kg.query(Q_COMPONENT, label=label).rows)
        original = _pose(rows["original"], "q") if "original" in rows else None
        pins = self._pins(label)
        return _rp(original), sorted((name, _rp(p.screw), _rp(p.hole)) for name, p in pins.items())

    def full_cad_service(self, label: str) -> Key:
        original = self._original(label)
        wires: dict[str, dict[str, Any]] = {}
        for row in self.kg.query(Q_CONNECTIONS, label=label):
            wire = wires.setdefault(row["w"], {"row": row})
            end = wire.setdefault(row["end"], {"label": row["ql"], "name": row["name"], "level": None})
            if row["kind"] == "level":
                end["level"] = row["level"]
            elif row["kind"] == "missing":
                end["missing"] = True
        connections = []
        for wire in sorted(wires.values(), key=lambda w: (w["row"]["path"], w["row"]["idx"])):
            origin, destination = wire["origin"], wire["destination"]
            connections.append(
                (
                    wire["row"]["wire"],
                    wire["row"]["idx"] - 1,  # list positions count from 0
                    f"{origin['label']}:{_named(origin['name'], origin['level'])}",
                    f"{destination['label']}:{_named(destination['name'], destination['level'])}",
                    bool(origin.get("missing") or destination.get("missing")),
                )
            )
        return _rp(original), connections

    def get_item_screw_service(self, label: str, detected: Pose) -> Key:
        original = self._original(label)
        if original is None:
            return None
        shift = detected * original.inverse()
        pins = self._pins(label)
        ends: dict[str, tuple[int, bool, str, str]] = {}
        for row in self.kg.query(Q_PIN_WIRES, label=label):
            # The first wire in list order (its origin end before its destination end), as ends_of.
            end = (row["idx"], row["kind"] == "to", row["wire"], row["term"])
            ends[row["p"]] = min(end, ends.get(row["p"], end))
        answer = []
        for name, pin in sorted(pins.items()):
            screw, hole = pin.screw or pin.hole, pin.hole or pin.screw
            if screw is None or hole is None:
                continue
            _, _, wire, termination = ends.get(pin.iri, (0, False, None, None))
            answer.append((name, _rp(shift * screw), _rp(shift * hole), wire, termination))
        return answer

    def get_terminal_data(self, label: str) -> Key:
        rows = self.kg.query(Q_TERMINAL, label=label).rows
        corner = next((r for r in rows if r["kind"] == "corner"), None)
        if corner is None:
            return None
        items = [r for r in rows if r["kind"] == "item"]
        length = sum(float(r["maxx"] - r["minx"]) for r in items)
        height = max((float(r["maxy"] - r["miny"]) for r in items), default=0.0)
        pins = self._pins(label)
        order = sorted(
            (name for name, p in pins.items() if p.screw or p.hole),
            key=lambda name: (pins[name].position or 0, _natural(name)),
        )
        return _rp(_pose(corner, "q")), order, round(length, 7), round(height, 7)

    def cluster_service(self, label: str) -> Key:
        axes: dict[str, str] = {}
        members: dict[tuple[str, str], dict[str, Any]] = {}
        for row in self.kg.query(Q_CLUSTERS, label=label):
            axes[row["cl"]] = row["axis"]
            member = members.setdefault((row["cl"], row["p"]), {"name": row["name"], "level": None})
            if row["kind"] == "level":
                member["level"] = row["level"]
            else:
                member[row["kind"]] = _r([float(row["x"]), float(row["y"]), float(row["z"])])
        clusters: dict[str, list[tuple[str, tuple[float, ...] | None]]] = {}
        for (cluster, _), m in members.items():
            point = m.get("hole", m.get("screw"))
            clusters.setdefault(cluster, []).append((_named(m["name"], m["level"]), point))
        return sorted((axes[c], tuple(sorted(points))) for c, points in clusters.items())

    def cad_reference(self, label: str) -> Key:
        rows = _by_kind(self.kg.query(Q_REFERENCE, label=label).rows)
        if "target" not in rows:
            return None
        return _rp(_pose(rows["target"], "q")), _rp(_pose(rows["corner"], "q"))

    def full_connection_provider(self, source: str, position: int, occupancy: bool) -> Key:
        at = {"idx": position, "list": self.graphs[source]}
        rows = _by_kind(self.kg.query(Q_WIRE_DESTINATION if occupancy else Q_WIRE_ORIGIN, **at).rows)
        row = rows["pin"]
        level = rows["level"]["level"] if "level" in rows else None
        # The end's component pose is its approach (target) pose, as the reference node gives it.
        target = _by_kind(self.kg.query(Q_REFERENCE, label=row["label"]).rows).get("target")
        pose = _pose(target, "q") if target else None
        return row["wire"], row["label"], _named(row["name"], level), "missing" in rows, _rp(pose)

    def group_connection_provider(self, source: str, position: int) -> Key:
        at = {"idx": position, "list": self.graphs[source]}
        ends: dict[str, dict[str, Any]] = {}
        for row in self.kg.query(Q_WIRE_BOTH, **at):
            end = ends.setdefault(row["end"], {"row": row, "level": None})
            kind = row["kind"]
            if kind == "level":
                end["level"] = row["level"]
            elif kind != "pin":
                end[kind] = _pose(row, "q")
        ducts, keypoints = "", []
        for row in self.kg.query(Q_ROUTE, **at):
            if row["kind"] == "ducts":
                ducts = row["ducts"]
            else:
                keypoints.append(_rp(_pose(row, "q")))
        origin, destination = ends["origin"], ends["destination"]
        return (
            origin["row"]["wire"],
            f"{origin['row']['label']}:{_named(origin['row']['name'], origin['level'])}",
            f"{destination['row']['label']}:{_named(destination['row']['name'], destination['level'])}",
            _rp(origin.get("screw") or origin.get("hole")),
            _rp(destination.get("screw") or destination.get("hole")),
            ducts,
            keypoints,
        )

    def reset_to_connection_list(self, number: str) -> Key:
        rows = self.kg.query(Q_WIRE_NUMBER, num=number).rows
        return rows[0]["idx"] - 1 if rows else None  # a list position counts from 0

    def rail_scanner(self, rail: str) -> Key:
        rows = self.kg.query(Q_RAIL, rl=rail).rows
        start = next((_pose(r, "q") for r in rows if r["kind"] == "rail"), None)
        human = {r["c"] for r in rows if r["kind"] == "human"}
        members = [
            (r["label"], _rp(_pose(r, "q"))) for r in rows if r["kind"] == "component" and r["c"] not in human
        ]
        return _rp(start), members


def _natural(text: str) -> tuple[tuple[int, int | str], ...]:
    """``"10:a"`` sorts after ``"2:b"``: digits compare as numbers, as the services sort pins."""
    return tuple((0, int(t)) if t.isdigit() else (1, t) for t in re.findall(r"\d+|\D+", text))


# -- the same keys from the services' answers -------------------------------------------------


def service_key(name: str, result: Any) -> Key:
    """The part of a service's answer the baseline reproduces, in the baseline's shape."""
    if name == "cad_service":
        pins = sorted((p.pin, _rp(p.screw), _rp(p.hole)) for p in result.pins)
        return _rp(result.original_pose), pins
    if name == "full_cad_service":
        connections = [
            (c.wire, c.list_position, c.origin, c.destination, c.missing_pin_data) for c in result.connections
        ]
        return _rp(result.original_pose), connections
    if name == "get_item_screw_service":
        data = zip(result.pins, result.screws, result.holes, result.screw_data, strict=True)
        return sorted((p, _rp(s), _rp(h), d.wire, d.termination) for p, s, h, d in data)
    if name == "get_terminal_data":
        return _rp(result.terminal_start), list(result.pins), round(result.length, 7), round(result.height, 7)
    if name == "cluster_service":
        return sorted(
            (c.axis, tuple(sorted(zip(c.pins, (_r(p) for p in c.points), strict=True))))
            for c in (*result.horizontal, *result.vertical)
        )
    if name == "cad_reference":
        return _rp(result.target_pose), _rp(result.corner_pose)
    if name == "full_connection_provider":
        return result.wire, result.label, result.pin, result.missing_pin_data, _rp(result.component_pose)
    if name == "group_connection_provider":
        return (
            result.wire,
            f"{result.origin.label}:{result.origin.pin}",
            f"{result.destination.label}:{result.destination.pin}",
            _rp(result.origin.screw or result.origin.hole),
            _rp(result.destination.screw or result.destination.hole),
            result.wire_path,
            [_rp(k) for k in result.path_keypoints],
        )
    if name == "rail_scanner":
        return _rp(result.rail_start), [
            (label, _rp(pose))
            for label, pose in zip(result.components_label, result.component_poses, strict=True)
        ]
    return None


# -- the calls of one size ---------------------------------------------------------------------


@dataclass
class Case:
    """One service: N calls through ``call()``, directly, and through the SPARQL baseline."""

    name: str
    via_call: Callable[[int], Any]
    direct: Callable[[int], Any]
    baseline: Callable[[int], Key] | None
    before: Callable[[int], None] | None = None  # untimed, before each call (rewinds cursors)
    check: Callable[[int], Any] | None = None  # the service answer the baseline is compared with


def _labelled(rng: random.Random, labels: Sequence[str], count: int) -> list[tuple[str, str]]:
    """(label as a client writes it, the label) pairs: some with the ``=-`` structure prefix."""
    picked = [labels[rng.randrange(len(labels))] for _ in range(count)]
    return [("=-" + label if rng.random() < 0.5 else label, label) for label in picked]


def _pose_text(pose: Pose) -> str:
    return ",".join(repr(v) for v in (*pose.position, *pose.orientation))


def build_cases(
    kg: KnowledgeGraph, model: CellModel, session: Session, count: int, rng: random.Random
) -> list[Case]:
    """Every IEMA service with ``count`` varied parameter sets."""
    baseline = Baseline(kg)
    rails = {r.label for r in model.rails}
    placed = [
        label
        for label, g in model.components.items()
        if g.original is not None and label not in rails and g.rail is not None
    ]
    blocks = [label for label in placed if model.components[label].terminal_block]
    robot = [s for s in model.steps if s.performer == "robot"]
    labels = _labelled(rng, placed, count)
    block_labels = _labelled(rng, blocks, count)
    detected = []
    for _, label in labels:
        original = model.components[label].original
        assert original is not None
        shift = Pose(
            (rng.uniform(-0.003, 0.003), rng.uniform(-0.003, 0.003), rng.uniform(-0.001, 0.001)),
            _small_turn(rng.uniform(-0.05, 0.05)),
        )
        detected.append(original * shift)
    numbers = [robot[rng.randrange(len(robot))] for _ in range(count)]
    cases: list[Case] = []

    def label_case(name: str, fn: Callable[[CellModel, str], Any], pairs: list[tuple[str, str]]) -> None:
        cases.append(
            Case(
                name,
                lambda i: call(session, name, {"label": pairs[i][0]}),
                lambda i: fn(model, pairs[i][0]),
                lambda i: getattr(baseline, name)(pairs[i][1]),
                check=lambda i: fn(model, pairs[i][0]),
            )
        )

    label_case("cad_service", iema.cad_service, labels)
    label_case("full_cad_service", iema.full_cad_service, labels)
    cases.append(
        Case(
            "get_item_screw_service",
            lambda i: call(
                session,
                "get_item_screw_service",
                {"label": labels[i][0], "detected_pose": _pose_text(detected[i])},
            ),
            lambda i: iema.get_item_screw_service(model, labels[i][0], detected[i]),
            lambda i: baseline.get_item_screw_service(labels[i][1], detected[i]),
            check=lambda i: iema.get_item_screw_service(model, labels[i][0], detected[i]),
        )
    )
    cases.append(
        Case(
            "get_item_screw_targets",
            lambda i: call(
                session,
                "get_item_screw_targets",
                {"label": labels[i][0], "cad_pose": _pose_text(detected[i])},
            ),
            lambda i: iema.get_item_screw_targets(model, labels[i][0], detected[i]),
            None,
        )
    )
    label_case("get_terminal_data", iema.get_terminal_data, block_labels)
    label_case("cluster_service", iema.cluster_service, labels)
    label_case("cad_reference", iema.cad_reference, labels)

    # Connection cursors: "call" and "direct" walk their own client's cursor; the baseline
    # walks the same robot steps by list position. Each is rewound (untimed) at the end.
    def rewind_connections(client: str) -> Callable[[int], None]:
        def before(i: int) -> None:
            if cursors.state(session, client).step >= len(robot):
                cursors.reset_connection_list(session, client)

        return before

    def at_step(i: int, per_step: int) -> tuple[str, int]:
        step = robot[(i // per_step) % len(robot)]
        # The graph counts a list's rows from 1 (ck:sequenceIndex); list positions count from 0.
        return step.source, step.position + 1

    both = rewind_connections("call")

    def before_both(i: int) -> None:
        both(i)
        rewind_connections("direct")(i)

    def full_check(i: int) -> Any:
        cursors.reset_connection_list(session, "check")
        state = cursors.state(session, "check")
        state.step = (i // 2) % len(robot)
        return cursors.full_connection_provider(session, i % 2 == 1, "check")

    cases.append(
        Case(
            "full_connection_provider",
            lambda i: call(
                session, "full_connection_provider", {"occupancy": "true" if i % 2 else "false"}, "call"
            ),
            lambda i: cursors.full_connection_provider(session, i % 2 == 1, "direct"),
            lambda i: baseline.full_connection_provider(*at_step(i, 2), i % 2 == 1),
            before_both,
            full_check,
        )
    )

    def group_check(i: int) -> Any:
        cursors.state(session, "check").step = i % len(robot)
        return cursors.group_connection_provider(session, "check")

    cases.append(
        Case(
            "group_connection_provider",
            lambda i: call(session, "group_connection_provider", {}, "call"),
            lambda i: cursors.group_connection_provider(session, "direct"),
            lambda i: baseline.group_connection_provider(*at_step(i, 1)),
            before_both,
            group_check,
        )
    )
    cases.append(
        Case(
            "reset_connection_list",
            lambda i: call(session, "reset_connection_list", {}, "call"),
            lambda i: cursors.reset_connection_list(session, "direct"),
            None,
        )
    )

    def reset_to_check(i: int) -> Any:
        cursors.reset_to_connection_list(session, float(numbers[i].wire), client="check")
        step = cursors.state(session, "check").step
        return robot[step].position

    cases.append(
        Case(
            "reset_to_connection_list",
            lambda i: call(session, "reset_to_connection_list", {"data": numbers[i].wire}, "call"),
            lambda i: cursors.reset_to_connection_list(session, float(numbers[i].wire), client="direct"),
            lambda i: baseline.reset_to_connection_list(numbers[i].wire),
            check=reset_to_check,
        )
    )

    cases.append(
        Case(
            "connection_provider_service",
            lambda i: call(session, "connection_provider_service", {}, "call"),
            lambda i: cursors.connection_provider_service(session, None, "direct"),
            None,
            before_both,
        )
    )
    cases.append(
        Case(
            "gearbox_display",
            lambda i: call(session, "gearbox_display", {}, "call"),
            lambda i: cursors.gearbox_display(session, "direct"),
            None,
        )
    )

    rail_labels = [r.label for r in model.rails]

    def rewind_rails(i: int) -> None:
        for client in ("call", "direct"):
            if cursors.state(session, client).rail >= len(rail_labels):
                cursors.reset_rail_scanner(session, client)

    def rail_check(i: int) -> Any:
        cursors.state(session, "check").rail = i % len(rail_labels)
        return cursors.rail_scanner(session, "check")

    cases.append(
        Case(
            "rail_scanner",
            lambda i: call(session, "rail_scanner", {}, "call"),
            lambda i: cursors.rail_scanner(session, "direct"),
            lambda i: baseline.rail_scanner(rail_labels[i % len(rail_labels)]),
            rewind_rails,
            rail_check,
        )
    )
    cases.append(
        Case(
            "reset_rail_scanner",
            lambda i: call(session, "reset_rail_scanner", {}, "call"),
            lambda i: cursors.reset_rail_scanner(session, "direct"),
            None,
        )
    )
    missing = {s.name for s in services_for("iema")} - {c.name for c in cases}
    if missing:
        raise SystemExit(f"bench_services.py does not know how to call: {', '.join(sorted(missing))}")
    return cases


def _small_turn(angle: float) -> tuple[float, float, float, float]:
    return (0.0, 0.0, math.sin(angle / 2), math.cos(angle / 2))


# -- measuring ---------------------------------------------------------------------------------


@dataclass
class Samples:
    """Latencies of one way of calling one service, in ns; the first call is kept apart."""

    first_ns: int = 0
    ns: list[int] = field(default_factory=list)

    def p(self, q: float) -> float:
        ordered = sorted(self.ns)
        if not ordered:
            return math.nan
        rank = (len(ordered) - 1) * q / 100
        low = math.floor(rank)
        high = min(low + 1, len(ordered) - 1)
        return (ordered[low] + (ordered[high] - ordered[low]) * (rank - low)) / 1000


def measure(
    run: Callable[[int], Any],
    count: int,
    before: Callable[[int], None] | None = None,
    budget: float | None = None,
) -> Samples:
    """``count`` timed calls ``run(0)`` … ``run(count - 1)`` (fewer once ``budget`` seconds pass).

    A first call ``run(0)`` goes before them and is kept apart (``first_ns``): it pays for the
    lazy indexes a session builds on first use.
    """
    samples = Samples()
    clock = time.perf_counter_ns
    if before is not None:
        before(0)
    started = clock()
    run(0)
    samples.first_ns = clock() - started
    deadline = time.perf_counter() + budget if budget else math.inf
    for i in range(count):
        if before is not None:
            before(i)
        started = clock()
        run(i)
        samples.ns.append(clock() - started)
        if time.perf_counter() > deadline:
            break
    return samples


@dataclass
class ServiceResult:
    name: str
    via_call: Samples
    direct: Samples
    baseline: Samples | None
    mismatches: int = 0
    checked: int = 0


@dataclass
class SizeResult:
    wires: int
    components: int
    rails: int
    triples: int
    generate_s: float
    build_s: float
    extract_s: float
    derive_s: float
    session_ms: float
    rss_mib: float | None
    peak_mib: float | None
    services: list[ServiceResult]
    notes: list[str] = field(default_factory=list)


def rss_mib(field: str = "VmRSS") -> float | None:
    """This process's resident set (``VmRSS``) or its peak so far (``VmHWM``), in MiB."""
    try:
        for line in Path("/proc/self/status").read_text(encoding="ascii").splitlines():
            if line.startswith(field + ":"):
                return int(line.split()[1]) / 1024
    except (OSError, ValueError):
        pass
    return None


def check_baseline(case: Case, count: int) -> tuple[int, int]:
    """(differences, comparisons) between the baseline's and the service's answers."""
    if case.baseline is None or case.check is None:
        return 0, 0
    differences = 0
    for i in range(count):
        ours = case.check(i)
        expected = ours if case.name == "reset_to_connection_list" else service_key(case.name, ours)
        if case.baseline(i) != expected:
            differences += 1
    return differences, count


def measure_size(wires: int, workdir: Path, options: Options) -> SizeResult:
    from cadkg.usecases.iema.derive.cabinet import derive_cell
    from cadkg.usecases.iema.derive.extract import extract

    print(f"{wires} wires: generating", file=sys.stderr, flush=True)
    started = time.perf_counter()
    files: CabinetFiles = write_cabinet_files(workdir / f"cabinet-{wires}", wires, options.seed)
    generate_s = time.perf_counter() - started
    print(f"{wires} wires: building", file=sys.stderr, flush=True)
    started = time.perf_counter()
    kg = KnowledgeGraph.build(files.manifest)
    build_s = time.perf_counter() - started
    rss, peak = rss_mib(), rss_mib("VmHWM")
    triples = len(kg)
    model = kg.cell_model()  # derived by the build, cached
    started = time.perf_counter()
    inputs = extract(kg)
    extract_s = time.perf_counter() - started
    started = time.perf_counter()
    fresh = derive_cell(inputs)
    derive_s = time.perf_counter() - started
    notes = []
    if len(fresh.steps) != len(model.steps) or fresh.components.keys() != model.components.keys():
        notes.append("a fresh derive_cell(extract(kg)) differs from kg.cell_model()")
    del fresh, inputs
    started = time.perf_counter()
    session = Session(model)
    session_ms = (time.perf_counter() - started) * 1000
    cases = build_cases(kg, model, session, options.calls, random.Random(options.seed + wires))
    results = []
    for case in cases:
        print(f"{wires} wires: {case.name}", file=sys.stderr, flush=True)
        via_call = measure(case.via_call, options.calls, case.before)
        direct = measure(case.direct, options.calls, case.before)
        base = None
        differences = checked = 0
        if case.baseline is not None:
            base = measure(case.baseline, options.baseline_calls, None, options.budget)
            differences, checked = check_baseline(case, min(FIRST_CHECKS, options.baseline_calls))
        results.append(ServiceResult(case.name, via_call, direct, base, differences, checked))
        if differences:
            notes.append(
                f"`{case.name}`: the SPARQL baseline's answer differs from the service's "
                f"on {differences} of {checked} checked calls"
            )
    result = SizeResult(
        wires,
        files.components,
        len(model.rails),
        triples,
        generate_s,
        build_s,
        extract_s,
        derive_s,
        session_ms,
        rss,
        peak,
        results,
        notes,
    )
    kg.close()
    del kg, model, session, cases
    gc.collect()
    shutil.rmtree(files.manifest.parent, ignore_errors=True)
    return result


# -- reporting ---------------------------------------------------------------------------------


def table(header: Sequence[str], rows: Sequence[Sequence[str]], left: int = 1) -> str:
    """A Markdown table; the first ``left`` columns are text (left aligned)."""
    align = [":---" if i < left else "---:" for i in range(len(header))]
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(align) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def us(value: float) -> str:
    return "—" if math.isnan(value) else f"{value:,.1f}" if value < 100 else f"{value:,.0f}"


def build_table(results: Sequence[SizeResult]) -> str:
    header = [
        "wires",
        "components",
        "rails",
        "triples",
        "generate s",
        "build s",
        "cell_model(): extract s",
        "derive s",
        "Session() ms",
        "RSS after build MiB",
        "peak RSS so far MiB",
        f"target build ≤ {TARGET_BUILD_SECONDS:g} s at {TARGET_WIRES:,}",
    ]
    rows = []
    for r in results:
        verdict = "—"
        if r.wires == TARGET_WIRES:
            verdict = "met" if r.build_s <= TARGET_BUILD_SECONDS else "**not met**"
        rows.append(
            [
                f"{r.wires:,}",
                f"{r.components:,}",
                f"{r.rails:,}",
                f"{r.triples:,}",
                f"{r.generate_s:.2f}",
                f"{r.build_s:.2f}",
                f"{r.extract_s:.2f}",
                f"{r.derive_s:.2f}",
                f"{r.session_ms:.1f}",
                "—" if r.rss_mib is None else f"{r.rss_mib:,.0f}",
                "—" if r.peak_mib is None else f"{r.peak_mib:,.0f}",
                verdict,
            ]
        )
    return table(header, rows, left=0)


def service_table(r: SizeResult) -> str:
    header = [
        "service",
        "calls",
        "call() p50 µs",
        "call() p95 µs",
        "direct p50 µs",
        "direct p95 µs",
        "first call µs",
        "SPARQL calls",
        "SPARQL p50 µs",
        "SPARQL p95 µs",
        "SPARQL / call() p50",
        f"target p50 ≤ {TARGET_P50_US:g} µs",
    ]
    rows = []
    for s in r.services:
        p50 = s.via_call.p(50)
        verdict = "met" if p50 <= TARGET_P50_US else "**not met**"
        if r.wires != TARGET_WIRES:
            verdict = f"({verdict})"
        base = s.baseline
        rows.append(
            [
                f"`{s.name}`",
                f"{len(s.via_call.ns):,}",
                us(p50),
                us(s.via_call.p(95)),
                us(s.direct.p(50)),
                us(s.direct.p(95)),
                us(s.via_call.first_ns / 1000),
                f"{len(base.ns):,}" if base else "—",
                us(base.p(50)) if base else "—",
                us(base.p(95)) if base else "—",
                f"{base.p(50) / p50:,.0f}×" if base and p50 > 0 else "—",
                verdict,
            ]
        )
    return table(header, rows)


def environment() -> str:
    import pyoxigraph

    import cadkg

    return (
        f"Python {platform.python_version()} on {platform.system()} {platform.machine()}, "
        f"{os.cpu_count()} CPU cores; cadkg {cadkg.__version__}, pyoxigraph {pyoxigraph.__version__}"
    )


def report(results: Sequence[SizeResult], options: Options) -> str:
    parts = [
        "## Environment",
        environment(),
        "## Build and cell model (in memory, this process)",
        build_table(results),
    ]
    for r in results:
        parts += [
            f"## Services at {r.wires:,} wires",
            f"{options.calls:,} calls per service and way (after one first call, shown apart); SPARQL "
            f"baseline: up to {options.baseline_calls:,} calls or {options.budget:g} s. Verdicts in "
            f"brackets are for sizes other than {TARGET_WIRES:,} wires, where the target does not apply.",
            service_table(r),
        ]
        if r.notes:
            parts.append("\n".join(f"- {note}" for note in r.notes))
    return "\n\n".join(parts) + "\n"


# -- command line ------------------------------------------------------------------------------


@dataclass(frozen=True)
class Options:
    sizes: tuple[int, ...]
    calls: int
    baseline_calls: int
    budget: float
    seed: int


def parse_args(argv: Sequence[str] | None) -> Options:
    parser = argparse.ArgumentParser(description="Latency of the IEMA services against a SPARQL baseline.")
    parser.add_argument(
        "--sizes",
        default="1000,10000,100000",
        help="comma-separated numbers of wires (default 1000,10000,100000)",
    )
    parser.add_argument(
        "--calls", type=int, default=2000, help="timed calls per service and way (default 2000)"
    )
    parser.add_argument(
        "--baseline-calls",
        type=int,
        default=200,
        help="timed SPARQL baseline calls per service (default 200)",
    )
    parser.add_argument(
        "--budget", type=float, default=10.0, help="seconds of SPARQL baseline calls per service (default 10)"
    )
    parser.add_argument(
        "--seed", type=int, default=0, help="seed of the cabinet and of the parameters (default 0)"
    )
    add_quick(parser, sizes="300", calls=200, baseline_calls=20, budget=2.0)
    args = parse(parser, argv)
    return Options(
        sizes=tuple(int(s.replace("_", "")) for s in args.sizes.split(",") if s.strip()),
        calls=max(1, args.calls),
        baseline_calls=max(1, args.baseline_calls),
        budget=args.budget,
        seed=args.seed,
    )


def main(argv: Sequence[str] | None = None) -> int:
    options = parse_args(argv)
    workdir = Path(tempfile.mkdtemp(prefix="cadkg-bench-services-"))
    started = time.perf_counter()
    try:
        results = [measure_size(wires, workdir, options) for wires in options.sizes]
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    print(report(results, options))
    print(f"(run took {time.perf_counter() - started:.0f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
