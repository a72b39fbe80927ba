"""Which wires of a cabinet the robot is handed, and why the others go to people.

A cabinet's connection list also names wires that are made off the mounting plate: the door's
push-buttons (zone ``P``), the motors (zone ``B``). The cell's software keeps the rows whose
origin is in the cabinet's own zones (``Q``, ``QE``); cadkg keeps every row and gives a person
each wire one of whose ends is outside them (the robot reaches neither a door nor a motor),
with the rule and the value that decided it, so the planner, ``full_cad_service``, SPARQL
(``ck:assignmentReason`` in the derived graph) and ``cadkg validate`` all say the same thing.

The decision itself is the core's (:func:`cadkg.plan.decision.decide`): this module supplies
its IEMA half, the cabinet rule (:class:`CabinetRule`) and the names a wire and its ends'
components are assigned by.
"""

from __future__ import annotations

from collections.abc import Collection, Container, Iterable
from dataclasses import dataclass
from functools import partial

from cadkg.mapping.writer import node_iri
from cadkg.plan.decision import ASSIGNED, Assignments, Decision, Performer, decide

__all__ = [
    "DEFAULT_ZONES",
    "LABEL_RULE",
    "ZONE_RULE",
    "CabinetRule",
    "WireFacts",
    "assignments_of",
    "cell_decision",
    "names_of",
    "parts_of",
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
class WireFacts:
    """What the cabinet rule judges a wire by: its number and list position (what it is
    assigned by), the zones of its origin and destination as the list writes them, its ends'
    component labels."""

    number: str
    position: int
    zones: tuple[str | None, str | None]
    labels: tuple[str, str]


def scope_reason(
    ends: tuple[str | None, str | None], labels: Iterable[str], zones: Collection[str], known: Container[str]
) -> str | None:
    """Why a wire is outside the robot's cabinet, or None when it is inside.

    ``ends`` are the zones of the wire's origin and destination as the list writes them: the
    wire is inside when each end the list gives a zone is in one of ``zones`` (the robot reaches
    both ends; an end without a zone is not judged). A list without zones says nothing of them;
    then a wire is inside when every end's label is a label of the CAD (``known``: the ID
    table's labels).
    """
    if any(ends):
        for end, zone in zip(("origin", "destination"), ends, strict=True):
            if zone and zone not in zones:
                return f"{end} zone {zone} is not among the robot zones {', '.join(zones)}"
        return None
    for label in labels:
        if label not in known:
            return f"label {label} is not in the CAD (no ID table row)"
    return None


def scope_rule(ends: tuple[str | None, str | None]) -> str:
    """The half of the cabinet rule :func:`scope_reason` judges a wire by, given its ends' zones."""
    return ZONE_RULE if any(ends) else LABEL_RULE


@dataclass(frozen=True, slots=True)
class CabinetRule:
    """The cabinet rule as the core decision's scope rule: a wire outside ``zones`` (or, when
    the list gives no zone, with an end's label not among ``known``) is a person's."""

    zones: Collection[str]
    known: Container[str]

    def __call__(self, wire: WireFacts) -> Decision | None:
        reason = scope_reason(wire.zones, wire.labels, self.zones, self.known)
        return None if reason is None else Decision(Performer.HUMAN, scope_rule(wire.zones), reason)


def names_of(wire: WireFacts) -> tuple[tuple[str, str], ...]:
    """What an assignment of the wire itself names: its number, then its list position."""
    return (("wire", wire.number), ("operation", str(wire.position)))


def parts_of(wire: WireFacts) -> tuple[tuple[str, str], ...]:
    """What an assignment of a thing the wire joins names: its ends' components."""
    return tuple(("component", label) for label in wire.labels)


def performers_of(assignments: Iterable[tuple[str, str, str]], base: str) -> dict[str, str]:
    """Target IRI → performer from (graph, target, performer): the source files first, then the
    edits graph (``cadkg assign``), so later edits win."""
    edits = base + "assignments"
    ordered = sorted(assignments, key=lambda a: a[0] == edits)
    return {target: who for _, target, who in ordered}


def assignments_of(
    performers: dict[str, str], base: str, wires: Iterable[tuple[str, int]], labels: Iterable[str]
) -> Assignments:
    """The assignments of a cabinet's wires (number, list position) and components by kind and
    id: each thing's IRI minted as the mapping mints it, looked up among ``performers``."""
    things: dict[tuple[str, str], None] = {}
    for number, position in wires:
        things[("wire", number)] = None
        things[("operation", str(position))] = None
    things.update(dict.fromkeys(("component", label) for label in labels))
    return Assignments.of_targets(performers, things, partial(node_iri, base))


def cell_decision(wire: WireFacts, assignments: Assignments, cabinet: CabinetRule) -> tuple[Performer, str]:
    """The cell's own decision on a wire, without the robot's abilities (those are a rules
    file's, the plan's): who, and the cabinet rule's reason ('' when no rule decided: an
    assignment's reason is the planner's to word)."""
    decision = decide(wire, assignments, names_of(wire), scope=cabinet, parts=parts_of(wire))
    return decision.performer, "" if decision.rule == ASSIGNED else decision.reason
