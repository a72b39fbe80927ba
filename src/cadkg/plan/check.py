"""A given order checked against a problem's precedence: ``cadkg validate`` findings at the
line of each task that comes too early, and the use case's notes."""

from __future__ import annotations

from cadkg.plan.tasks import Problem
from cadkg.query.validate import Finding, Severity

__all__ = ["order_findings"]


def order_findings(problem: Problem, check: str, severity: Severity = "error") -> list[Finding]:
    """Each precedence edge the files' order breaks, at the later task's place in its file;
    then the problem's notes, as warnings."""
    tasks = {t.key: t for t in problem.tasks}
    found = []
    for edge in problem.precedence:
        before, after = tasks[edge.before], tasks[edge.after]
        if edge.immediate and before.position + 1 != after.position:
            text = f"{after.label} does not come right after {before.label} ({before.where}): {edge.reason}"
        elif not edge.immediate and before.position > after.position:
            text = f"{after.label} comes before {before.label} ({before.where}), which must come first: "
            text += edge.reason
        else:
            continue
        found.append(Finding(after.where, severity, check, text))
    found += [Finding(where, "warning", check, text) for where, text in problem.notes]
    return found
