"""The robot's tasks in an IEMA cabinet: one per wire, who makes it and why, and what must be
made first because of where the wires leave their pins (docs/plan.md).

A wire landed on pin P is in the way of pin Q when its exit from P (the straight run from P's
hole towards the next point of its route, at most ``exit_length_m`` long) passes closer than the
tool's ``clearance_m`` to Q's approach corridor (``corridor_depth_m`` along the z axis of Q's
screw, the way the tool comes in). Then Q's wire comes first. Two levels of a terminal follow
from the same geometry: the level whose corridor the other's wire crosses goes first.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass
from typing import Any
from urllib.parse import unquote

import numpy as np

from cadkg.geometry.poses import Vec3
from cadkg.geometry.segments import close_pairs
from cadkg.mapping.writer import node_iri
from cadkg.plan.check import order_findings
from cadkg.plan.order import ASSIGNED
from cadkg.plan.rules import Rules, load_rules
from cadkg.plan.tasks import HUMAN, ROBOT, Decision, Precedence, Problem, Task
from cadkg.query.validate import Finding
from cadkg.usecases.iema.derive.cabinet import CadPin, CellModel, WireStep
from cadkg.usecases.iema.plan_scope import DEFAULT_RULES, SETTINGS, Scope, scope_decision, scope_of

__all__ = ["DEFAULT_RULES", "SETTINGS", "iema_problem", "order_check"]

_ENDS = ("origin", "destination")


@dataclass(frozen=True, slots=True)
class _Facts:
    """What the connection list says of a wire beyond the cell model: zones, section, line."""

    zones: tuple[str | None, str | None] = (None, None)
    section: float | None = None
    line: int | None = None


def _facts(kg: Any) -> dict[str, _Facts]:
    rows = kg.query(
        """SELECT ?w ?oz ?dz ?s ?line WHERE { ?w a ck:Wire .
             OPTIONAL { ?w ck:originZone ?oz } OPTIONAL { ?w ck:destinationZone ?dz }
             OPTIONAL { ?w ck:crossSectionMm2 ?s } OPTIONAL { ?w ck:sourceLine ?line } }"""
    )
    return {
        row["w"]: _Facts(
            (row["oz"], row["dz"]),
            float(row["s"]) if row["s"] is not None else None,
            int(row["line"]) if row["line"] is not None else None,
        )
        for row in rows
    }


def _point(pin: CadPin) -> Vec3 | None:
    pose = pin.screw or pin.hole
    return pose.position if pose is not None else None


def _assigned_by_kind(model: CellModel) -> dict[str, set[str]]:
    """The wire numbers, list positions and labels an assignment names, by kind."""
    found: dict[str, set[str]] = {"wire": set(), "operation": set(), "component": set()}
    for target in model.performers:
        for kind, names in found.items():
            prefix = f"{model.base}{kind}/"
            if target.startswith(prefix):
                names.add(unquote(target[len(prefix) :]))
    return found


def _assigned(model: CellModel, step: WireStep, by_kind: dict[str, set[str]], components: bool) -> str | None:
    """What an explicit assignment of the wire or its list position decided the wire by
    (``wire 1500.51``), or with ``components`` one of either end's component, if one did."""
    if not components:
        if step.iri in model.performers or step.wire in by_kind["wire"]:
            return f"wire {step.wire}"
        if str(step.position) in by_kind["operation"]:
            return f"operation {step.position}"
        return None
    for pin in (step.origin, step.destination):
        if pin.label in by_kind["component"]:
            return f"component {pin.label}"
    return None


def _performer(model: CellModel, step: WireStep) -> str:
    """Who an assignment gives the wire to: the derivation's answer, unless the cabinet rule
    gave it to a person there and a rules file's zones let it in here (then its components')."""
    if step.performer == HUMAN and step.reason:
        ends = (node_iri(model.base, "component", pin.label) for pin in (step.origin, step.destination))
        return HUMAN if any(model.performers.get(e) == HUMAN for e in ends) else ROBOT
    return step.performer


def _decide(
    model: CellModel, step: WireStep, facts: _Facts, rules: Rules, context: tuple[Scope, dict[str, set[str]]]
) -> tuple[Decision, tuple[str, ...]]:
    """Who makes the wire and why, and the tools it needs (origin's, then destination's).

    In the order of :mod:`cadkg.usecases.iema.robot_scope`: an assignment of the wire or its
    list position, the cabinet rule, an assignment of an end's component; then the robot's own
    rules (cross-section, tools, pin data)."""
    scope, by_kind = context
    tools, missing_tool = [], []
    default_tool = rules.robot.get("default_tool")
    for end, termination in zip(_ENDS, step.terminations, strict=True):
        tool = rules.tool_for(termination) if termination else default_tool
        if tool is None:
            missing_tool.append(f"{end} termination {termination or '(none given)'}")
        else:
            tools.append(str(tool))
    by_hand = _assigned(model, step, by_kind, components=False)
    scoped = scope_decision(scope, step, facts.zones[0]) if by_hand is None else None
    if scoped is not None:
        return scoped, ()
    by_hand = by_hand or _assigned(model, step, by_kind, components=True)
    if by_hand is not None:
        performer = _performer(model, step)
        who = "a person" if performer == HUMAN else "the robot"
        return Decision(performer, ASSIGNED, f"{by_hand} assigned to {who} by hand; wins over the rules"), (
            tuple(tools) if performer == ROBOT else ()
        )
    low, high = rules.number("cross_section_min_mm2", 0.0), rules.number("cross_section_max_mm2", 1e9)
    if facts.section is not None and not low <= facts.section <= high:
        return Decision(
            HUMAN,
            "cross-section",
            f"cross-section {facts.section:g} mm² is outside the robot's {low:g} to {high:g} mm² "
            f"({rules.source})",
        ), ()
    if missing_tool:
        served = ", ".join(f"{t.name}: {' '.join(t.serves)}" for t in rules.tools) or "none"
        return Decision(
            HUMAN, "termination", f"no tool serves the {' and the '.join(missing_tool)} (tools {served})"
        ), ()
    if step.missing:
        if rules.choice("missing_pin_data", ROBOT, (ROBOT, HUMAN)) == HUMAN:
            return Decision(HUMAN, "missing-pin-data", f"no pin data for {', '.join(step.missing)}"), ()
        return Decision(
            ROBOT,
            "missing-pin-data",
            f"no pin data for {', '.join(step.missing)}: the robot's, flagged for detection "
            "(missing_pin_data)",
        ), tuple(tools)
    section = f"{facts.section:g} mm², " if facts.section is not None else ""
    zones = "/".join(z or "-" for z in facts.zones)
    return Decision(
        ROBOT, "robot", f"zones {zones}, {section}tools {' then '.join(tools)}: every rule lets the robot"
    ), tuple(tools)


def iema_problem(kg: Any, rules: Rules) -> Problem:
    """The wires of the cabinet as tasks in list order, with decisions and precedence."""
    model: CellModel = kg.cell_model()
    facts = _facts(kg)
    numbers = Counter(step.wire for step in model.steps)
    context = (scope_of(kg, model, rules), _assigned_by_kind(model))
    tasks, decisions = [], {}
    for n, step in enumerate(model.steps):
        key = step.wire if numbers[step.wire] == 1 else f"{step.wire}@{step.position}"
        fact = facts.get(step.iri, _Facts())
        decision, tools = _decide(model, step, fact, rules, context)
        where = f"{step.source}:{fact.line}" if fact.line is not None else step.source
        tasks.append(
            Task(
                key,
                step.wire,
                "wire",
                n,
                tools,
                _point(step.origin),
                _point(step.destination),
                step.iri,
                where,
            )
        )
        decisions[key] = decision
    return Problem(tasks, decisions, _precedence(model, [t.key for t in tasks], rules))


def order_check(kg: Any) -> list[Finding]:
    """The connection lists' order against the default rules' precedence: a warning at the line
    of each wire listed before a wire that must be made first (the plan orders them)."""
    if not kg.cell_model().steps:
        return []
    problem = iema_problem(kg, load_rules(DEFAULT_RULES, "the iema default rules"))
    return order_findings(problem, "iema-order", "warning")


def _ends(model: CellModel) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per wire end (row ``2 n + end``, end 0 the origin): the position and orientation of the
    pin's screw (else hole), where the wire leaves it (its hole, else screw) and the next point
    of its route (the first duct keypoint, else the other end); NaN where a pin has no data."""
    rows = 2 * len(model.steps)
    frame, turn = np.full((rows, 3), np.nan), np.full((rows, 4), np.nan)
    leave, towards = np.full((rows, 3), np.nan), np.full((rows, 3), np.nan)
    for n, step in enumerate(model.steps):
        pins = (step.origin, step.destination)
        route = step.keypoints
        for end, pin in enumerate(pins):
            row = 2 * n + end
            pose = pin.screw or pin.hole
            if pose is None:
                continue
            frame[row], turn[row] = pose.position, pose.orientation
            leave[row] = (pin.hole or pin.screw or pose).position
            if len(route) >= 2:
                towards[row] = route[1 if end == 0 else -2].position
            elif (other := _point(pins[1 - end])) is not None:
                towards[row] = other
    return frame, turn, leave, towards


def _rotated(turn: np.ndarray, vz: float) -> np.ndarray:
    """(0, 0, vz) turned by each quaternion (x, y, z, w) of ``turn``, as :meth:`Pose.rotate` does."""
    x, y, z, w = turn.T
    cx, cy, cz = y * vz, -x * vz, w * vz
    return np.stack([2 * (y * cz - z * cy), 2 * (z * cx - x * cz), vz + 2 * (x * cy - y * cx)], axis=1)


def _precedence(model: CellModel, keys: list[str], rules: Rules) -> list[Precedence]:
    clearance = rules.number("clearance_m", 0.004)
    depth = rules.number("corridor_depth_m", 0.05)
    length = rules.number("exit_length_m", 0.1)
    frame, turn, leave, towards = _ends(model)
    # The approach corridors: from the screw along its z axis.
    placed = np.flatnonzero(~np.isnan(frame[:, 0]))
    filed = np.stack([frame[placed], frame[placed] + _rotated(turn[placed], depth)], axis=1)
    # The exits: from the hole towards the route's next point, at most ``length`` of it.
    gap = towards - leave
    norm = np.sqrt(gap[:, 0] * gap[:, 0] + gap[:, 1] * gap[:, 1] + gap[:, 2] * gap[:, 2])
    running = np.flatnonzero(norm >= 1e-9)  # NaN compares false: ends without data drop out
    scale = np.minimum(1.0, length / norm[running])[:, None]
    exits = np.stack([leave[running], leave[running] + gap[running] * scale], axis=1)
    number, corridor, gaps = close_pairs(exits, filed, clearance)
    # A wire's own pins and two wires on one pin give no edge.
    landed, blocked = running[number], placed[corridor]
    pins = _pin_numbers(model)
    keep = np.flatnonzero((landed // 2 != blocked // 2) & (pins[landed] != pins[blocked]))
    edges: dict[tuple[int, int], Precedence] = {}
    for k in keep.tolist():
        end, other = int(landed[k]), int(blocked[k])
        n, first = end // 2, other // 2
        if (first, n) in edges:
            continue
        leaving, pin = _pin(model, end), _pin(model, other)
        edges[(first, n)] = Precedence(
            keys[first],
            keys[n],
            f"wire {model.steps[n].wire} landed on {leaving.label}:{leaving.pin} passes "
            f"{float(gaps[k]) * 1000:.1f} mm from the approach of {pin.label}:{pin.pin} (clearance "
            f"{clearance * 1000:g} mm, depth {depth * 1000:g} mm): {model.steps[first].wire} first",
        )
    return [edges[k] for k in sorted(edges)]


def _pin(model: CellModel, row: int) -> CadPin:
    step = model.steps[row // 2]
    return step.destination if row % 2 else step.origin


def _pin_numbers(model: CellModel) -> np.ndarray:
    """Per wire end, a number shared by the ends on one pin."""
    numbers: dict[tuple[str, str], int] = {}
    return np.array(
        [
            numbers.setdefault((pin.label, pin.pin), len(numbers))
            for step in model.steps
            for pin in (step.origin, step.destination)
        ],
        dtype=np.int64,
    )
