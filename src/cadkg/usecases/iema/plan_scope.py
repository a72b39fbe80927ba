"""Which wires are the cabinet's robot's to make at all, as the planner reports it.

The decision is the cabinet rule of :mod:`cadkg.usecases.iema.robot_scope` (both ends in the
zones of the manifest's ``[derive] robot_zones``, Q and QE by default; for a wire the list gives no zone, the
labels the CAD places): the same the providers, SPARQL and ``cadkg validate`` use, taken for
every wire when the cell was derived. A rules file overrides it for the plan only: its ``zones``
replace the cell's, and ``label_not_in_cad = "robot"`` lets the label half through.
"""

from __future__ import annotations

from dataclasses import dataclass
from importlib import resources
from typing import TYPE_CHECKING, Any

from cadkg.plan.decision import Decision, Performer
from cadkg.plan.rules import Rules
from cadkg.usecases.iema.robot_scope import DEFAULT_ZONES, LABEL_RULE, scope_reason, scope_rule

if TYPE_CHECKING:
    from cadkg.usecases.iema.derive.cabinet import CellModel, WireStep

__all__ = ["DEFAULT_RULES", "SETTINGS", "Scope", "scope_decision", "scope_of"]

DEFAULT_RULES = resources.files("cadkg.usecases.iema").joinpath("plan-rules.toml")
# Every [robot] setting read here and in plan_tasks (docs/plan.md lists them).
SETTINGS = frozenset(
    {
        "zones",
        "label_not_in_cad",
        "missing_pin_data",
        "cross_section_min_mm2",
        "cross_section_max_mm2",
        "default_tool",
        "clearance_m",
        "corridor_depth_m",
        "exit_length_m",
    }
)


@dataclass(frozen=True, slots=True)
class Scope:
    """The cabinet rule a plan is made under: the zones, where they come from (for the reasons),
    and, when a rules file overrides them, the labels the CAD places."""

    zones: tuple[str, ...]
    source: str
    labels_judged: bool = True
    override: frozenset[str] | None = None


def scope_of(kg: Any, model: CellModel, rules: Rules) -> Scope:
    """The cabinet rule of the cell in ``kg`` under ``rules``."""
    labels_judged = rules.choice("label_not_in_cad", Performer.HUMAN, tuple(Performer)) == Performer.HUMAN
    if "zones" in rules.robot:
        known = frozenset(label for label, geometry in model.components.items() if geometry.items)
        return Scope(rules.names("zones"), f"the zones of {rules.source}", labels_judged, known)
    rows = kg.query("SELECT DISTINCT ?z WHERE { ?c a ck:Cell ; ck:robotZone ?z }")
    stated = tuple(sorted(row["z"] for row in rows))
    source = "the manifest's [derive] robot_zones" if stated else "the default [derive] robot_zones"
    return Scope(stated or DEFAULT_ZONES, source, labels_judged)


def scope_decision(scope: Scope, step: WireStep, zones: tuple[str | None, str | None]) -> Decision | None:
    """A person's decision when the wire (whose ends' zones the list gives as ``zones``) is
    outside the robot's cabinet; None when it is inside."""
    if scope.override is None:
        reason = step.reason or None
    else:
        reason = scope_reason(zones, (step.origin.label, step.destination.label), scope.zones, scope.override)
    rule = scope_rule(zones)
    if reason is None or (rule == LABEL_RULE and not scope.labels_judged):
        return None
    if rule == LABEL_RULE:
        return Decision(Performer.HUMAN, rule, f"{reason}; the list gives the wire no zone")
    return Decision(Performer.HUMAN, rule, f"{reason} ({scope.source})")
