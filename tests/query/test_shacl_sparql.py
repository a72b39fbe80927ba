"""The SHACL-to-SPARQL compiler on small inline shapes and graphs, pySHACL beside it."""

from __future__ import annotations

import pyoxigraph as ox
import pytest

import cadkg
from cadkg.errors import CadkgError, QueryError
from cadkg.query.shacl_shapes import UnsupportedShapeError, cadkg_shapes, read_shapes
from cadkg.query.shacl_sparql import ShapeResult, check_shapes
from tests.query.shacl_reference import pyshacl_results, result_keys

PREFIXES = """
@prefix sh:  <http://www.w3.org/ns/shacl#> .
@prefix xsd: <http://www.w3.org/2001/XMLSchema#> .
@prefix rdfs: <http://www.w3.org/2000/01/rdf-schema#> .
@prefix ck:  <https://w3id.org/cadkg#> .
@prefix ex:  <https://example.org/> .
"""
SH = "http://www.w3.org/ns/shacl#"
EX = "https://example.org/"


def _kg(**graphs: str) -> cadkg.KnowledgeGraph:
    kg = cadkg.KnowledgeGraph.memory()
    for name, turtle in graphs.items():
        kg._store.load(PREFIXES + turtle, ox.RdfFormat.TURTLE, to_graph=ox.NamedNode(EX + name))
    return kg


def _check(shapes: str, kg: cadkg.KnowledgeGraph, graphs: list[str] | None = None) -> list[ShapeResult]:
    """cadkg's results, asserted to be pySHACL's."""
    graphs = graphs if graphs is not None else kg.named_graphs()
    ours = check_shapes(kg, graphs, read_shapes(PREFIXES + shapes))
    assert result_keys(ours) == result_keys(pyshacl_results(kg, graphs, PREFIXES + shapes))
    return ours


def _found(results: list[ShapeResult]) -> set[tuple[str, str]]:
    return {(r.focus.removeprefix(EX), r.component.removesuffix("ConstraintComponent")) for r in results}


def test_cardinality_counts_a_value_stated_in_two_graphs_once() -> None:
    shapes = """ex:S a sh:NodeShape ; sh:targetClass ck:Wire ;
      sh:property [ sh:path ck:colour ; sh:maxCount 1 ; sh:minCount 1 ] ."""
    kg = _kg(
        a="ex:w1 a ck:Wire ; ck:colour 'BK' . ex:w2 a ck:Wire ; ck:colour 'BK' , 'RD' . ex:w3 a ck:Wire .",
        b="ex:w1 ck:colour 'BK' .",
    )
    assert _found(_check(shapes, kg)) == {("w2", "MaxCount"), ("w3", "MinCount")}


def test_targets_follow_subclasses_and_leave_other_graphs_out() -> None:
    shapes = """ex:S a sh:NodeShape ; sh:targetClass ck:Component ;
      sh:property [ sh:path ck:label ; sh:minCount 1 ] ."""
    # ck:TerminalBlock is a subclass of ck:Component in cadkg.ttl; graph c is not validated.
    kg = _kg(
        a="ex:x1 a ck:TerminalBlock . ex:c1 a ck:Component ; ck:label 'C1' .", c="ex:c2 a ck:Component ."
    )
    graphs = [g for g in kg.named_graphs() if g != EX + "c"]
    assert _found(_check(shapes, kg, graphs)) == {("x1", "MinCount")}
    # A value only the left-out graph states is no value.
    kg2 = _kg(a="ex:c1 a ck:Component .", c="ex:c1 ck:label 'C1' .")
    assert _found(_check(shapes, kg2, [g for g in kg2.named_graphs() if g != EX + "c"])) == {
        ("c1", "MinCount")
    }


def test_value_checks() -> None:
    shapes = """
    ex:S a sh:NodeShape ; sh:targetNode ex:n ; sh:property
      [ sh:path ex:d ; sh:datatype xsd:decimal ] , [ sh:path ex:k ; sh:nodeKind sh:IRI ] ,
      [ sh:path ex:i ; sh:in ( ex:a "b" 1 ) ] , [ sh:path ex:r ; sh:minInclusive 1 ; sh:maxExclusive 10 ] ,
      [ sh:path ex:p ; sh:pattern "^ab" ; sh:flags "i" ] , [ sh:path ex:c ; sh:class ck:Pin ] ,
      [ sh:path ex:o ; sh:or ( [ sh:datatype xsd:integer ] [ sh:nodeKind sh:IRI ] ) ] ,
      [ sh:path ex:e ; sh:disjoint ex:f ] , [ sh:path ex:t ; sh:datatype xsd:dateTime ] .
    """
    good = """ex:n ex:d 1.5 ; ex:k ex:a ; ex:i ex:a , "b" , 1 ; ex:r 1 , 9.5 ; ex:p "ABc" ; ex:c ex:pin ;
      ex:o 3 , ex:a ; ex:e ex:a ; ex:f ex:b ; ex:t "2024-05-01T12:00:00Z"^^xsd:dateTime . ex:pin a ck:Pin ."""
    assert _check(shapes, _kg(a=good)) == []
    bad = """ex:n ex:d "1.5" , "x"^^xsd:decimal ; ex:k "a" ; ex:i "a" , 1.0 ; ex:r 0 , 10 , "5" ; ex:p "cab" ;
      ex:c ex:frame , "pin" ; ex:o 1.5 ; ex:e ex:a ; ex:f ex:a ; ex:t "2024-13-01T00:00:00"^^xsd:dateTime .
      ex:frame a ck:Frame ."""
    found = {(r.path.removeprefix(EX) if r.path else "", r.component) for r in _check(shapes, _kg(a=bad))}
    assert found == {
        ("d", "DatatypeConstraintComponent"),
        ("k", "NodeKindConstraintComponent"),
        ("i", "InConstraintComponent"),
        ("r", "MinInclusiveConstraintComponent"),
        ("r", "MaxExclusiveConstraintComponent"),
        ("p", "PatternConstraintComponent"),
        ("c", "ClassConstraintComponent"),
        ("o", "OrConstraintComponent"),
        ("e", "DisjointConstraintComponent"),
        ("t", "DatatypeConstraintComponent"),
    }


def test_other_targets_severity_messages_and_deactivation() -> None:
    shapes = """
    ex:P a sh:PropertyShape ; sh:targetObjectsOf ck:fromPin ; sh:path ck:pinName ; sh:minCount 1 ;
      sh:severity sh:Warning ; sh:message "no name" .
    ex:Q a sh:NodeShape ; sh:targetSubjectsOf ck:fromPin ; sh:property [ sh:path ck:toPin ; sh:minCount 1 ] .
    ex:Off a sh:NodeShape ; sh:targetSubjectsOf ck:fromPin ; sh:deactivated true ;
      sh:property [ sh:path ck:colour ; sh:minCount 1 ] .
    ex:Cls a sh:NodeShape , rdfs:Class ; sh:property [ sh:path ck:label ; sh:minCount 1 ] .
    """
    kg = _kg(a="ex:w ck:fromPin ex:p . ex:thing a ex:Cls .")
    results = _check(shapes, kg)
    assert _found(results) == {("p", "MinCount"), ("w", "MinCount"), ("thing", "MinCount")}
    (warning,) = [r for r in results if r.focus == EX + "p"]
    assert (warning.severity, warning.message, warning.shape) == (SH + "Warning", "no name", EX + "P")
    # A shape without sh:message still says what is wrong.
    (missing,) = [r for r in results if r.focus == EX + "w"]
    assert missing.message == "fewer than 1 values" and missing.shape == f"{EX}Q/https://w3id.org/cadkg#toPin"


def test_sparql_constraints_see_the_focus_node_as_this() -> None:
    shapes = """
    ex:decl sh:declare [ sh:prefix "ck" ; sh:namespace "https://w3id.org/cadkg#"^^xsd:anyURI ] .
    ex:S a sh:NodeShape ; sh:targetClass ck:Wire ; sh:sparql [ sh:prefixes ex:decl ;
      sh:message "{$this} ends at {?value} twice ({?n})" ;
      sh:select '''SELECT $this ?value ?n WHERE {
        $this ck:toPin ?value . ?value ck:pinName ?n . $this ck:fromPin ?value }''' ] .
    ex:P a sh:PropertyShape ; sh:targetClass ck:Wire ; sh:path ck:lengthM ; sh:sparql [ sh:prefixes ex:decl ;
      sh:select "SELECT $this ?value WHERE { $this $PATH ?value FILTER(?value > 100) }" ] .
    """
    kg = _kg(
        a="""ex:w1 a ck:Wire ; ck:fromPin ex:p ; ck:toPin ex:p ; ck:lengthM 120.0 . ex:p ck:pinName "1" .
                  ex:w2 a ck:Wire ; ck:fromPin ex:p ; ck:toPin ex:q ; ck:lengthM 1.0 ."""
    )
    results = _check(shapes, kg)
    assert {(r.focus, r.path, r.shape) for r in results} == {
        (EX + "w1", None, EX + "S"),
        (EX + "w1", "https://w3id.org/cadkg#lengthM", EX + "P"),
    }
    assert f"{EX}w1 ends at {EX}p twice (1)" in {r.message for r in results}


def test_a_sparql_constraint_reporting_a_failure_is_an_error() -> None:
    shapes = """ex:S a sh:NodeShape ; sh:targetNode ex:n ;
      sh:sparql [ sh:select "SELECT $this ?failure WHERE { BIND(true AS ?failure) }" ] ."""
    with pytest.raises(QueryError, match="failed on"):
        check_shapes(_kg(a="ex:n ex:p 1 ."), [EX + "a"], read_shapes(PREFIXES + shapes))


@pytest.mark.parametrize(
    ("shape", "named"),
    [
        ("[ sh:path ( ck:a ck:b ) ; sh:minCount 1 ]", "sh:path"),
        ("[ sh:path [ sh:inversePath ck:a ] ; sh:minCount 1 ]", "sh:path"),
        ("[ sh:path ck:a ; sh:minLength 2 ]", "sh:minLength"),
        ("[ sh:path ck:a ; sh:node ex:Other ]", "sh:node"),
        (
            "[ sh:path ck:a ; sh:qualifiedValueShape [ sh:class ck:Pin ] ; sh:qualifiedMinCount 1 ]",
            "sh:qualified",
        ),
        ("[ sh:path ck:a ; sh:equals ck:b ]", "sh:equals"),
        ("[ sh:path ck:a ; sh:lessThan ck:b ]", "sh:lessThan"),
        ("[ sh:path ck:a ; sh:hasValue 1 ]", "sh:hasValue"),
        ("[ sh:path ck:a ; sh:uniqueLang true ]", "sh:uniqueLang"),
        ("[ sh:path ck:a ; sh:datatype xsd:gYear ]", "sh:datatype"),
        ("[ sh:path ck:a ; sh:or ( [ sh:minCount 1 ] ) ]", "sh:minCount"),
        ('[ sh:path ck:a ; sh:minCount 1 ; sh:message "one"@en , "un"@fr ]', "sh:message"),
    ],
)
def test_a_property_feature_the_compiler_does_not_run_is_an_error(shape: str, named: str) -> None:
    with pytest.raises(UnsupportedShapeError, match=named) as caught:
        read_shapes(PREFIXES + f"ex:S a sh:NodeShape ; sh:targetClass ck:Wire ; sh:property {shape} .")
    assert "does not run it" in str(caught.value)
    assert isinstance(caught.value, CadkgError)


@pytest.mark.parametrize(
    ("shape", "named"),
    [
        ("sh:targetClass ck:Wire ; sh:closed true", "sh:closed"),
        ("sh:targetClass ck:Wire ; sh:not [ sh:class ck:Pin ]", "sh:not"),
        ("sh:targetClass ck:Wire ; sh:and ( [ sh:class ck:Pin ] )", "sh:and"),
        ("sh:targetClass ck:Wire ; sh:xone ( [ sh:class ck:Pin ] )", "sh:xone"),
        ("sh:targetClass ck:Wire ; sh:class ck:Pin", "sh:class"),
        ("sh:target [ a ex:SomeTargetType ]", "sh:SPARQLTarget"),
        ('sh:targetClass ck:Wire ; sh:sparql [ sh:ask "ASK { }" ]', "sh:ask"),
        (
            'sh:targetClass ck:Wire ; sh:sparql [ sh:select "SELECT $this WHERE { $this ?p $shapesGraph }" ]',
            "shapesGraph",
        ),
        (
            'sh:targetClass ck:Wire ; sh:sparql [ sh:select "PREFIX a: <x:> SELECT $this WHERE { }" ]',
            "PREFIX",
        ),
        ("sh:property [ sh:path ck:a ; sh:minCount 1 ]", None),  # no target: never run, but it is read
    ],
)
def test_a_node_feature_the_compiler_does_not_run_is_an_error(shape: str, named: str | None) -> None:
    text = PREFIXES + f"ex:S a sh:NodeShape ; {shape} ."
    if named is None:
        assert read_shapes(text).shapes == ()
        return
    with pytest.raises(UnsupportedShapeError, match=named):
        read_shapes(text)


def test_an_untargeted_shape_with_an_unsupported_feature_is_an_error_too() -> None:
    with pytest.raises(UnsupportedShapeError, match="sh:minLength"):
        read_shapes(PREFIXES + "ex:S a sh:PropertyShape ; sh:path ck:a ; sh:minLength 1 .")


def test_every_targeted_shape_of_shapes_ttl_is_compiled() -> None:
    from cadkg.ontology.terms import ontology_path

    graph = ox.Store()
    graph.load(path=ontology_path("shapes.ttl"), format=ox.RdfFormat.TURTLE)
    targeted = {
        row["s"].value
        for row in graph.query(
            "SELECT DISTINCT ?s WHERE { ?s ?t ?o "
            "VALUES ?t { sh:targetClass sh:targetSubjectsOf sh:targetObjectsOf sh:targetNode sh:target } }",
            prefixes={"sh": SH},
        )
    }
    assert {shape.node for shape in cadkg_shapes().shapes} == targeted
    # Every shape gives its own message, so a finding reads the same from either engine.
    assert all(p.message for s in cadkg_shapes().shapes for p in s.properties)
    assert all(c.message for s in cadkg_shapes().shapes for c in s.sparql)


def test_well_formed_means_what_xsd_says() -> None:
    # pySHACL takes whatever Python's float(), int() and Decimal() accept; cadkg takes XSD's
    # lexical rules (docs/validation.md), so these are checked without pySHACL beside.
    shapes = """ex:S a sh:NodeShape ; sh:targetNode ex:n ;
      sh:property [ sh:path ex:v ; sh:or ( [ sh:datatype xsd:decimal ] [ sh:datatype xsd:double ]
                                            [ sh:datatype xsd:integer ] ) ] ."""
    bad = ['"1e5"^^xsd:decimal', '" 1.5"^^xsd:double', '"1_000"^^xsd:integer', '"inf"^^xsd:decimal']
    good = ['"1.5"^^xsd:decimal', '"1e5"^^xsd:double', '"INF"^^xsd:double', '"-7"^^xsd:integer']
    for value, broken in [(v, True) for v in bad] + [(v, False) for v in good]:
        kg = _kg(a=f"ex:n ex:v {value} .")
        results = check_shapes(kg, kg.named_graphs(), read_shapes(PREFIXES + shapes))
        assert bool(results) is broken, value


def test_a_sparql_constraint_without_a_message_says_the_shape_s() -> None:
    shapes = """ex:S a sh:NodeShape ; sh:targetNode ex:n ; sh:message "{$this} has {?value}" ;
      sh:sparql [ sh:select "SELECT $this ?value WHERE { $this <https://example.org/p> ?value }" ] ."""
    kg = _kg(a="ex:n ex:p 7 .")
    ours = _check(shapes, kg)
    assert [r.message for r in ours] == [f"{EX}n has 7"]
    assert [r.message for r in pyshacl_results(kg, kg.named_graphs(), PREFIXES + shapes)] == [f"{EX}n has 7"]
    both = shapes.replace(" ] .", ' ; sh:message "two" ] .')
    with pytest.raises(UnsupportedShapeError, match="sh:message on the shape and on its SPARQL"):
        read_shapes(PREFIXES + both)
