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
from collections.abc import Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np

from cadkg.geometry.poses import Vec3
from cadkg.geometry.segments import close_pairs
from cadkg.plan.check import order_findings
from cadkg.plan.decision import Assignments, Decision, Performer, Rule, decide
from cadkg.plan.rules import Rules, load_rules
from cadkg.plan.tasks import Precedence, Problem, Task
from cadkg.query.validate import Finding
from cadkg.usecases.iema.derive.cabinet import CadPin, CellModel, WireStep
from cadkg.usecases.iema.plan_scope import DEFAULT_RULES, SETTINGS, Scope, scope_decision, scope_of
from cadkg.usecases.iema.robot_scope import WireFacts, assignments_of, names_of, parts_of

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


@dataclass(frozen=True, slots=True)
class _Wire:
    """A wire as the plan's rules see it: its step, the list's facts, and the tools its ends'
    terminations take (the origin's, then the destination's) with the ends no tool serves."""

    step: WireStep
    facts: _Facts
    judged: WireFacts
    tools: tuple[str, ...]
    missing_tool: tuple[str, ...]


def _wire(step: WireStep, facts: _Facts, rules: Rules) -> _Wire:
    tools, missing_tool = [], []
    default_tool = rules.robot.get("default_tool")
    for end, termination in zip(_ENDS, step.terminations, strict=True):
        tool = rules.tool_for(termination) if termination else default_tool
        if tool is None:
            missing_tool.append(f"{end} termination {termination or '(none given)'}")
        else:
            tools.append(str(tool))
    judged = WireFacts(step.wire, step.position, facts.zones, (step.origin.label, step.destination.label))
    return _Wire(step, facts, judged, tuple(tools), tuple(missing_tool))


def _scoped(scope: Scope, wire: _Wire) -> Decision | None:
    return scope_decision(scope, wire.step, wire.facts.zones)


def _cross_section(rules: Rules, wire: _Wire) -> Decision | None:
    low, high = rules.number("cross_section_min_mm2", 0.0), rules.number("cross_section_max_mm2", 1e9)
    section = wire.facts.section
    if section is None or low <= section <= high:
        return None
    return Decision(
        Performer.HUMAN,
        "cross-section",
        f"cross-section {section:g} mm² is outside the robot's {low:g} to {high:g} mm² ({rules.source})",
    )


def _termination(rules: Rules, wire: _Wire) -> Decision | None:
    if not wire.missing_tool:
        return None
    served = ", ".join(f"{t.name}: {' '.join(t.serves)}" for t in rules.tools) or "none"
    return Decision(
        Performer.HUMAN,
        "termination",
        f"no tool serves the {' and the '.join(wire.missing_tool)} (tools {served})",
    )


def _pin_data(rules: Rules, wire: _Wire) -> Decision | None:
    missing = wire.step.missing
    if not missing:
        return None
    if rules.choice("missing_pin_data", Performer.ROBOT, tuple(Performer)) == Performer.HUMAN:
        return Decision(Performer.HUMAN, "missing-pin-data", f"no pin data for {', '.join(missing)}")
    return Decision(
        Performer.ROBOT,
        "missing-pin-data",
        f"no pin data for {', '.join(missing)}: the robot's, flagged for detection (missing_pin_data)",
    )


def _every_rule(wire: _Wire) -> Decision:
    section = f"{wire.facts.section:g} mm², " if wire.facts.section is not None else ""
    zones = "/".join(z or "-" for z in wire.facts.zones)
    return Decision(
        Performer.ROBOT,
        "robot",
        f"zones {zones}, {section}tools {' then '.join(wire.tools)}: every rule lets the robot",
    )


def _abilities(rules: Rules) -> tuple[Rule[_Wire], ...]:
    """The robot's own rules, in the order they are asked after the cabinet rule."""
    return (
        partial(_cross_section, rules),
        partial(_termination, rules),
        partial(_pin_data, rules),
        _every_rule,
    )


def _decide(
    wire: _Wire, assignments: Assignments, scope: Rule[_Wire], abilities: Sequence[Rule[_Wire]]
) -> tuple[Decision, tuple[str, ...]]:
    """Who makes the wire and why (the core's decision under the plan's cabinet rule and the
    robot's rules), and the tools the robot needs for it."""
    judged = wire.judged
    decision = decide(
        wire, assignments, names_of(judged), scope=scope, parts=parts_of(judged), abilities=abilities
    )
    return decision, wire.tools if decision.performer is Performer.ROBOT else ()


def iema_problem(kg: Any, rules: Rules) -> Problem:
    """The wires of the cabinet as tasks in list order, with decisions and precedence."""
    model: CellModel = kg.cell_model()
    facts = _facts(kg)
    numbers = Counter(step.wire for step in model.steps)
    assignments = assignments_of(
        model.performers, model.base, ((s.wire, s.position) for s in model.steps), model.components
    )
    scope, abilities = partial(_scoped, scope_of(kg, model, rules)), _abilities(rules)
    tasks, decisions = [], {}
    for n, step in enumerate(model.steps):
        key = step.wire if numbers[step.wire] == 1 else f"{step.wire}@{step.position}"
        fact = facts.get(step.iri, _Facts())
        decision, tools = _decide(_wire(step, fact, rules), assignments, scope, abilities)
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
                tuple(termination or "" for termination in step.terminations),
                # A number several wires share names them all: one of them is its list position.
                ("wire", step.wire) if numbers[step.wire] == 1 else ("operation", str(step.position)),
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
