"""The robot's tasks in an ELVEZ cell: one per operation of the assembly sequence, who does it
and why, and what must come first by the files' own meaning (docs/plan.md):

* a harness's connector is taken out of its comb (EC) before it is placed (PC), and placed
  before any of its branches is routed (RC); without a PC, the EC comes before the routes;
* a branch's cables are routed (RC) before any taping (T, TJ) of their harness at a spot of
  their route;
* every branch is routed once, and every taping is on a route (else a note).

An RC naming a harness's first connector routes all its branches; one naming a cable routes
its branch. A spot or label no file defines sends the operation to a person.
"""

from __future__ import annotations

from collections import defaultdict
from functools import partial
from typing import Any

from cadkg.errors import CadkgError
from cadkg.geometry.poses import Vec3
from cadkg.mapping.writer import node_iri
from cadkg.plan.cell import cell_base
from cadkg.plan.check import order_findings as check_order
from cadkg.plan.decision import Assignments, Decision, Performer, decide
from cadkg.plan.rules import Rules, load_rules
from cadkg.plan.tasks import Precedence, Problem, Task
from cadkg.query.validate import Finding
from cadkg.usecases.elvez import DEFAULT_RULES
from cadkg.usecases.elvez.files.harnesses import WiringHarness
from cadkg.usecases.elvez.files.sequence import SequenceStep, SpotRef
from cadkg.usecases.elvez.model import ElvezModel, build_model, operation_iris, unresolved
from cadkg.usecases.elvez.platform import key_centre

__all__ = [
    "DEFAULT_RULES",
    "elvez_problem",
    "operation_key",
    "operation_label",
    "order_findings",
    "problem_of",
    "source_path",
]

_ROUTE, _TAPES, _EXTRACT, _PLACE = "RC", ("T", "TJ"), "EC", "PC"
_CHECK = "elvez-order"


def operation_key(step: SequenceStep) -> str:
    """The task key of an operation: ``op`` and its order in the sequence (``op3``)."""
    return f"op{step.order}"


def operation_label(step: SequenceStep) -> str:
    """What a person calls an operation: its code and labels (``RC GR11``)."""
    return f"{step.code} {'-'.join(step.labels)}"


def _spot_point(model: ElvezModel, spot: SpotRef) -> Vec3 | None:
    element = model.element(spot.jig)
    definition = model.definition(element) if element is not None else None
    if element is None or definition is None:
        return None
    guide = next((g for g in definition.guides if g.couple == spot.guide), None)
    try:
        frame = model.pose(element.frame)
    except CadkgError:
        return None
    return (frame * key_centre(guide.key)).position if guide is not None else frame.position


def _harness(model: ElvezModel, step: SequenceStep) -> tuple[WiringHarness | None, set[str]]:
    """The harness an operation handles and the branches (end connector labels) it names:
    all of them when it names the first connector."""
    harness, branches = None, set()
    for label in step.labels:
        found = model.harness_of(label)
        if found is None:
            continue
        harness, end, _ = found
        branches |= {end.label} if end is not None else {e.label for e in harness.end_connectors}
    return harness, branches


def _assignments(kg: Any, base: str, model: ElvezModel) -> Assignments:
    """The operations' assignments by their order in the sequence."""
    rows = kg.query("SELECT ?target ?who WHERE { ?a ck:assignmentOf ?target ; ck:assignedTo ?who }")
    performers = {row["target"]: row["who"].rsplit("#", 1)[-1] for row in rows}
    operations = (("operation", str(step.order)) for step in model.sequence)
    return Assignments.of_targets(performers, operations, partial(node_iri, base))


def _unresolved(model: ElvezModel, step: SequenceStep) -> Decision | None:
    notes = unresolved(model, step)
    return Decision(Performer.HUMAN, "unresolved", "; ".join(notes)) if notes else None


def _no_tool(rules: Rules, step: SequenceStep) -> Decision | None:
    if rules.tool_for(step.code.upper()) is not None:
        return None
    served = ", ".join(f"{t.name}: {' '.join(t.serves)}" for t in rules.tools) or "none"
    return Decision(Performer.HUMAN, "operation", f"no tool serves {step.code.upper()} (tools {served})")


def _not_in_cell(model: ElvezModel, rules: Rules, step: SequenceStep) -> Decision | None:
    code = step.code.upper()
    tool = rules.tool_for(code)
    stations = {d.tool.kind for e in model.tools() if (d := model.definition(e)) and d.tool is not None}
    if stations and tool not in stations:
        return Decision(
            Performer.HUMAN, "tool-not-in-cell", f"{code} needs the {tool}, which no ATC station holds"
        )
    return None


def _every_rule(rules: Rules, step: SequenceStep) -> Decision:
    code = step.code.upper()
    return Decision(
        Performer.ROBOT, "robot", f"{code} with the {rules.tool_for(code)}: every rule lets the robot"
    )


def _decide(
    model: ElvezModel, step: SequenceStep, rules: Rules, assignments: Assignments
) -> tuple[Decision, tuple[str, ...]]:
    """Who performs the operation and why (the core's decision under the robot's rules), and
    the tool it needs."""
    tool = rules.tool_for(step.code.upper())
    abilities = (
        partial(_unresolved, model),
        partial(_no_tool, rules),
        partial(_not_in_cell, model, rules),
        partial(_every_rule, rules),
    )
    decision = decide(step, assignments, (("operation", str(step.order)),), abilities=abilities)
    return decision, (tool,) if tool is not None and decision.performer is Performer.ROBOT else ()


def elvez_problem(kg: Any, rules: Rules) -> Problem:
    """The operations of the sequence as tasks in file order, with decisions and precedence."""
    return problem_of(kg, build_model(kg), rules)


def problem_of(kg: Any, model: ElvezModel, rules: Rules) -> Problem:
    """:func:`elvez_problem` of a model already built."""
    iris = operation_iris(kg)
    base = cell_base(kg)
    assigned = _assignments(kg, base, model)
    tasks, decisions = [], {}
    for n, (step, where) in enumerate(zip(model.sequence, model.step_where, strict=True)):
        decision, tools = _decide(model, step, rules, assigned)
        points = [_spot_point(model, s) for s in step.spots]
        known = [p for p in points if p is not None]
        start, end = (known[0], known[-1]) if known else (None, None)
        key = operation_key(step)
        tasks.append(
            Task(
                key,
                operation_label(step),
                step.code.upper(),
                n,
                tools,
                start,
                end,
                iris.get(step.line, ""),
                where,
                assign_as=("operation", str(step.order)),
            )
        )
        decisions[key] = decision
    edges, notes = _precedence(model, _harness_file(kg))
    return Problem(tasks, decisions, edges, notes)


def source_path(kg: Any, kind: str) -> str:
    """The path of the first source of reader ``kind`` (the kind itself when there is none)."""
    rows = kg.query(
        "SELECT ?path WHERE { ?g ck:readerKind ?kind ; ck:sourcePath ?path } ORDER BY ?path LIMIT 1",
        kind=kind,
    ).rows
    return str(rows[0]["path"]) if rows else kind


def _harness_file(kg: Any) -> str:
    return source_path(kg, "elvez-harnesses")


def order_findings(kg: Any, model: ElvezModel) -> list[Finding]:
    """The sequence's own order checked against what must come first: an error at the line of
    each operation that comes too early, and the notes (a branch routed twice or never, a
    taping on no route) as warnings."""
    return check_order(problem_of(kg, model, load_rules(DEFAULT_RULES, "the elvez default rules")), _CHECK)


def _precedence(model: ElvezModel, harness_file: str) -> tuple[list[Precedence], list[tuple[str, str]]]:
    edges: list[Precedence] = []
    notes: list[tuple[str, str]] = []
    by_code: dict[tuple[str, str], list[SequenceStep]] = defaultdict(list)  # (code, harness id)
    routes: dict[tuple[str, str], list[SequenceStep]] = defaultdict(list)  # (harness, branch)
    for step in model.sequence:
        harness, branches = _harness(model, step)
        if harness is None:
            continue
        code = step.code.upper()
        by_code[(code, harness.id)].append(step)
        if code == _ROUTE:
            for branch in branches:
                routes[(harness.id, branch)].append(step)
    where = dict(zip((id(s) for s in model.sequence), model.step_where, strict=True))
    for harness in model.harnesses:
        first = harness.first_connector
        extracts, places = by_code[(_EXTRACT, harness.id)], by_code[(_PLACE, harness.id)]
        routed = [s for s in model.sequence if s.code.upper() == _ROUTE and _harness(model, s)[0] is harness]
        for ec in extracts:
            for pc in places:
                edges.append(
                    _edge(
                        ec, pc, f"the gripper holds {first} from its comb (EC) until it is placed (PC)", True
                    )
                )
        for before in places or extracts:
            verb = "placed (PC)" if places else "taken out of its comb (EC)"
            for rc in routed:
                edges.append(_edge(before, rc, f"{first} is {verb} before its branches are routed"))
        for end in harness.end_connectors:
            count = len(routes[(harness.id, end.label)])
            if count != 1:
                orders = ", ".join(str(s.order) for s in routes[(harness.id, end.label)])
                text = "is not routed by the sequence" if not count else f"is routed {count} times ({orders})"
                notes.append((f"{harness_file}:{end.line}", f"branch {end.label} of {first} {text}"))
        for tape in (s for code in _TAPES for s in by_code[(code, harness.id)]):
            spots = {(s.jig, s.guide) for s in tape.spots}
            through = [rc for rc in routed if spots & {(s.jig, s.guide) for s in rc.spots}]
            for rc in through:
                shared = sorted(f"{j}.{g}" for j, g in spots & {(s.jig, s.guide) for s in rc.spots})
                edges.append(
                    _edge(
                        rc,
                        tape,
                        f"{'-'.join(rc.labels)} is routed through {', '.join(shared)} "
                        "before it is taped there",
                    )
                )
            if not through:
                notes.append(
                    (
                        where[id(tape)],
                        f"{operation_label(tape)} at {tape.spot_text} is on no route of {first}",
                    )
                )
    return edges, notes


def _edge(before: SequenceStep, after: SequenceStep, reason: str, immediate: bool = False) -> Precedence:
    return Precedence(operation_key(before), operation_key(after), reason, immediate)
