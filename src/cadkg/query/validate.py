"""Validation of a cell graph: SHACL shapes plus semantic checks across files.

Every finding is located at the input file and line it came from, because the
person fixing it works in the EPLAN export, not in the graph.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Any, Literal

from cadkg.errors import format_location
from cadkg.registry import derivation, use_case
from cadkg.store import cell_profile

if TYPE_CHECKING:
    from cadkg.store import GraphStore

__all__ = ["Finding", "source_location", "validate"]

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


def source_location(kg: GraphStore, node: str) -> str:
    import pyoxigraph as ox

    result = kg.raw_query(
        "SELECT ?node ?path ?line WHERE {"
        " GRAPH ?g { ?node ck:sourceLine ?line } ?g ck:sourcePath ?path } LIMIT 1",
        {"node": ox.NamedNode(node)},
    )
    for solution in result:
        return format_location(solution["path"].value, int(solution["line"].value))
    return node


def _semantic(kg: GraphStore, progress: Callable[[str, int, int], None] | None) -> list[Finding]:
    def tick(done: int) -> None:
        if progress is not None:
            progress("checks", done, 3)

    def wire_errors(query: str, code: str, message: Callable[[Any], str]) -> list[Finding]:
        return [
            Finding(source_location(kg, row["wire"]), "error", code, message(row)) for row in kg.query(query)
        ]

    findings = wire_errors(
        _UNKNOWN_LABELS,
        "unknown-label",
        lambda row: f"component {row['label']!r} (pin {row['pinName']}) is not in any ID table",
    )
    tick(1)
    findings.extend(_duplicate_wire_numbers(kg))
    tick(2)
    findings += wire_errors(
        _PINS_WITHOUT_DATA,
        "pin-without-data",
        lambda row: (
            f"pin {row['label']}:{row['pinName']}{':' + row['level'] if row['level'] else ''} "
            "has no screw or hole position in any component model"
        ),
    )
    tick(3)
    return findings


def _use_case_checks(kg: GraphStore) -> list[Finding]:
    try:
        checks = use_case(cell_profile(kg)).checks
    except KeyError:
        return []
    return list(checks(kg)) if checks is not None else []


def _derived_graph(kg: GraphStore) -> list[Finding]:
    """An error when the derived graph is missing or empty while the cell model gives triples
    for it (a change cut short would leave it so): the robot's poses would be gone."""
    derive = derivation(cell_profile(kg))
    cell_model = getattr(kg, "cell_model", None)
    if derive is None or cell_model is None:
        return []
    model = cell_model()
    base = derive.base(model)
    if not base:
        return []
    graph = derive.graph(model)
    # Asked first: writing the graph's triples again only to see that there are some took
    # longer than every other check of a 10k-wire cabinet together.
    if kg.ask(f"ASK {{ GRAPH <{graph}> {{ ?s ?p ?o }} }}"):
        return []
    if not derive.ntriples(model, base, None).strip():
        return []
    where = str(getattr(kg, "directory", None) or graph)
    return [
        Finding(
            where,
            "error",
            "derived-graph",
            f"the derived graph <{graph}> is missing or empty, yet the cell model gives it triples "
            "(poses, keypoints); build the store again",
        )
    ]


def _duplicate_wire_numbers(kg: GraphStore) -> list[Finding]:
    """Wires sharing a number are fine when they form one chain through shared pins
    (EPLAN numbers potential jumpers that way); each further chain is an error."""
    import networkx as nx

    by_number: dict[tuple[str, str], list[Any]] = {}
    for row in kg.query(_WIRE_ENDS):
        by_number.setdefault((row["scope"] or "", row["number"]), []).append(row)
    findings = []
    for (_, number), rows in by_number.items():
        if len(rows) < 2:  # one wire is one chain: most numbers, no graph to make
            continue
        chains = nx.Graph()
        for row in rows:
            chains.add_edge(row["from"], row["to"], wire=row["wire"], order=row["sequence"] or 0)
        parts = [
            sorted((data["order"], data["wire"]) for _, _, data in chains.subgraph(nodes).edges(data=True))
            for nodes in nx.connected_components(chains)
        ]
        if len(parts) < 2:
            continue
        parts.sort()
        first = source_location(kg, parts[0][0][1])
        for part in parts[1:]:
            findings.append(
                Finding(
                    source_location(kg, part[0][1]),
                    "error",
                    "duplicate-wire-number",
                    f"wire number {number!r} already used at {first} for wires between other pins",
                )
            )
    return findings


def _shacl(kg: GraphStore, on_query: Callable[[int, int], None] | None = None) -> list[Finding]:
    from cadkg.query.shacl_shapes import SH, cadkg_shapes
    from cadkg.query.shacl_sparql import check_shapes
    from cadkg.store import GraphStore

    # What the files say, not the derived graph: cadkg writes that one from them (its poses
    # checked against these shapes by cadkg's tests), and in a cabinet it holds 70 % of the triples.
    graphs = kg.source_graphs()
    # The compiled shapes are pyoxigraph queries: on an external store they run on a local copy.
    local = GraphStore.of_quads(kg.quads(graphs)) if kg.remote else kg
    results = check_shapes(local, graphs, cadkg_shapes(), on_query=on_query)
    return [
        Finding(
            r.focus if r.focus.startswith("_:") else source_location(kg, r.focus),
            "error" if r.severity == SH + "Violation" else "warning",
            "shacl",
            f"<{r.focus}>: {r.message}" + (f" (property <{r.path}>)" if r.path is not None else ""),
        )
        for r in results
    ]


def validate(
    kg: GraphStore, *, shacl: bool = True, progress: Callable[[str, int, int], None] | None = None
) -> list[Finding]:
    """All findings, sorted by location: SHACL shapes (on every graph but the derived
    one), a derived graph missing or empty while the cell model gives it triples, unknown
    labels, duplicate wire numbers (wires of one number that do not form one chain through
    shared pins), pins whose component model has no data for them, and the
    checks of the cell's use case (:attr:`cadkg.usecase.UseCase.checks`; IEMA's: terminal
    diagram destinations that no connection list wires).

    ``progress(stage, done, total)`` is told of each step: stage ``"checks"`` (the semantic
    checks), then ``"shapes"`` (the queries the SHACL shapes compile to).
    """
    findings = _semantic(kg, progress)
    findings.extend(_derived_graph(kg))
    findings.extend(_use_case_checks(kg))
    if shacl:
        findings.extend(_shacl(kg, None if progress is None else partial(progress, "shapes")))
    return sorted(set(findings))
