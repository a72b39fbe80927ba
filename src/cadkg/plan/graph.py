"""The plan as data: the named graph ``{base}plan`` in the ontology's terms (docs/plan.md),
written after every ``cadkg plan`` and read back by the cursor services, ``/api/plan`` and the
named query ``plan-steps``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import pyoxigraph as ox

from cadkg.mapping.writer import TripleWriter
from cadkg.ontology.terms import CK_NS
from cadkg.plan.decision import Performer

if TYPE_CHECKING:  # the ordering (numpy) is not needed to read a stored plan back
    from cadkg.plan.order import Plan

__all__ = [
    "PlannedStep",
    "StoredPlan",
    "cell_base",
    "plan_graph",
    "plan_ntriples",
    "read_plan",
    "robot_positions",
    "write_plan",
]

_TYPE = "<http://www.w3.org/1999/02/22-rdf-syntax-ns#type>"


def cell_base(kg: Any) -> str:
    """The base IRI of the cell (its ``ck:Cell`` is ``{base}cell/this``); empty without a cell."""
    rows = kg.query("SELECT ?c WHERE { ?c a ck:Cell } LIMIT 1").rows
    return str(rows[0]["c"]).removesuffix("cell/this") if rows else ""


def plan_graph(base: str) -> str:
    """The IRI of the plan's named graph."""
    return base + "plan"


def _t(name: str) -> str:
    return f"<{CK_NS}{name}>"


def plan_ntriples(plan: Plan, base: str, rules: str) -> bytes:
    """The plan in N-Triples, its nodes minted under ``base`` (``{base}plan/task/KEY`` ...)."""
    w = TripleWriter(base)
    typed, text = w.typed, w.text
    task_list = w.iri("plan", "list")
    w.add(task_list, _TYPE, _t("TaskList"))
    w.add(task_list, _t("label"), text("the robot's task list"))
    w.add(task_list, _t("rulesSource"), text(rules))
    for name, value in (
        ("toolChanges", plan.measure.tool_changes),
        ("filesToolChanges", plan.files.tool_changes),
        ("toolChangesLowerBound", plan.lower_bound),
        ("filesPrecedenceViolations", plan.files.violations),
    ):
        w.add(task_list, _t(name), typed(value))
    w.add(task_list, _t("travelM"), typed(float(plan.measure.travel)))
    w.add(task_list, _t("filesTravelM"), typed(float(plan.files.travel)))
    timing = plan.timing
    if timing is not None:
        for name, seconds in (
            ("robotTimeS", timing.robot_s),
            ("personTimeS", timing.person_s),
            ("makespanS", timing.makespan_s),
        ):
            w.add(task_list, _t(name), typed(float(seconds)))
    if plan.unbalanced_makespan_s is not None:
        w.add(task_list, _t("unbalancedMakespanS"), typed(float(plan.unbalanced_makespan_s)))
    nodes = {}
    for step in plan.steps:
        task = step.task
        node = nodes[task.key] = w.iri("plan", "task", task.key)
        w.add(node, _TYPE, _t("PlannedTask"))
        w.add(node, _t("inTaskList"), task_list)
        w.add(node, _t("stepIndex"), typed(step.index))
        w.add(node, _t("filePosition"), typed(task.position))
        w.add(node, _t("taskKey"), text(task.key))
        w.add(node, _t("label"), text(task.label))
        w.add(node, _t("taskKind"), text(task.kind))
        w.add(node, _t("assignedTo"), _t(step.decision.performer))
        w.add(node, _t("decisionRule"), text(step.decision.rule))
        w.add(node, _t("decisionReason"), text(step.decision.reason))
        w.add(node, _t("placementReason"), text(step.why_here))
        if task.tools and step.decision.performer == Performer.ROBOT:
            w.add(node, _t("toolNames"), text(";".join(task.tools)))
        if task.iri:
            w.add(node, _t("doesWork"), f"<{task.iri}>")
        if timing is not None:
            w.add(node, _t("startS"), typed(float(timing.start[step.index])))
            w.add(node, _t("endS"), typed(float(timing.end[step.index])))
    for n, (edge, dropped) in enumerate(
        [(e, False) for e in plan.precedence] + [(e, True) for e in plan.dropped]
    ):
        node = w.iri("plan", "precedence", str(n))
        w.add(node, _TYPE, _t("PrecedenceEdge"))
        w.add(node, _t("beforeTask"), nodes[edge.before])
        w.add(node, _t("afterTask"), nodes[edge.after])
        w.add(node, _t("precedenceReason"), text(edge.reason))
        if edge.immediate:
            w.add(node, _t("immediate"), typed(True))
        if dropped:
            w.add(node, _t("droppedForCycle"), typed(True))
    return w.data()


def write_plan(kg: Any, plan: Plan, base: str, rules: str) -> str:
    """Replace the plan graph of ``kg`` with ``plan``; returns the graph's IRI."""
    graph = plan_graph(base)
    kg.replace_graph(graph, plan_ntriples(plan, base, rules))
    return graph


@dataclass(frozen=True, slots=True)
class PlannedStep:
    """A step of a stored plan, as the cursor services and ``/api/plan`` read it."""

    step: int
    key: str
    label: str
    kind: str
    performer: str
    tools: tuple[str, ...]
    work: str
    position: int
    rule: str
    reason: str
    why_here: str
    # Seconds from the plan's start (None in a plan stored before plans were timed).
    start_s: float | None = None
    end_s: float | None = None


@dataclass(frozen=True)
class StoredPlan:
    steps: tuple[PlannedStep, ...]
    # (before key, after key, reason, dropped for a cycle)
    precedence: tuple[tuple[str, str, str, bool], ...]
    summary: dict[str, Any]


def read_plan(kg: Any, base: str) -> StoredPlan | None:
    """The plan stored in ``kg`` (None when it has none)."""
    name = plan_graph(base)
    if name not in kg.named_graphs():
        return None
    graph = ox.NamedNode(name)
    rows = kg.query(
        """SELECT ?step ?key ?label ?kind ?who ?tools ?work ?position ?rule ?reason ?why ?start ?end
           WHERE { GRAPH ?g {
             ?t a ck:PlannedTask ; ck:stepIndex ?step ; ck:taskKey ?key ; ck:label ?label ;
                ck:taskKind ?kind ; ck:assignedTo ?who ; ck:filePosition ?position ; ck:decisionRule ?rule ;
                ck:decisionReason ?reason ; ck:placementReason ?why .
             OPTIONAL { ?t ck:toolNames ?tools } OPTIONAL { ?t ck:doesWork ?work }
             OPTIONAL { ?t ck:startS ?start ; ck:endS ?end } } } ORDER BY ?step""",
        g=graph,
    )
    steps = tuple(
        PlannedStep(
            int(r["step"]),
            r["key"],
            r["label"],
            r["kind"],
            str(r["who"]).rsplit("#", 1)[-1],
            tuple(r["tools"].split(";")) if r["tools"] else (),
            r["work"] or "",
            int(r["position"]),
            r["rule"],
            r["reason"],
            r["why"],
            float(r["start"]) if r["start"] is not None else None,
            float(r["end"]) if r["end"] is not None else None,
        )
        for r in rows
    )
    edges = tuple(
        (r["before"], r["after"], r["reason"], r["dropped"] is not None)
        for r in kg.query(
            """SELECT ?before ?after ?reason ?dropped WHERE { GRAPH ?g { ?e a ck:PrecedenceEdge ;
                 ck:beforeTask/ck:taskKey ?before ; ck:afterTask/ck:taskKey ?after ;
                 ck:precedenceReason ?reason OPTIONAL { ?e ck:droppedForCycle ?dropped } } }
               ORDER BY ?e""",
            g=graph,
        )
    )
    summary_rows = kg.query(
        """SELECT ?p ?v WHERE { GRAPH ?g { ?l a ck:TaskList ; ?p ?v } }""",
        g=graph,
    ).rows
    summary = {str(r["p"]).removeprefix(CK_NS): r["v"] for r in summary_rows if str(r["p"]).startswith(CK_NS)}
    return StoredPlan(steps, edges, summary)


def robot_positions(kg: Any) -> list[int] | None:
    """The files' positions of the robot's tasks in the order of the stored plan, for the cursor
    services to follow; None when ``kg`` (a store, or None) holds no plan."""
    if kg is None:
        return None
    base = cell_base(kg)
    name = plan_graph(base)
    if not base or name not in kg.named_graphs():
        return None
    found = kg.query(
        """SELECT ?position WHERE { GRAPH ?g { ?t a ck:PlannedTask ; ck:assignedTo ck:robot ;
             ck:stepIndex ?step ; ck:filePosition ?position } } ORDER BY ?step""",
        g=ox.NamedNode(name),
    )
    return [int(row["position"]) for row in found]
