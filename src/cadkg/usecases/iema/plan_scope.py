"""Which wires are the cabinet's robot's to make at all: the cabinet rule of
:mod:`cadkg.usecases.iema.robot_scope` (the zones of the connection list, else the labels the CAD
places), as the planner's first rule. The rest go to a person, with the rule and the values.

The zones are the cell's (the manifest's ``[derive] robot_zones``, ``Q``/``QE`` by default), as
the providers, ``full_cad_service`` and ``cadkg validate`` use them; a rules file that names its
own ``zones`` plans by those instead.
"""

from __future__ import annotations

from collections.abc import Sequence

from cadkg.plan.rules import Rules
from cadkg.plan.tasks import HUMAN, Decision
from cadkg.usecases.iema.derive.cabinet import CellModel, WireStep
from cadkg.usecases.iema.robot_scope import scope_reason

__all__ = ["scope_decision"]


def scope_decision(
    model: CellModel, step: WireStep, zones: Sequence[str | None], rules: Rules
) -> Decision | None:
    """A person's decision when the wire is outside the robot's cabinet; None when inside.

    ``zones`` are the wire's origin and destination zones as the connection list gives them;
    the origin's decides, as the cabinet rule reads the list.
    """
    own = rules.names("zones", ())
    if own:
        known = {label for label, geometry in model.components.items() if geometry.items}
        reason = scope_reason(zones[0], (step.origin.label, step.destination.label), own, known)
        where = rules.source
    else:
        reason, where = step.reason or None, "the cell's robot zones"
    if reason is None:
        return None
    rule = "zone" if reason.startswith("zone") else "label-not-in-cad"
    if rule == "label-not-in-cad" and rules.choice("label_not_in_cad", HUMAN, ("robot", HUMAN)) != HUMAN:
        return None
    return Decision(HUMAN, rule, f"{reason} ({where})")
