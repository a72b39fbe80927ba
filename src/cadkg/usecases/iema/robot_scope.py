"""Which wires of a cabinet the robot is handed, and why the others go to people.

A cabinet's connection list also names wires that are made off the mounting plate: the door's
push-buttons (zone ``P``), the motors (zone ``B``). The cell's software keeps only the rows of
the cabinet's own zones (``Q``, ``QE``); cadkg keeps every row and gives the others to a person,
with the rule and the value that decided it, so the planner, ``full_cad_service``, SPARQL
(``ck:assignmentReason`` in the derived graph) and ``cadkg validate`` all say the same thing.

The order of the decision: an assignment of the wire or of its operation (overlay file or
``cadkg assign``) wins; then the cabinet rule (:func:`scope_reason`); then an assignment of
either end's component to a person; else the robot.
"""

from __future__ import annotations

from collections.abc import Collection, Container, Iterable
from dataclasses import dataclass

from cadkg.mapping.writer import node_iri

__all__ = [
    "DEFAULT_ZONES",
    "LABEL_RULE",
    "ZONE_RULE",
    "Decision",
    "decide",
    "performers_of",
    "scope_reason",
    "scope_rule",
]

# The cabinet's zones in the IEMA exports: the manifest's [derive] robot_zones changes them.
DEFAULT_ZONES = ("Q", "QE")
# The names of the cabinet rule's two halves, as the planner reports them.
ZONE_RULE = "zone"
LABEL_RULE = "label-not-in-cad"


@dataclass(frozen=True, slots=True)
class Decision:
    """Who makes a wire, and the rule that decided it ('' when an assignment or nothing did)."""

    performer: str
    reason: str = ""


def scope_reason(
    zone: str | None, labels: Iterable[str], zones: Collection[str], known: Container[str]
) -> str | None:
    """Why a wire is outside the robot's cabinet, or None when it is inside.

    ``zone`` is the zone of the wire's origin as the list writes it: the wire is inside when it
    is one of ``zones``. A list without zones says nothing of them; then a wire is inside when
    every end's label is a label of the CAD (``known``: the ID table's labels).
    """
    if zone:
        if zone in zones:
            return None
        return f"zone {zone} is not among the robot zones {', '.join(zones)}"
    for label in labels:
        if label not in known:
            return f"label {label} is not in the CAD (no ID table row)"
    return None


def scope_rule(zone: str | None) -> str:
    """The half of the cabinet rule :func:`scope_reason` judges a wire by, given its origin zone."""
    return ZONE_RULE if zone else LABEL_RULE


def performers_of(assignments: Iterable[tuple[str, str, str]], base: str) -> dict[str, str]:
    """Target IRI → performer from (graph, target, performer): the source files first, then the
    edits graph (``cadkg assign``), so later edits win."""
    edits = base + "assignments"
    ordered = sorted(assignments, key=lambda a: a[0] == edits)
    return {target: who for _, target, who in ordered}


def decide(
    performers: dict[str, str],
    base: str,
    wire: tuple[str, str, int],
    ends: tuple[str, str],
    zone: str | None,
    zones: Collection[str],
    known: Container[str],
) -> Decision:
    """Who makes the wire ``(iri, number, list position)`` between the components ``ends``."""
    iri, number, position = wire
    assigned = (
        performers.get(iri)
        or performers.get(node_iri(base, "wire", number))
        or performers.get(node_iri(base, "operation", str(position)))
    )
    if assigned:
        return Decision(assigned)
    reason = scope_reason(zone, ends, zones, known)
    if reason is not None:
        return Decision("human", reason)
    for label in ends:
        if performers.get(node_iri(base, "component", label)) == "human":
            return Decision("human")
    return Decision("robot")
