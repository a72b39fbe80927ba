"""The plan of a cell: its use case's tasks under a rules file, ordered.

The rules are, first found: the file given, the manifest's ``[plan] rules``, the use case's
default (``plan-rules.toml`` in its folder). Their time model is the default's, each ``[time]``
key the chosen file gives replacing the default's.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from functools import partial
from pathlib import Path
from typing import Any

import cadkg.registry as registry
from cadkg.errors import QueryError
from cadkg.plan.balance import timed
from cadkg.plan.graph import StoredPlan, cell_base, read_plan, write_plan
from cadkg.plan.order import Plan, make_plan
from cadkg.plan.progress import by_task, plan_around, read_progress
from cadkg.plan.rules import Rules, check_settings, load_rules, parse_rules
from cadkg.plan.tasks import Problem, Task
from cadkg.plan.times import TimeModel
from cadkg.store import cell_profile

__all__ = [
    "assign_ids",
    "assigned_by",
    "cell_base",
    "cell_profile",
    "plan_cell",
    "rules_of",
    "store_plan",
    "time_model",
]


def rules_of(kg: Any, rules: Path | None = None) -> Rules:
    """The rules a plan of ``kg`` is made under (see the module doc).

    Raises
    ------
    QueryError
        When the cell's use case makes no plans.
    RulesError
        When the rules file is malformed.
    """
    profile = cell_profile(kg)
    planner = registry.use_case(profile).planner
    if planner is None:
        raise QueryError(f"the {profile or 'default'} use case makes no task list")
    return check_settings(_chosen_rules(kg, profile, planner.rules, rules), planner.settings)


def _chosen_rules(kg: Any, profile: str, default: Any, rules: Path | None) -> Rules:
    if rules is not None:
        return load_rules(rules)
    given = kg.query(
        "SELECT ?name ?text WHERE { ?c a ck:Cell ; ck:planRules ?name ; ck:planRulesText ?text }"
    )
    if given.rows:
        row = given.rows[0]
        return parse_rules(str(row["text"]), f"{row['name']} (the manifest's [plan] rules)")
    return load_rules(default, f"the {profile} default rules")


def plan_cell(
    kg: Any, rules: Path | None = None, solver_budget: float = 0.0, balance: bool | None = None
) -> Plan:
    """The plan of the cell in ``kg``, timed (not written; see :func:`store_plan`); with a
    ``solver_budget``, improved by CP-SAT (:func:`cadkg.plan.order.make_plan`); balanced when
    ``balance`` says so, else when the rules' ``[time] balance`` does."""
    return _planned(kg, rules_of(kg, rules), solver_budget, balance)


def time_model(kg: Any, rules: Rules) -> TimeModel:
    """The time model of ``rules``: the use case's default ``[time]`` under the file's own."""
    planner = registry.use_case(cell_profile(kg)).planner
    assert planner is not None  # rules_of raised otherwise
    default = load_rules(planner.rules, f"the {cell_profile(kg)} default rules")
    return TimeModel.layered(default.time, rules.time)


def _planned(kg: Any, rules: Rules, solver_budget: float = 0.0, balance: bool | None = None) -> Plan:
    planner = registry.use_case(cell_profile(kg)).planner
    assert planner is not None  # rules_of raised otherwise
    problem = planner.tasks(kg, rules)
    model = time_model(kg, rules)
    chosen = model.balance if balance is None else balance
    reports = by_task(problem.tasks, read_progress(kg))
    if not reports:
        order: Callable[[Problem], Plan] = partial(make_plan, solver_budget=solver_budget)
        return timed(problem, order(problem), model, order, chosen)
    # Refreshed around what the cell has reported (docs/plan.md, Progress); what it has taken
    # on stays where it is, balanced or not.
    previous = read_plan(kg, cell_base(kg))
    order = partial(plan_around, reports=reports, previous=previous, solver_budget=solver_budget)
    taken = frozenset(k for k, r in reports.items() if r.state in ("done", "started"))
    return timed(problem, order(problem), model, order, chosen, taken)


def store_plan(
    kg: Any, rules: Path | None = None, solver_budget: float = 0.0, balance: bool | None = None
) -> StoredPlan:
    """Make the plan of the cell in ``kg``, replace its plan graph with it, and read it back.

    Raises what :func:`rules_of` raises, StoreError on a read-only store, and ImportError when
    a solver budget is given and OR-Tools is not installed.
    """
    chosen = rules_of(kg, rules)
    base = cell_base(kg)
    write_plan(kg, _planned(kg, chosen, solver_budget, balance), base, chosen.source)
    stored = read_plan(kg, base)
    assert stored is not None  # just written
    return stored


def assigned_by(kg: Any, kind: str) -> set[str]:
    """The ids of ``kind`` that the cell's plan tasks are assigned by (``Task.assign_as``): what
    ``cadkg assign`` accepts besides what the cell model lists. Empty for a cell that makes no
    plans."""
    planner = registry.use_case(cell_profile(kg)).planner
    if planner is None:
        return set()
    return assign_ids(planner.tasks(kg, rules_of(kg)).tasks, kind)


def assign_ids(tasks: Iterable[Task], kind: str) -> set[str]:
    """The ids of ``kind`` that ``tasks`` are assigned by."""
    return {t.assign_as[1] for t in tasks if t.assign_as and t.assign_as[0] == kind}
