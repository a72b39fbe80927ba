"""A stored plan as people and programs read it: the summary line, the rows of the table and
CSV (``step,task,kind,performer,tool,reason``), JSON with the precedence, and why a task is
where it is."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from cadkg.plan.decision import BALANCE, Performer
from cadkg.plan.graph import PlannedStep, StoredPlan
from cadkg.plan.progress import STATUSES

__all__ = ["CSV_COLUMNS", "as_json", "explain", "find", "rows", "summary"]

CSV_COLUMNS = ("step", "task", "kind", "performer", "tool", "reason")


def _tool(step: PlannedStep) -> str:
    return ";".join(step.tools)


def rows(plan: StoredPlan) -> list[tuple[str, ...]]:
    """One row per step, in the order of :data:`CSV_COLUMNS`."""
    return [(str(s.step), s.label, s.kind, s.performer, _tool(s), s.reason) for s in plan.steps]


def _number(plan: StoredPlan, name: str) -> float:
    value = plan.summary.get(name, 0)
    return float(value) if value is not None else 0.0


def summary(plan: StoredPlan) -> str:
    """``12 tasks: 6 robot, 6 person; tool changes 4 (files' order 4, lower bound 3) ...``."""
    robot = sum(1 for s in plan.steps if s.performer == Performer.ROBOT)
    kept = sum(1 for e in plan.precedence if not e[3])
    dropped = len(plan.precedence) - kept
    changes, files_changes = _number(plan, "toolChanges"), _number(plan, "filesToolChanges")
    bound, broken = _number(plan, "toolChangesLowerBound"), _number(plan, "filesPrecedenceViolations")
    travel, files_travel = _number(plan, "travelM"), _number(plan, "filesTravelM")
    return (
        f"{len(plan.steps)} tasks: {robot} robot, {len(plan.steps) - robot} person; "
        f"tool changes {changes:.0f} (files' order {files_changes:.0f}, lower bound {bound:.0f}); "
        f"travel {travel:.2f} m (files' order {files_travel:.2f} m); precedence {kept} edges, "
        f"{broken:.0f} broken by the files' order, none by the plan"
        + (f", {dropped} dropped to break cycles" if dropped else "")
        + _times(plan)
        + f"; rules: {plan.summary.get('rulesSource', '')}"
    )


def _times(plan: StoredPlan) -> str:
    """``; time: robot 420 s, person 240 s, makespan 480 s side by side`` (and what a balance
    gained); empty for a plan stored before plans were timed."""
    if "makespanS" not in plan.summary:
        return ""
    text = (
        f"; time: robot {_number(plan, 'robotTimeS'):.0f} s, person {_number(plan, 'personTimeS'):.0f} s, "
        f"makespan {_number(plan, 'makespanS'):.0f} s side by side"
    )
    if "unbalancedMakespanS" in plan.summary:
        moved = sum(1 for s in plan.steps if s.rule == BALANCE)
        before = _number(plan, "unbalancedMakespanS")
        text += f" (balanced: {moved} tasks moved to a person, {before:.0f} s before)"
    return text


# The summary's times as --format json names them.
_TIMES = {
    "robotTimeS": "robot_time_s",
    "personTimeS": "person_time_s",
    "makespanS": "makespan_s",
    "unbalancedMakespanS": "unbalanced_makespan_s",
}


def as_json(plan: StoredPlan, status: Mapping[str, str] | None = None) -> dict[str, Any]:
    """The plan as JSON data: summary (with ``robot_time_s``, ``person_time_s``, ``makespan_s``
    and the statuses counted), steps (the CSV's fields, the file position, why the step is where
    it is, ``start_s`` and ``end_s``, and its ``status`` from ``status``, by task key, else
    ``pending``) and ``precedence: [{before, after, reason}]`` (kept edges)."""
    data = _as_json(plan)
    status = status or {}
    counts = dict.fromkeys(STATUSES, 0)
    for step in data["steps"]:
        step["status"] = status.get(step["key"], "pending")
        counts[step["status"]] += 1
    data["summary"]["status"] = counts
    return data


def _as_json(plan: StoredPlan) -> dict[str, Any]:
    names = {"toolChanges", "filesToolChanges", "toolChangesLowerBound", "filesPrecedenceViolations"}
    return {
        "summary": {
            "tasks": len(plan.steps),
            "robot": sum(1 for s in plan.steps if s.performer == Performer.ROBOT),
            **{
                k: (int(v) if k in names else float(v) if k.endswith("M") else str(v))
                for k, v in plan.summary.items()
                if k in names | {"travelM", "filesTravelM", "rulesSource"}
            },
            **{json: float(plan.summary[k]) for k, json in _TIMES.items() if k in plan.summary},
        },
        "steps": [
            {
                **dict(zip(CSV_COLUMNS, row, strict=True)),
                "step": step.step,
                "key": step.key,
                "file_position": step.position,
                "rule": step.rule,
                "placement": step.why_here,
                "start_s": step.start_s,
                "end_s": step.end_s,
            }
            for step, row in zip(plan.steps, rows(plan), strict=True)
        ],
        "precedence": [
            {"before": before, "after": after, "reason": reason}
            for before, after, reason, dropped in plan.precedence
            if not dropped
        ],
    }


def find(plan: StoredPlan, task: str) -> PlannedStep | None:
    """The step whose key or label is ``task``."""
    return next((s for s in plan.steps if task in (s.key, s.label)), None)


def explain(plan: StoredPlan, task: str) -> str | None:
    """Why ``task`` (a key or label) is where it is and who does it; None when no task is so named."""
    step = find(plan, task)
    if step is None:
        return None
    label = {s.key: s.label for s in plan.steps}
    at = {s.key: s.step for s in plan.steps}
    lines = [
        f"{step.label} ({step.kind}) is step {step.step} of {len(plan.steps)} "
        f"(position {step.position} in the files).",
        f"Who: {step.performer} — {step.rule}: {step.reason}",
        f"Where: {step.why_here}",
    ]
    if step.start_s is not None and step.end_s is not None:
        lane = "the robot's" if step.performer == Performer.ROBOT else "the person's"
        lines.append(f"When: {step.start_s:.0f} s → {step.end_s:.0f} s, in {lane} lane")
    for before, after, reason, dropped in plan.precedence:
        if step.key not in (before, after):
            continue
        other = after if before == step.key else before
        relation = "before" if before == step.key else "after"
        state = "dropped for a cycle" if dropped else f"step {at[other]}"
        lines.append(f"Comes {relation} {label[other]} ({state}): {reason}")
    return "\n".join(lines)
