"""How the rows of a kind's queries gather into things: one value, several, none."""

from __future__ import annotations

import pyoxigraph as ox

from cadkg.changes.kinds import parse_kind
from cadkg.changes.things import read_things
from cadkg.store import GraphStore

EX = "https://example.org/t/"
CK = "https://w3id.org/cadkg#"
RDF_TYPE = "http://www.w3.org/1999/02/22-rdf-syntax-ns#type"
DECIMAL = ox.NamedNode("http://www.w3.org/2001/XMLSchema#decimal")

KIND = parse_kind(
    "wire",
    """# wire: a wire, by its number
SELECT ?thing ?id ?colour ?section WHERE {
  ?thing a ck:Wire ; ck:wireNumber ?id .
  OPTIONAL { ?thing ck:colour ?colour }
  OPTIONAL { ?thing ck:crossSectionMm2 ?section }
}
# ---
SELECT ?thing ?colour ?key_list WHERE { ?thing ck:altColour ?colour ; ck:inList ?key_list }
""",
)

Fact = tuple[str, str, ox.Literal | ox.NamedNode, str]


def _store(facts: list[Fact]) -> GraphStore:
    """A store of the quads ``(thing, property, value, graph)``."""
    kg = GraphStore.memory()
    kg._store.extend(
        ox.Quad(
            ox.NamedNode(EX + s),
            ox.NamedNode(RDF_TYPE if p == "a" else CK + p),
            o,
            ox.NamedNode(EX + g),
        )
        for s, p, o, g in facts
    )
    return kg


def _wire(name: str, number: str) -> list[Fact]:
    return [(name, "a", ox.NamedNode(CK + "Wire"), "list"), (name, "wireNumber", ox.Literal(number), "list")]


def test_one_value_several_none_and_a_later_querys() -> None:
    kg = _store(
        [
            *_wire("w1", "1"),
            ("w1", "colour", ox.Literal("RD"), "list"),
            ("w1", "colour", ox.Literal("RD"), "other"),  # the same value twice: one value
            ("w1", "crossSectionMm2", ox.Literal("1.50", datatype=DECIMAL), "list"),
            *_wire("w2", "2"),
            ("w2", "colour", ox.Literal("BU"), "list"),
            ("w2", "colour", ox.Literal("BK"), "list"),  # two values: both, sorted
            *_wire("w3", "3"),  # neither colour nor section
            *_wire("w4", "4"),
            ("w4", "colour", ox.Literal("GN"), "list"),
            ("w4", "inList", ox.Literal("L1"), "list"),
            ("w4", "altColour", ox.Literal("YE"), "list"),  # the second query adds a value ...
            ("w4", "altColour", ox.Literal("GN"), "plan"),  # ... and repeats the first
        ]
    )
    things = {t.id: t for t in read_things(kg, KIND)}
    assert things["1"].attributes == {"colour": "RD", "section": "1.5"}
    assert things["2"].attributes == {"colour": ("BK", "BU"), "section": None}
    assert things["3"].attributes == {"colour": None, "section": None}
    assert things["4"].attributes == {"colour": ("GN", "YE"), "section": None}
    assert things["4"].keys == {"key_list": "L1"} and things["1"].keys == {}
    assert {t.iri for t in things.values()} == {EX + n for n in ("w1", "w2", "w3", "w4")}
