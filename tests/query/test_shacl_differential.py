"""cadkg's SHACL engine (shapes compiled to SPARQL) against pySHACL, result for result.

On every example cell, on every graph the shape tests validate, and on good cells broken at
random with fixed seeds (triples removed, copied, given a second value, altered, retyped), both
engines must report the same (focus node, path, constraint component, shape, severity) and
the same messages. Between them the graphs must break every constraint of every shape in
``shapes.ttl``, so that no shape agrees only by never being tested.
"""

from __future__ import annotations

import inspect
import random
import time
from collections.abc import Iterator
from pathlib import Path

import pyoxigraph as ox
import pytest

import cadkg
from cadkg.ontology.terms import ONTOLOGY_IRI
from cadkg.query.shacl_shapes import AnyOf, cadkg_shapes
from cadkg.query.shacl_sparql import ShapeResult, check_shapes
from cadkg.query.validate import validate
from tests.conftest import ROOT
from tests.ontology import test_ontology_files as shape_tests
from tests.query.shacl_reference import pyshacl_results, result_keys

# pySHACL, the reference, takes minutes on the examples and the seeded graphs.
pytestmark = pytest.mark.slow

EXAMPLES = sorted((ROOT / "examples").glob("*/manifest*.toml"))
# Good cells to break: wires, poses and a plan; routes and waypoints; harness models and tools.
SEEDED = ["iema-switchgear", "elimco-bench", "elvez-cell"]
SEEDS = range(5)
EXTRA_MUTATIONS = 5
XSD = "http://www.w3.org/2001/XMLSchema#"
RDF_TYPE = ox.NamedNode("http://www.w3.org/1999/02/22-rdf-syntax-ns#type")
DATA = "https://example.org/shape-test-data"


def _agree(kg: cadkg.KnowledgeGraph, graphs: list[str]) -> list[ShapeResult]:
    """Both engines' results on ``graphs``; asserts they agree and gives cadkg's."""
    ours = check_shapes(kg, graphs, cadkg_shapes())
    theirs = pyshacl_results(kg, graphs)
    assert sorted(result_keys(ours), key=str) == sorted(result_keys(theirs), key=str)
    # Messages name their focus node, so a blank one (labelled apart by each engine) is left out.
    assert {r for r in ours if "_:" not in r.message} == {r for r in theirs if "_:" not in r.message}
    return ours


@pytest.mark.parametrize("manifest", EXAMPLES, ids=lambda m: f"{m.parent.name}/{m.name}")
def test_the_engines_agree_on_every_example(manifest: Path) -> None:
    kg = cadkg.build(manifest)
    ours = _agree(kg, kg.source_graphs())
    # And cadkg validate reports them, each located where its focus node was stated.
    shacl = [f for f in validate(kg) if f.check == "shacl"]
    assert {f.message.split(">: ", 1)[1].split(" (property")[0] for f in shacl} == {r.message for r in ours}


# -- the graphs of the shape tests ---------------------------------------------------------
def _shape_test_graphs() -> list[str]:
    """The Turtle of every graph tests/ontology's shape tests validate, recorded as they run."""
    recorded: list[str] = []
    original = shape_tests._validate

    def recording(data_ttl: str, ontology: object, shapes: object) -> object:
        recorded.append(shape_tests.PREFIXES + data_ttl)
        return original(data_ttl, ontology, shapes)  # type: ignore[arg-type]

    ontology, shapes = shape_tests._parse(shape_tests.CADKG_TTL), shape_tests._parse(shape_tests.SHAPES_TTL)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(shape_tests, "_validate", recording)
        for name, test in sorted(vars(shape_tests).items()):
            params = set(inspect.signature(test).parameters) if name.startswith("test_") else set()
            if not params or not {"ontology", "shapes"} <= params:
                continue
            calls: list[dict[str, object]] = [{}]
            for mark in getattr(test, "pytestmark", []):
                if mark.name == "parametrize":
                    calls = [{mark.args[0]: value} for value in mark.args[1]]
            if params - {"ontology", "shapes"} - {k for call in calls for k in call}:
                continue
            for call in calls:
                test(ontology=ontology, shapes=shapes, **call)
    return recorded


def _graph_of(turtle: str) -> cadkg.KnowledgeGraph:
    kg = cadkg.KnowledgeGraph.memory()
    kg._store.load(turtle, ox.RdfFormat.TURTLE, to_graph=ox.NamedNode(DATA))
    return kg


@pytest.fixture(scope="module")
def shape_test_results() -> list[list[ShapeResult]]:
    graphs = _shape_test_graphs()
    assert len(graphs) >= 20  # every shape test's graph, not none by a change in that module
    return [_agree(kg, kg.named_graphs()) for kg in map(_graph_of, graphs)]


def test_the_engines_agree_on_the_shape_tests_graphs(shape_test_results: list[list[ShapeResult]]) -> None:
    assert sum(map(len, shape_test_results)) > 0


# -- good cells broken at random ------------------------------------------------------------
def _literal_variants(o: ox.Literal, rng: random.Random) -> list[ox.Term]:
    dt = o.datatype.value
    text = o.value
    variants: list[ox.Term] = [
        ox.Literal(text, language="en"),
        ox.Literal("abc", datatype=o.datatype),  # ill-typed unless a string
        ox.NamedNode("https://example.org/not-a-literal"),
    ]
    if dt in (XSD + "integer", XSD + "decimal", XSD + "double"):
        number = float(text)
        variants += [
            ox.Literal(text),  # the number as a string
            ox.Literal("0", datatype=ox.NamedNode(XSD + "integer")),
            ox.Literal(repr(-abs(number) - 1.0), datatype=o.datatype if dt != XSD + "integer" else None),
            ox.Literal(repr(number + rng.choice((0.5, 0.25))), datatype=ox.NamedNode(XSD + "double")),
            ox.Literal(str(int(number) - 1), datatype=ox.NamedNode(XSD + "integer")),
        ]
    elif dt == XSD + "string":
        variants += [ox.Literal(text + "X"), ox.Literal("7", datatype=ox.NamedNode(XSD + "integer"))]
    else:
        variants.append(ox.Literal(text))
    return variants


OPERATIONS = ("remove", "copy", "second", "break", "replace")
ANY_OPERATIONS = ("remove", "copy", "second", "replace", "replace")


def _surely_broken(q: ox.Quad) -> ox.Quad:
    """``q`` altered so that it breaks any shape on its predicate: a literal given a language, a
    node given a literal."""
    o = ox.Literal(q.object.value, language="en") if isinstance(q.object, ox.Literal) else ox.Literal("x")
    return ox.Quad(q.subject, q.predicate, o, q.graph_name)


def _classes(quads: list[ox.Quad]) -> dict[str, frozenset[str]]:
    """The classes of each subject, by the subject's N-Triples form."""
    types: dict[str, set[str]] = {}
    for q in quads:
        if q.predicate == RDF_TYPE:
            types.setdefault(str(q.subject), set()).add(str(q.object))
    return {subject: frozenset(classes) for subject, classes in types.items()}


def _mutate(quads: list[ox.Quad], seed: int, relevant: set[str]) -> list[ox.Quad]:
    """``quads`` with a change to a triple of each predicate a shape looks at, and a few to any.

    The predicates take turns through OPERATIONS as the seed grows, so that over the seeds each
    is removed, copied into another graph, given a second value, broken and altered; which
    triple, and what it is altered to, is the seed's random choice.
    """
    rng = random.Random(seed)
    quads = list(quads)
    graphs = sorted({q.graph_name.value for q in quads if isinstance(q.graph_name, ox.NamedNode)})
    predicates = sorted({q.predicate.value for q in quads} & relevant)
    classes = _classes(quads)
    # A break alters a triple of the predicate on a subject of every class that has it, in a
    # way that breaks any shape on it: every constraint is broken whatever the examples hold
    # and whichever triples the seed picks.
    changes: list[tuple[str | None, str]] = [
        (p, OPERATIONS[(rank + seed) % len(OPERATIONS)]) for rank, p in enumerate(predicates)
    ]
    changes += [(None, rng.choice(ANY_OPERATIONS)) for _ in range(EXTRA_MUTATIONS)]
    for predicate, operation in changes:
        candidates = [x for x in quads if predicate is None or x.predicate.value == predicate]
        if operation == "break":
            by_class: dict[frozenset[str], list[ox.Quad]] = {}
            for x in candidates:
                by_class.setdefault(classes.get(str(x.subject), frozenset()), []).append(x)
            for kind in sorted(by_class, key=sorted):
                q = rng.choice(by_class[kind])
                quads[quads.index(q)] = _surely_broken(q)
            continue
        q = rng.choice(candidates)
        if operation == "remove":
            quads.remove(q)
            continue
        if operation == "copy":
            quads.append(ox.Quad(q.subject, q.predicate, q.object, ox.NamedNode(rng.choice(graphs))))
            continue
        same_predicate = [x.object for x in quads if x.predicate == q.predicate and x.object != q.object]
        same_subject = [x.object for x in quads if x.subject == q.subject and x.object != q.object]
        if isinstance(q.object, ox.Literal):
            choices = _literal_variants(q.object, rng) + rng.sample(
                same_predicate, min(3, len(same_predicate))
            )
        else:
            choices = (
                rng.sample(same_predicate, min(5, len(same_predicate))) + same_subject[:5] + [ox.Literal("x")]
            )
        new = ox.Quad(q.subject, q.predicate, rng.choice(choices), q.graph_name)
        if operation == "replace":
            quads.remove(q)
        quads.append(new)
    return quads


def _shape_paths() -> set[str]:
    shapes = cadkg_shapes().shapes
    paths = {p.path for s in shapes for p in s.properties}
    return paths | {"http://www.w3.org/1999/02/22-rdf-syntax-ns#type", "https://w3id.org/cadkg#inPlan",
                    "https://w3id.org/cadkg#hasWaypoint"}  # fmt: skip


INGESTED_AT = ox.NamedNode("https://w3id.org/cadkg#ingestedAt")
A_FIXED_TIME = ox.Literal("2026-01-01T00:00:00Z", datatype=ox.NamedNode(XSD + "dateTime"))


def _at_a_fixed_time(q: ox.Quad) -> ox.Quad:
    return ox.Quad(q.subject, q.predicate, A_FIXED_TIME, q.graph_name) if q.predicate == INGESTED_AT else q


def _good_quads(example: str) -> list[ox.Quad]:
    """The source graphs of a built example, in one order, the build's clock held fixed: it is
    the one thing that differs between two builds, and the seeds must break the same triples
    in the same way on every run."""
    good = cadkg.build(ROOT / "examples" / example / "manifest.toml")
    graphs = set(good.source_graphs()) - {ONTOLOGY_IRI}
    chosen = (q for q in good.quads() if q.graph_name.value in graphs)  # type: ignore[union-attr]
    return sorted(map(_at_a_fixed_time, chosen), key=str)


def _seeded_cells() -> Iterator[tuple[str, cadkg.KnowledgeGraph]]:
    relevant = _shape_paths()
    for example in SEEDED:
        quads = _good_quads(example)
        for seed in SEEDS:
            broken = cadkg.KnowledgeGraph.memory()
            broken._store.extend(_mutate(quads, seed, relevant))
            yield f"{example}-{seed}", broken


def test_a_seed_breaks_a_cell_the_same_way_on_every_build() -> None:
    first = _good_quads("elimco-bench")
    time.sleep(1.1)  # the next build's clock reads another second
    second = _good_quads("elimco-bench")
    relevant = _shape_paths()
    assert all(_mutate(first, seed, relevant) == _mutate(second, seed, relevant) for seed in SEEDS)


@pytest.fixture(scope="module")
def seeded_results() -> dict[str, list[ShapeResult]]:
    return {name: _agree(kg, kg.named_graphs()) for name, kg in _seeded_cells()}


def test_the_engines_agree_on_seeded_broken_graphs(seeded_results: dict[str, list[ShapeResult]]) -> None:
    assert len(seeded_results) == len(SEEDED) * len(SEEDS)
    # Every broken cell is found broken: the mutations reach what the shapes look at.
    assert all(seeded_results.values()), [name for name, results in seeded_results.items() if not results]


def _constraints() -> set[tuple[str, str]]:
    """(shape, constraint component) of every constraint in shapes.ttl."""
    pairs = set()
    for shape in cadkg_shapes().shapes:
        pairs |= {(shape.node, "SPARQLConstraintComponent") for _ in shape.sparql}
        for prop in shape.properties:
            pairs |= {(prop.node, check.component) for check in prop.checks}
            if prop.min_count is not None:
                pairs.add((prop.node, "MinCountConstraintComponent"))
            if prop.max_count is not None:
                pairs.add((prop.node, "MaxCountConstraintComponent"))
    assert any(isinstance(c, AnyOf) for s in cadkg_shapes().shapes for p in s.properties for c in p.checks)
    return pairs


def test_every_constraint_of_every_shape_was_broken_and_agreed_on(
    shape_test_results: list[list[ShapeResult]], seeded_results: dict[str, list[ShapeResult]]
) -> None:
    seen = {(r.shape, r.component) for results in shape_test_results for r in results}
    seen |= {(r.shape, r.component) for results in seeded_results.values() for r in results}
    assert sorted(_constraints() - seen) == [], sorted(seen)
