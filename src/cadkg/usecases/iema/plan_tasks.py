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
from importlib import resources
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
from cadkg.usecases.iema.plan_scope import Scope, scope_decision, scope_of

__all__ = ["DEFAULT_RULES", "iema_problem", "order_check"]

DEFAULT_RULES = resources.files("cadkg.usecases.iema").joinpath("plan-rules.toml")

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


def _exit(step: WireStep, end: int, length: float) -> tuple[Vec3, Vec3] | None:
    """The straight run of a wire leaving its ``end`` (0 origin, 1 destination), clipped."""
    pin = (step.origin, step.destination)[end]
    pose = pin.hole or pin.screw
    if pose is None:
        return None
    route = [k.position for k in step.keypoints]
    if end == 1:
        route.reverse()
    other = _point((step.destination, step.origin)[end])
    towards = route[1] if len(route) >= 2 else other
    if towards is None:
        return None
    start = pose.position
    gap = [towards[k] - start[k] for k in range(3)]
    norm = sum(g * g for g in gap) ** 0.5
    if norm < 1e-9:
        return None
    scale = min(1.0, length / norm)
    return start, (start[0] + gap[0] * scale, start[1] + gap[1] * scale, start[2] + gap[2] * scale)


def _precedence(model: CellModel, keys: list[str], rules: Rules) -> list[Precedence]:
    clearance = rules.number("clearance_m", 0.004)
    depth = rules.number("corridor_depth_m", 0.05)
    length = rules.number("exit_length_m", 0.1)
    filed: list[tuple[Vec3, Vec3]] = []
    corridors: list[tuple[int, CadPin]] = []  # per filed corridor: its task and pin
    for n, step in enumerate(model.steps):
        for pin in (step.origin, step.destination):
            if pin.screw is None and pin.hole is None:
                continue
            pose = pin.screw or pin.hole
            assert pose is not None
            axis = pose.rotate((0.0, 0.0, depth))
            start = pose.position
            filed.append((start, (start[0] + axis[0], start[1] + axis[1], start[2] + axis[2])))
            corridors.append((n, pin))
    exits: list[tuple[Vec3, Vec3]] = []
    owners: list[tuple[int, CadPin]] = []  # per exit: its task and the pin it leaves
    for n, step in enumerate(model.steps):
        for end, landed in enumerate((step.origin, step.destination)):
            run = _exit(step, end, length)
            if run is not None:
                exits.append(run)
                owners.append((n, landed))
    edges: dict[tuple[int, int], Precedence] = {}
    found = close_pairs(
        np.array(exits, dtype=float).reshape(-1, 2, 3),
        np.array(filed, dtype=float).reshape(-1, 2, 3),
        clearance,
    )
    for number, corridor, gap in found:
        n, landed = owners[number]
        first, pin = corridors[corridor]
        if first == n or (pin.label, pin.pin) == (landed.label, landed.pin) or (first, n) in edges:
            continue
        wire = model.steps[n].wire
        edges[(first, n)] = Precedence(
            keys[first],
            keys[n],
            f"wire {wire} landed on {landed.label}:{landed.pin} passes {gap * 1000:.1f} mm from "
            f"the approach of {pin.label}:{pin.pin} (clearance {clearance * 1000:g} mm, depth "
            f"{depth * 1000:g} mm): {model.steps[first].wire} first",
        )
    return [edges[k] for k in sorted(edges)]
