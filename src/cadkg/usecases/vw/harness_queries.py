"""The SPARQL of the harness views (:mod:`cadkg.usecases.vw.harness_data` runs them).

Each query asks for few patterns: the store evaluates joins one lookup per row. Whether a
thing is the harness's (bound ``?h``) is a ``FILTER EXISTS`` closing the group, one lookup per
row the rest of the group found: a ``ck:partOf ?h`` pattern in the group would start the join
from every thing of the harness instead, and reading those things (250k at 100k wires) to keep
rows in Python costs more than the lookups.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from cadkg.store import GraphStore

__all__ = [
    "AT_NODES",
    "AT_NODES_ONLY",
    "BASE",
    "CAVITIES",
    "CONFIGURATIONS",
    "CONNECTORS",
    "HARNESSES",
    "IN_MODULE",
    "LOOSE_PINS",
    "MODULES",
    "NODES",
    "PLACED",
    "ROUTED",
    "ROUTINGS",
    "ROUTINGS_ONLY",
    "SEGMENTS",
    "STATED",
    "WIRE_VALUES",
    "wires_query",
]

HARNESSES = """
SELECT ?h ?label ?number ?description ?format WHERE {
  ?h a ck:Harness .
  OPTIONAL { ?h ck:label ?label }
  OPTIONAL { ?h ck:harnessNumber ?number }
  OPTIONAL { ?h ck:description ?description }
  OPTIONAL { ?h ck:fileFormat ?format }
}
"""
BASE = "SELECT ?cell WHERE { ?cell a ck:Cell } LIMIT 1"
SEGMENTS = """
SELECT ?s ?from ?to ?label ?length ?diameter ?section ?source WHERE {
  ?s a ck:Segment ; ck:segmentFrom ?from ; ck:segmentTo ?to .
  OPTIONAL { ?s ck:label ?label }
  OPTIONAL { ?s ck:lengthM ?length }
  OPTIONAL { ?s ck:diameterM ?diameter }
  OPTIONAL { ?s ck:bundleSectionMm2 ?section }
  OPTIONAL { ?s ck:lengthSource ?source }
  FILTER EXISTS { ?s ck:partOf ?h }
}
"""
# A node not of the harness is still shown where a segment of the harness ends at it: ?in.
NODES = """
SELECT ?n ?label ?x ?y ?z ?in WHERE {
  ?n a ck:HarnessNode .
  OPTIONAL { ?n ck:label ?label }
  OPTIONAL { ?n ck:nodeX ?x ; ck:nodeY ?y ; ck:nodeZ ?z }
  BIND (EXISTS { ?n ck:partOf ?h } AS ?in)
}
"""
AT_NODES = """
SELECT ?c ?n ?label ?in WHERE {
  ?c ck:atNode ?n .
  OPTIONAL { ?c ck:label ?label }
  BIND (EXISTS { ?n ck:partOf ?h } AS ?in)
}
"""
# The wires view does without the connectors' labels here: a lookup per connector, among its
# pins and cavities, that the connectors' query makes again.
AT_NODES_ONLY = """
SELECT ?c ?n ?label ?in WHERE {
  ?c ck:atNode ?n .
  BIND (EXISTS { ?n ck:partOf ?h } AS ?in)
}
"""
PLACED = """
SELECT ?x ?on ?type ?label WHERE {
  ?x ck:placedOn ?on ; a ?type .
  VALUES ?type { ck:Fixing ck:Protection }
  OPTIONAL { ?x ck:label ?label }
  FILTER EXISTS { ?x ck:partOf ?h }
}
"""
ROUTINGS = """
SELECT ?r ?w ?order ?label ?number WHERE {
  ?r ck:routingOf ?w ; ck:segmentOrder ?order .
  OPTIONAL { ?w ck:label ?label }
  OPTIONAL { ?w ck:wireNumber ?number }
  FILTER EXISTS { ?r ck:partOf ?h }
}
"""
ROUTINGS_ONLY = """
SELECT ?r ?w ?order ?label ?number WHERE {
  ?r ck:routingOf ?w ; ck:segmentOrder ?order .
  FILTER EXISTS { ?r ck:partOf ?h }
}
"""
ROUTED = """
SELECT ?w ?s ?label ?number WHERE {
  ?w ck:routedThrough ?s .
  OPTIONAL { ?w ck:label ?label }
  OPTIONAL { ?w ck:wireNumber ?number }
  FILTER EXISTS { ?w ck:partOf ?h }
}
"""
IN_MODULE = "SELECT ?x ?m WHERE { ?x ck:inModule ?m }"
MODULES = """
SELECT ?m ?label ?kind ?family ?familyLabel WHERE {
  ?m a ck:HarnessModule .
  OPTIONAL { ?m ck:label ?label }
  OPTIONAL { ?m ck:moduleKind ?kind }
  OPTIONAL { ?m ck:moduleFamily ?family . OPTIONAL { ?family ck:label ?familyLabel } }
  FILTER EXISTS { ?m ck:partOf ?h }
}
"""
CONFIGURATIONS = """
SELECT ?c ?label ?m WHERE {
  ?c a ck:HarnessConfiguration ; ck:configurationModule ?m .
  OPTIONAL { ?c ck:label ?label }
  FILTER EXISTS { ?c ck:partOf ?h }
}
"""
# The harness's connectors: those it has (directly or by a branch), and those part of it; each
# once before its label is looked up (a connector is a subject of some fifty statements).
CONNECTORS = """
SELECT ?c ?label WHERE {
  {
    SELECT DISTINCT ?c ?h WHERE {
      { ?h ck:hasConnector ?c } UNION { ?h ck:hasBranch/ck:hasConnector ?c }
      UNION { ?c a ck:Connector ; ck:partOf ?h }
    }
  }
  OPTIONAL { ?c ck:label ?label }
}
"""
CAVITIES = """
SELECT ?c ?cavity ?label ?index WHERE {
  ?c ck:hasCavity ?cavity .
  OPTIONAL { ?cavity ck:label ?label }
  OPTIONAL { ?cavity ck:pinIndex ?index }
}
"""
# A wire's ends are the cavities its pins are in; a pin in no cavity is told by its own name
# (the query gives the pin where there is no cavity: one term per end).
WIRE_VALUES = (
    ("label", "label"),
    ("number", "wireNumber"),
    ("section", "crossSectionMm2"),
    ("colour", "colour"),
    ("length", "lengthM"),
    ("diameter", "diameterM"),
    ("cable", "cableName"),
    ("signal", "potentialName"),
)
STATED = "ASK {{ ?s ck:{} ?o }}"


def wires_query(kg: GraphStore) -> str:
    """The wires and their values; a value no thing of the store states is left out of the
    query (every OPTIONAL is a lookup per wire)."""
    optional = "\n".join(
        f"  OPTIONAL {{ ?w ck:{term} ?{name} }}" for name, term in WIRE_VALUES if kg.ask(STATED.format(term))
    )
    names = " ".join(f"?{name}" for name, _ in WIRE_VALUES)
    return (
        f"SELECT ?w (COALESCE(?fromCavity, ?from) AS ?fromEnd) (COALESCE(?toCavity, ?to) AS ?toEnd)"
        f" {names} WHERE {{\n"
        "  ?w ck:fromPin ?from ; ck:toPin ?to .\n"
        "  OPTIONAL { ?from ck:inCavity ?fromCavity }\n"
        "  OPTIONAL { ?to ck:inCavity ?toCavity }\n"
        f"{optional}\n  FILTER EXISTS {{ ?w ck:partOf ?h }}\n}}"
    )


LOOSE_PINS = """
SELECT ?pin ?connector ?name ?index WHERE {
  ?pin ck:pinOf ?connector .
  FILTER NOT EXISTS { ?pin ck:inCavity ?cavity }
  OPTIONAL { ?pin ck:pinName ?name }
  OPTIONAL { ?pin ck:pinIndex ?index }
}
"""
