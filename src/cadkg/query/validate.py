"""Validation of a cell graph: SHACL shapes plus semantic checks across files.

Every finding is located at the input file and line it came from, because the
person fixing it works in the EPLAN export, not in the graph.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

from cadkg.errors import format_location
from cadkg.ontology.terms import ontology_path

if TYPE_CHECKING:
    from cadkg.store import GraphStore

__all__ = ["Finding", "validate"]

Severity = Literal["error", "warning"]


@dataclass(frozen=True, order=True)
class Finding:
    """One problem: where it is, how bad, which check found it and what it is."""

    location: str
    severity: Severity
    check: str
    message: str

    def __str__(self) -> str:
        return f"{self.location}: {self.severity}: {self.message} [{self.check}]"


_UNKNOWN_LABELS = """
SELECT DISTINCT ?wire ?label ?pinName ?node WHERE {
  FILTER EXISTS { ?anyItem a ck:CadItem }
  # Wires of a connection list (a plan): harness cables end at connectors, not at CAD items.
  ?wire a ck:Wire ; ck:inPlan ?plan .
  { ?wire ck:fromPin ?pin } UNION { ?wire ck:toPin ?pin }
  ?pin ck:pinOf ?component ; ck:pinName ?pinName .
  ?component ck:label ?label .
  FILTER NOT EXISTS { ?component ck:hasItem ?item }
  FILTER NOT EXISTS { ?component a ck:Duct }
  BIND(?wire AS ?node)
}
"""

_WIRE_ENDS = """
SELECT DISTINCT ?wire ?number ?from ?to ?sequence ?scope WHERE {
  ?wire a ck:Wire ; ck:wireNumber ?number ; ck:fromPin ?from ; ck:toPin ?to .
  OPTIONAL { ?wire ck:sequenceIndex ?sequence }
  # Wire numbers are unique within a harness (directly or through its cable), else within the cell.
  OPTIONAL { ?wire ck:partOf+ ?scope . ?scope a ck:Harness }
}
"""

# The derivation flags pins no model places; that is a finding only once component
# models are loaded at all (a cell of ID table and connection list alone has none).
_PINS_WITHOUT_DATA = """
SELECT DISTINCT ?wire ?label ?pinName ?level WHERE {
  { ?wire ck:fromPin ?pin } UNION { ?wire ck:toPin ?pin }
  ?pin ck:missingPinData true ; ck:pinOf/ck:label ?label ; ck:pinName ?pinName .
  OPTIONAL { ?pin ck:level ?level }
  FILTER EXISTS { ?anyModel ck:definesPin ?anyModelPin }
}
ORDER BY ?wire
"""


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


def _diagram_against_lists(kg: GraphStore) -> list[Finding]:
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
                    _where(kg, row["row"]),
                    "warning",
                    "diagram-vs-list",
                    f"the terminal diagram puts {row['ref']} on {row['strip']}:{row['terminal']};"
                    " no connection list has that wire",
                )
            )
    return findings


def _where(kg: GraphStore, node: str) -> str:
    import pyoxigraph as ox

    result = kg.raw_query(
        "SELECT ?node ?path ?line WHERE {"
        " GRAPH ?g { ?node ck:sourceLine ?line } ?g ck:sourcePath ?path } LIMIT 1",
        {"node": ox.NamedNode(node)},
    )
    for solution in result:
        return format_location(solution["path"].value, int(solution["line"].value))
    return node


def _semantic(kg: GraphStore) -> list[Finding]:
    findings = []
    for row in kg.query(_UNKNOWN_LABELS):
        findings.append(
            Finding(
                _where(kg, row["wire"]),
                "error",
                "unknown-label",
                f"component {row['label']!r} (pin {row['pinName']}) is not in any ID table",
            )
        )
    findings.extend(_duplicate_wire_numbers(kg))
    findings.extend(_diagram_against_lists(kg))
    for row in kg.query(_PINS_WITHOUT_DATA):
        findings.append(
            Finding(
                _where(kg, row["wire"]),
                "error",
                "pin-without-data",
                f"pin {row['label']}:{row['pinName']}{':' + row['level'] if row['level'] else ''} "
                "has no screw or hole position in any component model",
            )
        )
    return findings


def _duplicate_wire_numbers(kg: GraphStore) -> list[Finding]:
    """Wires sharing a number are fine when they form one chain through shared pins
    (EPLAN numbers potential jumpers that way); each further chain is an error."""
    import networkx as nx

    by_number: dict[tuple[str, str], nx.Graph] = {}
    for row in kg.query(_WIRE_ENDS):
        chains = by_number.setdefault((row["scope"] or "", row["number"]), nx.Graph())
        chains.add_edge(row["from"], row["to"], wire=row["wire"], order=row["sequence"] or 0)
    findings = []
    for (_, number), chains in by_number.items():
        parts = [
            sorted((data["order"], data["wire"]) for _, _, data in chains.subgraph(nodes).edges(data=True))
            for nodes in nx.connected_components(chains)
        ]
        if len(parts) < 2:
            continue
        parts.sort()
        first = _where(kg, parts[0][0][1])
        for part in parts[1:]:
            findings.append(
                Finding(
                    _where(kg, part[0][1]),
                    "error",
                    "duplicate-wire-number",
                    f"wire number {number!r} already used at {first} for wires between other pins",
                )
            )
    return findings


def _shacl(kg: GraphStore) -> list[Finding]:
    import pyshacl
    import rdflib
    from rdflib.namespace import SH

    # What the files say, not the derived graph: cadkg writes that one from them (its poses
    # checked against these shapes by cadkg's tests), and in a cabinet it holds 70 % of the
    # triples and took 70 % of the SHACL time.
    data = rdflib.Graph()
    data.parse(data=kg.serialize("nt", graphs=kg.source_graphs()), format="nt")
    shapes = rdflib.Graph().parse(ontology_path("shapes.ttl"), format="turtle")
    ontology = rdflib.Graph().parse(ontology_path("cadkg.ttl"), format="turtle")
    conforms, report, _ = pyshacl.validate(
        data, shacl_graph=shapes, ont_graph=ontology, inference="none", advanced=True
    )
    if conforms:
        return []
    findings = []
    for result in report.subjects(rdflib.RDF.type, SH.ValidationResult):
        focus = report.value(result, SH.focusNode)
        severity = report.value(result, SH.resultSeverity)
        message = report.value(result, SH.resultMessage)
        path = report.value(result, SH.resultPath)
        what = str(message) if message else "violates a shape"
        if path is not None:
            what += f" (property {path.n3(data.namespace_manager)})"
        findings.append(
            Finding(
                _where(kg, str(focus)) if isinstance(focus, rdflib.URIRef) else str(focus),
                "error" if severity == SH.Violation else "warning",
                "shacl",
                f"<{focus}>: {what}",
            )
        )
    return findings


def validate(kg: GraphStore, *, shacl: bool = True) -> list[Finding]:
    """All findings, sorted by location: SHACL shapes (on every graph but the derived
    one), unknown labels, duplicate wire numbers (wires of one number that do not form one
    chain through shared pins), pins whose component model has no data for them, terminal
    diagram destinations that no connection list wires."""
    findings = _semantic(kg)
    if shacl:
        findings.extend(_shacl(kg))
    return sorted(set(findings))
