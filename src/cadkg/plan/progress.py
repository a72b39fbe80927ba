"""What the cell reports it did: a task started, done or failed (``cadkg progress``,
``POST /api/progress``, ROS ``report_progress``; docs/plan.md, Progress).

A report is kept in the named graph ``{base}progress``, one node per task (the latest report of
a task replaces the one before), with the identity of its work as a revision diff names it
(:mod:`cadkg.changes`: a wire by its number and ends, an operation by its code and labels). A
rebuild carries the graph over, and reading it matches each report to the work of the graph as
it now is by that identity, so a report stays on its wire when another revision renumbers it.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping
from dataclasses import dataclass
from datetime import UTC, datetime
from typing import TYPE_CHECKING, Any

import pyoxigraph as ox

from cadkg.changes.compare import pair_things
from cadkg.changes.kinds import ThingKind, kinds_for
from cadkg.changes.things import Thing, cell_profiles, read_things
from cadkg.errors import NotFound, QueryError, StoreError
from cadkg.mapping.writer import TripleWriter
from cadkg.ontology.terms import CK_NS
from cadkg.plan.decision import Decision, Performer
from cadkg.plan.graph import StoredPlan, cell_base
from cadkg.plan.tasks import Problem, Task

if TYPE_CHECKING:
    from cadkg.plan.order import Plan

__all__ = [
    "FAILED",
    "STATES",
    "STATUSES",
    "Report",
    "by_task",
    "check_state",
    "finished_work",
    "no_task",
    "plan_around",
    "progress_graph",
    "read_progress",
    "record",
    "statuses",
]

STATES = ("started", "done", "failed")
"""What a report may say of a task."""
STATUSES = ("pending", *STATES)
"""A task's status in the plan: ``pending`` until a report says otherwise."""

FAILED = "failed"
"""The rule of the decision that gives a task the robot reported failed to a person."""

_TYPE = "<http://www.w3.org/1999/02/22-rdf-syntax-ns#type>"


@dataclass(frozen=True, slots=True)
class Report:
    """The latest report of one task: its state, the report's text, when and by whom, and the
    task's key and label when it was reported; ``work`` the IRI of its work in the graph read."""

    state: str
    reason: str
    at: str
    by: str
    key: str
    label: str
    work: str


def progress_graph(base: str) -> str:
    """The IRI of the progress reports' named graph."""
    return base + "progress"


def check_state(state: str) -> str:
    """``state`` when it is one a report may give.

    Raises
    ------
    QueryError
        Otherwise, naming the states.
    """
    if state not in STATES:
        raise QueryError(f"progress: unknown state {state!r}; expected one of {', '.join(STATES)}")
    return state


def _t(name: str) -> str:
    return f"<{CK_NS}{name}>"


def _kind_of(kg: Any, work: str) -> ThingKind | None:
    """The change kind named for the class of ``work`` (ck:Wire: wire, ck:Operation: operation)."""
    if not work:
        return None
    classes = {
        str(row["c"]).removeprefix(CK_NS).lower()
        for row in kg.query("SELECT ?c WHERE { ?w a ?c }", w=ox.NamedNode(work)).rows
    }
    return next((k for k in kinds_for(sorted(set(cell_profiles(kg)))) if k.name in classes), None)


def _names(kind: ThingKind) -> list[str]:
    return sorted({*kind.key, *(name for names in kind.match for name in names)})


def _identity(kg: Any, kind: ThingKind | None, work: str) -> dict[str, Any]:
    """What identifies ``work`` to an engineer: the values of its kind's key and matches."""
    if kind is None:
        return {}
    thing = next((t for t in read_things(kg, kind) if t.iri == work), None)
    if thing is None:
        return {}
    return {name: thing.value(name) for name in _names(kind)}


def _rows(kg: Any, base: str) -> list[dict[str, Any]]:
    name = progress_graph(base)
    if not base or name not in kg.named_graphs():
        return []
    return list(
        kg.query(
            """SELECT ?r ?state ?reason ?at ?by ?key ?label ?work ?kind ?identity WHERE { GRAPH ?g {
             ?r a ck:ProgressReport ; ck:progressState ?state ; ck:reportedTask ?key ; ck:label ?label ;
                ck:reportedAt ?at ; ck:progressKind ?kind ; ck:progressIdentity ?identity .
             OPTIONAL { ?r ck:progressReason ?reason } OPTIONAL { ?r ck:reportedBy ?by }
             OPTIONAL { ?r ck:progressOf ?work } } } ORDER BY ?at ?r""",
            g=ox.NamedNode(name),
        ).rows
    )


def _as_thing(kind: ThingKind, node: str, identity: Mapping[str, Any]) -> Thing:
    values = {k: tuple(v) if isinstance(v, list) else v for k, v in identity.items()}
    found = values.pop("id", None)
    keys = {k: v for k, v in values.items() if k.startswith("key_")}
    attributes = {k: v for k, v in values.items() if not k.startswith("key_")}
    return Thing(kind.name, str(found or ""), node, attributes, None, keys)


def _matched(kg: Any, rows: list[dict[str, Any]]) -> dict[str, tuple[dict[str, Any], str]]:
    """Each report node → (its row, the IRI of its work in ``kg`` now; '' when gone)."""
    kinds = {k.name: k for k in kinds_for(sorted(set(cell_profiles(kg))))}
    out: dict[str, tuple[dict[str, Any], str]] = {}
    by_kind: dict[str, list[dict[str, Any]]] = {}
    for row in rows:
        identity = json.loads(row["identity"])
        if row["kind"] in kinds and identity:
            by_kind.setdefault(row["kind"], []).append(row)
        else:  # work no diff identifies: by its IRI, while the graph has it
            work = row["work"] or ""
            out[str(row["r"])] = (row, work if work and _exists(kg, work) else "")
    for name, reports in by_kind.items():
        # By the kind's key, then its first match only (a wire renumbered, same ends): a wire
        # with an end changed is other work, which the report does not speak of.
        kind = dataclasses.replace(kinds[name], match=kinds[name].match[:1])
        old = [_as_thing(kind, str(r["r"]), json.loads(r["identity"])) for r in reports]
        pairs, _, _ = pair_things(kind, old, read_things(kg, kind))
        now = {a.iri: b.iri or "" for a, b in pairs}
        for row in reports:
            out[str(row["r"])] = (row, now.get(str(row["r"]), ""))
    return out


def _exists(kg: Any, iri: str) -> bool:
    return bool(kg.ask("ASK { ?w ?p ?o }", w=ox.NamedNode(iri)))


def read_progress(kg: Any) -> dict[str, Report]:
    """The latest report of each work of ``kg`` (its IRI now → report); reports whose work the
    graph no longer has are left out. Empty when the store holds none."""
    rows = _rows(kg, cell_base(kg))
    if not rows:
        return {}
    found: dict[str, Report] = {}
    for row, work in _matched(kg, rows).values():
        if not work:
            continue
        at = row["at"].isoformat() if hasattr(row["at"], "isoformat") else str(row["at"])
        reason, by = row["reason"] or "", row["by"] or ""
        report = Report(row["state"], reason, at, by, row["key"], row["label"], work)
        if work not in found or found[work].at <= report.at:
            found[work] = report
    return found


def finished_work(kg: Any) -> frozenset[str]:
    """The IRIs of the work reported done or failed: what the cursor services hand out no more
    (a failed task is a person's from the report on)."""
    if kg is None:
        return frozenset()
    return frozenset(w for w, r in read_progress(kg).items() if r.state in ("done", "failed"))


def record(kg: Any, key: str, label: str, work: str, state: str, reason: str = "", by: str = "") -> str:
    """Write the report of one task (key, label, the IRI of its work) into ``kg``'s progress
    graph, replacing any earlier report of the same work; call inside ``kg.change()``.
    Returns the report's node.

    Raises
    ------
    QueryError
        On an unknown state.
    StoreError
        When the store has no cell.
    """
    check_state(state)
    base = cell_base(kg)
    if not base:
        raise StoreError("the store has no cell; build it from a manifest first")
    graph = progress_graph(base)
    kind = _kind_of(kg, work)
    stale = [node for node, (_, now) in _matched(kg, _rows(kg, base)).items() if work and now == work]
    w = TripleWriter(base)
    node = w.iri("progress", key)
    w.add(node, _TYPE, _t("ProgressReport"))
    w.add(node, _t("reportedTask"), w.text(key))
    w.add(node, _t("label"), w.text(label))
    w.add(node, _t("progressState"), w.text(state))
    if reason:
        w.add(node, _t("progressReason"), w.text(reason))
    if by:
        w.add(node, _t("reportedBy"), w.text(by))
    when = datetime.now(UTC).isoformat(timespec="microseconds")
    w.add(node, _t("reportedAt"), f'"{when}"^^<http://www.w3.org/2001/XMLSchema#dateTime>')
    w.add(node, _t("progressKind"), w.text(kind.name if kind else ""))
    w.add(node, _t("progressIdentity"), w.text(json.dumps(_identity(kg, kind, work), sort_keys=True)))
    if work:
        w.add(node, _t("progressOf"), f"<{work}>")
    replaced = {*stale, node[1:-1]}
    kept = "".join(
        f"{q.subject} {q.predicate} {q.object} .\n"
        for q in kg.graph_quads(graph)
        if not (isinstance(q.subject, ox.NamedNode) and q.subject.value in replaced)
    )
    # One transaction: the old report goes only if the new one lands.
    kg.replace_graph(graph, kept.encode("utf-8") + w.data())
    return node[1:-1]


def no_task(task: str, what: str = "progress") -> NotFound:
    """The error of a report (or of ``what`` else names a task) naming no task of the cell."""
    return NotFound(f"{what}: no task {task!r} in the plan (a wire number, an operation label or key)")


def by_task(tasks: list[Task], reports: Mapping[str, Report]) -> dict[str, Report]:
    """The reports of ``tasks`` by task key: through the task's work, else its key."""
    keyed = {r.key: r for r in reports.values()}
    found = {}
    for task in tasks:
        report = reports.get(task.iri) if task.iri else keyed.get(task.key)
        if report is not None:
            found[task.key] = report
    return found


def statuses(plan: StoredPlan, reports: Mapping[str, Report]) -> dict[str, str]:
    """Each step's status (task key → ``pending``, ``started``, ``done`` or ``failed``)."""
    keyed = {r.key: r for r in reports.values()}
    out = {}
    for step in plan.steps:
        report = reports.get(step.work) if step.work else keyed.get(step.key)
        out[step.key] = report.state if report is not None else "pending"
    return out


def _failed(decision: Decision, report: Report) -> Decision:
    if decision.performer is not Performer.ROBOT:
        return decision
    by = f" by {report.by}" if report.by else ""
    text = report.reason or "no reason given"
    why = f"the robot reported it failed ({text}; reported{by} at {report.at}): a person's now"
    return Decision(Performer.HUMAN, FAILED, why)


def plan_around(
    problem: Problem, reports: Mapping[str, Report], previous: StoredPlan | None, solver_budget: float = 0.0
) -> Plan:
    """The plan of ``problem`` around what the cell reported (``reports`` by task key): a failed
    robot task goes to a person; the tasks done, then those started, come first, in their order in
    the ``previous`` plan (else as reported), each as it was planned there; the rest is planned
    after them (:func:`cadkg.plan.order.make_plan`)."""
    # Only here: the cursors read the reports on every call, and ordering imports numpy.
    from cadkg.plan.measure import lower_bound, measure
    from cadkg.plan.order import Plan, Step, make_plan

    decisions = dict(problem.decisions)
    for key, report in reports.items():
        if report.state == FAILED:
            decisions[key] = _failed(decisions[key], report)
    before = {s.key: s for s in previous.steps} if previous is not None else {}
    by_key = {t.key: t for t in problem.tasks}
    fixed = sorted(
        (key for key, r in reports.items() if r.state in ("done", "started") and key in by_key),
        key=lambda k: (
            reports[k].state != "done",
            before[k].step if k in before else len(before),
            reports[k].at,
        ),
    )
    pinned = set(fixed)
    steps = []
    for n, key in enumerate(fixed):
        was, report = before.get(key), reports[key]
        if was is not None:  # as it was planned when the cell took it on
            decisions[key] = Decision(Performer(was.performer), was.rule, was.reason)
        by = f" by {report.by}" if report.by else ""
        why = f"{report.state} (reported{by} at {report.at})" + (f"; planned: {was.why_here}" if was else "")
        steps.append(Step(n, by_key[key], decisions[key], why))
    rest = Problem(
        [t for t in problem.tasks if t.key not in pinned],
        {k: d for k, d in decisions.items() if k not in pinned},
        [e for e in problem.precedence if e.before not in pinned and e.after not in pinned],
        list(problem.notes),
    )
    planned = make_plan(rest, solver_budget)
    steps += [Step(len(fixed) + s.index, s.task, s.decision, s.why_here) for s in planned.steps]
    decisions.update({s.task.key: s.decision for s in planned.steps})
    edges = [*planned.precedence, *(e for e in problem.precedence if e.before in pinned or e.after in pinned)]
    files = sorted(problem.tasks, key=lambda t: t.position)
    return Plan(
        steps=steps,
        precedence=edges,
        dropped=planned.dropped,
        measure=measure([s.task for s in steps], decisions, edges),
        files=measure(files, decisions, edges),
        lower_bound=lower_bound(files, decisions),
        notes=planned.notes,
    )
