"""Which wires are the cabinet's robot's to make at all: the zones it works in, and the labels
the CAD places. The rest go to a person, with the rule and the values that decided it.

Kept apart from the rules of tools and geometry (:mod:`cadkg.usecases.iema.plan_tasks`) so the
cell's own scope decision can replace it whole.
"""

from __future__ import annotations

from collections.abc import Sequence

from cadkg.plan.rules import Rules
from cadkg.plan.tasks import HUMAN, Decision
from cadkg.usecases.iema.derive.cabinet import CellModel, WireStep

__all__ = ["DEFAULT_ZONES", "scope_decision"]

DEFAULT_ZONES = ("Q", "QE")


def scope_decision(
    model: CellModel, step: WireStep, zones: Sequence[str | None], rules: Rules
) -> Decision | None:
    """A person's decision when the wire is outside the robot's zones or names a label the CAD
    does not place; None when the wire is in the robot's scope.

    ``zones`` are the wire's origin and destination zones as the connection list gives them
    (None when it gives none: the zone rule then does not apply to that end).
    """
    allowed = rules.names("zones", DEFAULT_ZONES)
    for end, zone in zip(("origin", "destination"), zones, strict=True):
        if allowed and zone is not None and zone not in allowed:
            return Decision(
                HUMAN,
                "zone",
                f"{end} zone {zone} is not one of the robot's zones ({', '.join(allowed)}; {rules.source})",
            )
    if rules.choice("label_not_in_cad", HUMAN, ("robot", HUMAN)) != HUMAN:
        return None
    for end, pin in (("origin", step.origin), ("destination", step.destination)):
        geometry = model.components.get(pin.label)
        if geometry is None or not geometry.items:
            return Decision(
                HUMAN,
                "label-not-in-cad",
                f"{end} {pin.label} is not in the CAD (no item of the WRI table carries it)",
            )
    return None
