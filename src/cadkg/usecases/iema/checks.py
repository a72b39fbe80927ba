"""IEMA's own checks for ``cadkg validate``: what the terminal diagram and the connection
lists of one cabinet say differently, the wires a rule gave to people, the wire ends a list lost."""

from __future__ import annotations

from cadkg.query.validate import Finding, source_location
from cadkg.store import GraphStore

__all__ = ["cabinet_checks", "diagram_against_lists", "people_and_lost_ends"]

# The terminal diagram's wire ends beside the connection lists' (docs/formats/terminal-diagram.md).
_DIAGRAM_DESTINATIONS = """
SELECT DISTINCT ?row ?strip ?terminal ?stripZone ?ref ?zone WHERE {
  ?block ck:hasDiagramRow ?row ; ck:label ?strip .
  ?row ck:diagramTerminal ?terminal ; ck:hasDiagramDestination ?destination .
  ?destination ck:diagramDestination ?ref .
  OPTIONAL { ?row ck:diagramZone ?stripZone } OPTIONAL { ?destination ck:diagramZone ?zone }
}
"""
# Ends and pins apart, joined in Python: one query joining both through property paths took
# minutes on a 366-wire cabinet.
_LIST_WIRES = """
SELECT DISTINCT ?from ?to WHERE { ?wire a ck:Wire ; ck:inPlan ?plan ; ck:fromPin ?from ; ck:toPin ?to }
"""
_PINS = """
SELECT DISTINCT ?pin ?label ?name ?level WHERE {
  ?pin a ck:Pin ; ck:pinName ?name ; ck:pinOf ?component . ?component ck:label ?label .
  OPTIONAL { ?pin ck:level ?level }
}
"""


def diagram_against_lists(kg: GraphStore) -> list[Finding]:
    """A terminal diagram's destination with no wire in the connection lists: one finding each.

    Only where both can be compared: the destination in the strip's own zone (when the diagram
    gives zones), and both the strip and the destination's device in some connection list, for
    a list of the cabinet leaves the field wiring out.
    """
    from cadkg.ingest.eplan.labels import PinSyntaxError, parse_pin_ref

    rows = kg.query(_DIAGRAM_DESTINATIONS).rows
    if not rows:
        return []
    wires: set[tuple[str, str, str, str | None]] = set()
    listed: set[str] = set()
    pins = {row["pin"]: (row["label"], row["name"], row["level"]) for row in kg.query(_PINS)}
    for end in kg.query(_LIST_WIRES):
        a, b = pins.get(end["from"]), pins.get(end["to"])
        if a is None or b is None:
            continue
        for (label, pin, _), (other, other_pin, level) in ((a, b), (b, a)):
            wires.add((label, pin, f"{other}:{other_pin}", level))
            listed.add(label)
    findings = []
    for row in rows:
        if row["stripZone"] and row["zone"] and row["stripZone"] != row["zone"]:
            continue
        try:
            ref = parse_pin_ref(row["ref"])
        except PinSyntaxError:
            continue  # a device without a pin, or a pin without its device: nothing to compare
        if row["strip"] not in listed or ref.component not in listed:
            continue
        found = {
            level
            for s, t, other, level in wires
            if (s, t) == (row["strip"], row["terminal"]) and other == f"{ref.component}:{ref.pin}"
        }
        if not found or (ref.level is not None and ref.level not in found and None not in found):
            findings.append(
                Finding(
                    source_location(kg, row["row"]),
                    "warning",
                    "diagram-vs-list",
                    f"the terminal diagram puts {row['ref']} on {row['strip']}:{row['terminal']};"
                    " no connection list has that wire",
                )
            )
    return findings


# The derived graph's rule decisions (robot_scope), and the wires whose list lost an end's reference.
_FOR_PEOPLE = """
SELECT DISTINCT ?wire ?number ?reason WHERE { ?wire ck:wireNumber ?number ; ck:assignmentReason ?reason }
"""
_LOST_ENDS = """
SELECT DISTINCT ?wire ?number ?end WHERE {
  ?wire a ck:Wire ; ck:wireNumber ?number .
  { ?wire ck:fromPin ?pin BIND("origin" AS ?end) } UNION { ?wire ck:toPin ?pin BIND("destination" AS ?end) }
  ?pin ck:pinName "?" ; ck:pinOf/ck:label "?" .
}
"""


def people_and_lost_ends(kg: GraphStore) -> list[Finding]:
    """One finding per wire the cabinet rule gave to a person (with the rule and the value), and
    per wire end the list lost (``#NAME?`` or an empty cell), kept with missing pin data."""
    findings = [
        Finding(
            source_location(kg, row["wire"]),
            "warning",
            "wire-for-a-person",
            f"wire {row['number']} is given to a person: {row['reason']}",
        )
        for row in kg.query(_FOR_PEOPLE)
    ]
    findings += [
        Finding(
            source_location(kg, row["wire"]),
            "warning",
            "lost-wire-end",
            f"wire {row['number']}: the list gives no reference for its {row['end']};"
            " it is kept with missing pin data",
        )
        for row in kg.query(_LOST_ENDS)
    ]
    return findings


def cabinet_checks(kg: GraphStore) -> list[Finding]:
    """Every IEMA check of :mod:`cadkg.usecases.iema.checks`."""
    return diagram_against_lists(kg) + people_and_lost_ends(kg)
