"""Checks of the cadkg ontology, its VEC alignment and its SHACL shapes."""

from __future__ import annotations

from pathlib import Path

import pytest
from rdflib import Graph, Literal, Namespace, URIRef
from rdflib.namespace import OWL, RDF, RDFS, SH

pyshacl = pytest.importorskip("pyshacl")

REPO = Path(__file__).resolve().parents[2]
ONTOLOGY_DIR = REPO / "src" / "cadkg" / "ontology"
CADKG_TTL = ONTOLOGY_DIR / "cadkg.ttl"
ALIGNMENT_TTL = ONTOLOGY_DIR / "vec-alignment.ttl"
SHAPES_TTL = ONTOLOGY_DIR / "shapes.ttl"
VEC_TTL = REPO.parent / "shared" / "data" / "vec" / "vec-2.1.0-ontology.ttl"

# A plain Namespace: rdflib's closed XSD namespace warns when pytest inspects it.
XSD = Namespace("http://www.w3.org/2001/XMLSchema#")
CK = Namespace("https://w3id.org/cadkg#")
CKS = Namespace("https://w3id.org/cadkg/shapes#")
VEC = "http://www.prostep.org/ontologies/ecad/2024/03/vec#"
ONTOLOGY_IRI = URIRef("https://w3id.org/cadkg")

TERM_TYPES = (OWL.Class, OWL.ObjectProperty, OWL.DatatypeProperty)

REQUIRED_CLASSES = [
    "Cell",
    "Platform",
    "Element",
    "Guide",
    "AtcSlot",
    "Rail",
    "Surface",
    "Duct",
    "Keypoint",
    "Component",
    "CadItem",
    "CommercialModel",
    "Label",
    "TerminalBlock",
    "TerminalItem",
    "Pin",
    "Screw",
    "Hole",
    "Connector",
    "Cavity",
    "Wire",
    "Cable",
    "Harness",
    "Branch",
    "Segment",
    "HarnessNode",
    "Fixing",
    "Protection",
    "Operation",
    "InsertOperation",
    "RouteOperation",
    "TapeOperation",
    "ScrewOperation",
    "ConnectOperation",
    "ActionPlan",
    "Assignment",
    "Performer",
    "Spot",
    "Tool",
    "ToolChangerSlot",
    "Frame",
    "Pose",
    "Mesh",
    "Hose",
    "SourceFile",
    "BenchPin",
    "RoutePath",
]

REQUIRED_SUBCLASSES = {
    "Guide": "Element",
    "AtcSlot": "Element",
    "Rail": "Element",
    "Surface": "Element",
    "Duct": "Element",
    "TerminalBlock": "Component",
    "TerminalItem": "CadItem",
    "Connector": "Component",
    "InsertOperation": "Operation",
    "RouteOperation": "Operation",
    "TapeOperation": "Operation",
    "ScrewOperation": "Operation",
    "ConnectOperation": "Operation",
    "BenchPin": "Keypoint",
}

REQUIRED_OBJECT_PROPERTIES = [
    "hasPin",
    "pinOf",
    "fromPin",
    "toPin",
    "hasBranch",
    "containsCable",
    "hasConnector",
    "hasCavity",
    "atSpot",
    "usesTool",
    "involves",
    "instanceOf",
    "names",
    "hasLabel",
    "hasItem",
    "partOf",
    "onRail",
    "hasTerminalItem",
    "parentFrame",
    "hasFrame",
    "hasPose",
    "screwPose",
    "holePose",
    "hasMesh",
    "inPlan",
    "assignedTo",
    "assignmentOf",
    "passesThrough",
    "segmentFrom",
    "segmentTo",
    "routedThrough",
    "onPlatform",
    "hasKeypoint",
    "toolSlot",
    "definedIn",
]

# local name -> xsd range
REQUIRED_DATATYPE_PROPERTIES = {
    "label": XSD.string,
    "rawLabel": XSD.string,
    "cadId": XSD.string,
    "commercialCode": XSD.string,
    "pinName": XSD.string,
    "level": XSD.string,
    "wireNumber": XSD.string,
    "crossSectionMm2": XSD.decimal,
    "colour": XSD.string,
    "potentialType": XSD.string,
    "potentialName": XSD.string,
    "lengthM": XSD.decimal,
    "ductPath": XSD.string,
    "originTermination": XSD.string,
    "destinationTermination": XSD.string,
    "originPage": XSD.string,
    "originZone": XSD.string,
    "destinationPage": XSD.string,
    "destinationZone": XSD.string,
    "sequenceIndex": XSD.integer,
    "sourceLine": XSD.integer,
    "sourcePath": XSD.string,
    "sha256": XSD.string,
    "readerKind": XSD.string,
    "ingestedAt": XSD.dateTime,
    "tx": XSD.double,
    "ty": XSD.double,
    "tz": XSD.double,
    "qx": XSD.double,
    "qy": XSD.double,
    "qz": XSD.double,
    "qw": XSD.double,
    "xDim": XSD.double,
    "yDim": XSD.double,
    "zDim": XSD.double,
    "description": XSD.string,
    "quantity": XSD.integer,
    "profile": XSD.string,
    "meshUri": XSD.anyURI,
    "diameterM": XSD.double,
    "colourRgb": XSD.string,
    "keyLength": XSD.double,
    "keyGap": XSD.double,
    "keyHeight": XSD.double,
    "pinIndex": XSD.integer,
    "isDoublePin": XSD.boolean,
    "doublePinDistanceM": XSD.double,
    "role": XSD.string,
    "benchX": XSD.double,
    "benchY": XSD.double,
    "bendRadiusM": XSD.double,
    "direction": XSD.string,
    "jobKey": XSD.string,
}


# ---------------------------------------------------------------------------
# fixtures
# ---------------------------------------------------------------------------


def _parse(path: Path) -> Graph:
    graph = Graph()
    graph.parse(path, format="turtle")
    return graph


@pytest.fixture(scope="module")
def ontology() -> Graph:
    return _parse(CADKG_TTL)


@pytest.fixture(scope="module")
def alignment() -> Graph:
    return _parse(ALIGNMENT_TTL)


@pytest.fixture(scope="module")
def shapes() -> Graph:
    return _parse(SHAPES_TTL)


def _ck_terms(graph: Graph) -> set[URIRef]:
    return {
        s
        for t in TERM_TYPES
        for s in graph.subjects(RDF.type, t)
        if isinstance(s, URIRef) and str(s).startswith(str(CK))
    }


# ---------------------------------------------------------------------------
# ontology
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("path", [CADKG_TTL, ALIGNMENT_TTL, SHAPES_TTL], ids=lambda p: p.name)
def test_file_parses(path: Path) -> None:
    assert len(_parse(path)) > 0


def test_ontology_header(ontology: Graph) -> None:
    assert (ONTOLOGY_IRI, RDF.type, OWL.Ontology) in ontology
    assert ontology.value(ONTOLOGY_IRI, OWL.versionInfo) == Literal("0.1.0")
    assert ontology.value(ONTOLOGY_IRI, URIRef("http://purl.org/dc/terms/title")) is not None
    assert ontology.value(ONTOLOGY_IRI, RDFS.comment) is not None


def test_every_term_has_english_label_and_comment(ontology: Graph) -> None:
    terms = _ck_terms(ontology)
    assert len(terms) > 100
    missing = []
    for term in sorted(terms):
        for prop in (RDFS.label, RDFS.comment):
            values = [
                o for o in ontology.objects(term, prop) if isinstance(o, Literal) and o.language == "en"
            ]
            if not values or not all(str(v).strip() for v in values):
                missing.append(f"{term} {prop}")
    assert not missing, missing


@pytest.mark.parametrize("name", REQUIRED_CLASSES)
def test_required_class(ontology: Graph, name: str) -> None:
    assert (CK[name], RDF.type, OWL.Class) in ontology


@pytest.mark.parametrize("name,parent", sorted(REQUIRED_SUBCLASSES.items()))
def test_required_subclass(ontology: Graph, name: str, parent: str) -> None:
    assert (CK[name], RDFS.subClassOf, CK[parent]) in ontology


def test_tool_changer_slot_is_atc_slot(ontology: Graph) -> None:
    assert (CK.ToolChangerSlot, OWL.equivalentClass, CK.AtcSlot) in ontology
    assert (CK.AtcSlot, RDFS.subClassOf, CK.Element) in ontology
    # AtcSlot is declared once; ToolChangerSlot only through the equivalence.
    assert (CK.ToolChangerSlot, RDFS.subClassOf, None) not in ontology


@pytest.mark.parametrize("name", REQUIRED_OBJECT_PROPERTIES)
def test_required_object_property(ontology: Graph, name: str) -> None:
    assert (CK[name], RDF.type, OWL.ObjectProperty) in ontology


@pytest.mark.parametrize("name,xsd_range", sorted(REQUIRED_DATATYPE_PROPERTIES.items()))
def test_required_datatype_property(ontology: Graph, name: str, xsd_range: URIRef) -> None:
    assert (CK[name], RDF.type, OWL.DatatypeProperty) in ontology
    assert (CK[name], RDFS.range, xsd_range) in ontology


def test_every_datatype_property_has_xsd_range(ontology: Graph) -> None:
    for prop in ontology.subjects(RDF.type, OWL.DatatypeProperty):
        ranges = list(ontology.objects(prop, RDFS.range))
        assert len(ranges) == 1 and str(ranges[0]).startswith(str(XSD)), prop


def test_named_individuals(ontology: Graph) -> None:
    for name in ("robot", "human"):
        assert (CK[name], RDF.type, CK.Performer) in ontology
        assert (CK[name], RDF.type, OWL.NamedIndividual) in ontology


def test_property_axioms(ontology: Graph) -> None:
    assert (CK.pinOf, OWL.inverseOf, CK.hasPin) in ontology
    assert (CK.hasLabel, OWL.inverseOf, CK.names) in ontology
    assert (CK.partOf, RDF.type, OWL.TransitiveProperty) in ontology
    assert (CK.fromPin, RDFS.domain, CK.Wire) in ontology
    assert (CK.toPin, RDFS.range, CK.Pin) in ontology
    assert (CK.hasCavity, RDFS.domain, CK.Connector) in ontology
    assert (CK.segmentFrom, RDFS.range, CK.HarnessNode) in ontology


def test_referenced_ck_terms_are_declared(ontology: Graph, alignment: Graph, shapes: Graph) -> None:
    """Every ck: IRI used anywhere in the three files is declared in cadkg.ttl."""
    declared = {s for s in ontology.subjects() if isinstance(s, URIRef)}
    for graph in (ontology, alignment, shapes):
        for triple in graph:
            for node in triple:
                if isinstance(node, URIRef) and str(node).startswith(str(CK)):
                    assert node in declared, node


# ---------------------------------------------------------------------------
# VEC alignment
# ---------------------------------------------------------------------------


def test_alignment_has_enough_mappings(alignment: Graph) -> None:
    vec_objects = {o for o in alignment.objects() if isinstance(o, URIRef) and str(o).startswith(VEC)}
    assert 15 <= len(vec_objects) <= 80


def test_alignment_vec_terms_exist() -> None:
    if not VEC_TTL.is_file():
        pytest.skip(f"VEC ontology not found at {VEC_TTL}")
    vec = _parse(VEC_TTL)
    alignment = _parse(ALIGNMENT_TTL)
    used = {o for o in alignment.objects() if isinstance(o, URIRef) and str(o).startswith(VEC)}
    assert used
    missing = [str(term) for term in sorted(used) if not any((term, RDF.type, t) in vec for t in TERM_TYPES)]
    assert not missing, missing


def test_alignment_does_not_redefine_vec_terms(alignment: Graph) -> None:
    vec_subjects = {s for s in alignment.subjects() if str(s).startswith(VEC)}
    assert not vec_subjects


# ---------------------------------------------------------------------------
# SHACL shapes
# ---------------------------------------------------------------------------

PREFIXES = """
@prefix ck:  <https://w3id.org/cadkg#> .
@prefix ex:  <https://example.org/cell#> .
@prefix xsd: <http://www.w3.org/2001/XMLSchema#> .
"""

COMPONENTS = """
ex:F1500_1 a ck:Component ; ck:label "F1500.1" .
ex:Q1500_1 a ck:Component ; ck:label "Q1500.1" .
ex:F1500_1_14 a ck:Pin ; ck:pinOf ex:F1500_1 ; ck:pinName "14" .
ex:F1500_1_13 a ck:Pin ; ck:pinOf ex:F1500_1 ; ck:pinName "13" .
ex:Q1500_1_A1 a ck:Pin ; ck:pinOf ex:Q1500_1 ; ck:pinName "A1" .
"""

WORLD = """
ex:world a ck:Frame ; ck:label "world" .
"""


def _validate(data_ttl: str, ontology: Graph, shapes: Graph) -> tuple[bool, Graph]:
    data = Graph()
    data.parse(data=PREFIXES + data_ttl, format="turtle")
    conforms, results, _text = pyshacl.validate(
        data,
        shacl_graph=shapes,
        ont_graph=ontology,
        inference="none",
        advanced=True,  # as cadkg validate runs them: one shape targets by a SPARQL query
        abort_on_first=False,
        allow_warnings=False,
        meta_shacl=False,
    )
    return bool(conforms), results


def _results(report: Graph) -> list[dict]:
    out = []
    for result in report.subjects(RDF.type, SH.ValidationResult):
        out.append(
            {
                "focus": report.value(result, SH.focusNode),
                "path": report.value(result, SH.resultPath),
                "shape": report.value(result, SH.sourceShape),
                "constraint": report.value(result, SH.sourceConstraint),
                "component": report.value(result, SH.sourceConstraintComponent),
            }
        )
    return out


def test_conforming_wire_passes(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(
        COMPONENTS
        + """
        ex:w1 a ck:Wire ;
            ck:fromPin ex:F1500_1_14 ;
            ck:toPin ex:Q1500_1_A1 ;
            ck:wireNumber "1500.51" ;
            ck:crossSectionMm2 0.75 ;
            ck:lengthM 0.746 ;
            ck:colour "BU" .
        """,
        ontology,
        shapes,
    )
    assert conforms, _results(report)


def test_wire_with_two_from_pins_fails(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(
        COMPONENTS
        + """
        ex:w1 a ck:Wire ;
            ck:fromPin ex:F1500_1_14 , ex:F1500_1_13 ;
            ck:toPin ex:Q1500_1_A1 .
        """,
        ontology,
        shapes,
    )
    assert not conforms
    results = _results(report)
    assert len(results) == 1, results
    (result,) = results
    assert result["focus"] == URIRef("https://example.org/cell#w1")
    assert result["path"] == CK.fromPin
    assert result["shape"] == CKS.WireFromPinShape
    assert result["component"] == SH.MaxCountConstraintComponent


def test_wire_with_non_positive_cross_section_fails(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(
        COMPONENTS
        + """
        ex:w1 a ck:Wire ;
            ck:fromPin ex:F1500_1_14 ;
            ck:toPin ex:Q1500_1_A1 ;
            ck:crossSectionMm2 0.0 .
        """,
        ontology,
        shapes,
    )
    assert not conforms
    paths = {(r["path"], r["component"]) for r in _results(report)}
    assert paths == {(CK.crossSectionMm2, SH.MinExclusiveConstraintComponent)}


def test_wire_without_to_pin_fails(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(
        COMPONENTS + "ex:w1 a ck:Wire ; ck:fromPin ex:F1500_1_14 .",
        ontology,
        shapes,
    )
    assert not conforms
    assert {(r["shape"], r["component"]) for r in _results(report)} == {
        (CKS.WireToPinShape, SH.MinCountConstraintComponent)
    }


def test_wire_from_a_pin_to_itself_fails(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(
        COMPONENTS + "ex:w1 a ck:Wire ; ck:fromPin ex:F1500_1_14 ; ck:toPin ex:F1500_1_14 .",
        ontology,
        shapes,
    )
    assert not conforms
    assert [(r["focus"], r["shape"], r["component"]) for r in _results(report)] == [
        (URIRef("https://example.org/cell#w1"), CKS.WireEndsShape, SH.DisjointConstraintComponent)
    ]


def _pose(qx: str, qy: str, qz: str, qw: str) -> str:
    return (
        WORLD
        + f"""
        ex:p1 a ck:Pose ;
            ck:parentFrame ex:world ;
            ck:tx "0.0085"^^xsd:double ; ck:ty "0.009"^^xsd:double ; ck:tz "0.04496"^^xsd:double ;
            ck:qx "{qx}"^^xsd:double ; ck:qy "{qy}"^^xsd:double ;
            ck:qz "{qz}"^^xsd:double ; ck:qw "{qw}"^^xsd:double .
        """
    )


def test_unit_quaternion_pose_passes(ontology: Graph, shapes: Graph) -> None:
    # 90 degrees about z
    half_sqrt2 = "0.7071067811865476"
    conforms, report = _validate(_pose("0.0", "0.0", half_sqrt2, half_sqrt2), ontology, shapes)
    assert conforms, _results(report)


def test_non_unit_quaternion_pose_fails(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(_pose("0.0", "0.0", "0.5", "0.5"), ontology, shapes)
    assert not conforms
    results = _results(report)
    assert len(results) == 1, results
    (result,) = results
    assert result["focus"] == URIRef("https://example.org/cell#p1")
    assert result["shape"] == CKS.PoseUnitQuaternionShape
    assert result["constraint"] == CKS.UnitQuaternionConstraint
    assert result["component"] == SH.SPARQLConstraintComponent


def test_pose_without_parent_frame_fails(ontology: Graph, shapes: Graph) -> None:
    data = _pose("0.0", "0.0", "0.0", "1.0").replace("ck:parentFrame ex:world ;", "")
    conforms, report = _validate(data, ontology, shapes)
    assert not conforms
    assert {(r["path"], r["component"]) for r in _results(report)} == {
        (CK.parentFrame, SH.MinCountConstraintComponent)
    }


PLAN_ITEMS = """
ex:planA a ck:ActionPlan .
ex:planB a ck:ActionPlan .
ex:op1 a ck:RouteOperation ; ck:inPlan ex:planA ; ck:sequenceIndex 1 .
ex:op2 a ck:TapeOperation ; ck:inPlan {plan2} ; ck:sequenceIndex {index2} .
"""


def test_same_index_in_one_plan_fails(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(PLAN_ITEMS.format(plan2="ex:planA", index2="1"), ontology, shapes)
    assert not conforms
    results = _results(report)
    assert {r["focus"] for r in results} == {
        URIRef("https://example.org/cell#op1"),
        URIRef("https://example.org/cell#op2"),
    }
    for result in results:
        assert result["shape"] == CKS.UniqueSequenceIndexInPlanShape
        assert result["constraint"] == CKS.UniqueSequenceIndexInPlanConstraint
        assert result["path"] == CK.sequenceIndex


def test_same_index_in_different_plans_passes(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(PLAN_ITEMS.format(plan2="ex:planB", index2="1"), ontology, shapes)
    assert conforms, _results(report)


def test_different_indices_in_one_plan_pass(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(PLAN_ITEMS.format(plan2="ex:planA", index2="2"), ontology, shapes)
    assert conforms, _results(report)


def test_zero_sequence_index_fails(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(PLAN_ITEMS.format(plan2="ex:planB", index2="0"), ontology, shapes)
    assert not conforms
    assert {(r["path"], r["component"]) for r in _results(report)} == {
        (CK.sequenceIndex, SH.MinInclusiveConstraintComponent)
    }


def test_duplicate_waypoint_index_fails(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(
        """
        ex:route a ck:RoutePath ; ck:hasWaypoint ex:wp1 , ex:wp2 .
        ex:wp1 a ck:Waypoint ; ck:sequenceIndex 1 .
        ex:wp2 a ck:Waypoint ; ck:sequenceIndex 1 .
        """,
        ontology,
        shapes,
    )
    assert not conforms
    results = _results(report)
    assert len(results) == 1, results
    assert results[0]["shape"] == CKS.UniqueWaypointIndexShape
    assert results[0]["path"] == CK.hasWaypoint


def test_only_the_route_with_a_shared_waypoint_index_is_reported(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(
        """
        ex:good a ck:RoutePath ; ck:hasWaypoint ex:g1 , ex:g2 , ex:g3 .
        ex:g1 a ck:Waypoint ; ck:sequenceIndex 1 .
        ex:g2 a ck:Waypoint ; ck:sequenceIndex 2 .
        ex:g3 a ck:Waypoint ; ck:sequenceIndex 3 .
        ex:bad a ck:RoutePath ; ck:hasWaypoint ex:b1 , ex:b2 , ex:b3 .
        ex:b1 a ck:Waypoint ; ck:sequenceIndex 1 .
        ex:b2 a ck:Waypoint ; ck:sequenceIndex 2 .
        ex:b3 a ck:Waypoint ; ck:sequenceIndex 2 .
        """,
        ontology,
        shapes,
    )
    assert not conforms
    assert [(r["focus"], r["shape"]) for r in _results(report)] == [
        (URIRef("https://example.org/cell#bad"), CKS.UniqueWaypointIndexShape)
    ]


def test_only_the_pose_off_the_unit_quaternion_is_reported(ontology: Graph, shapes: Graph) -> None:
    good = _pose("0.0", "0.0", "0.0", "1.0")
    bad = _pose("0.0", "0.0", "0.0", "0.999").replace("ex:p1 ", "ex:p2 ").replace(WORLD, "")
    conforms, report = _validate(good + bad, ontology, shapes)
    assert not conforms
    assert [(r["focus"], r["constraint"]) for r in _results(report)] == [
        (URIRef("https://example.org/cell#p2"), CKS.UnitQuaternionConstraint)
    ]


def test_component_needs_exactly_one_label(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(
        """
        ex:X1600 a ck:TerminalBlock .
        ex:F1 a ck:Component ; ck:label "F1" , "F2" .
        """,
        ontology,
        shapes,
    )
    assert not conforms
    found = {(r["focus"], r["path"], r["component"]) for r in _results(report)}
    assert found == {
        (URIRef("https://example.org/cell#X1600"), CK.label, SH.MinCountConstraintComponent),
        (URIRef("https://example.org/cell#F1"), CK.label, SH.MaxCountConstraintComponent),
    }


def test_pin_needs_component_and_name(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(
        """
        ex:frame a ck:Frame .
        ex:pin a ck:Pin ; ck:pinOf ex:frame .
        """,
        ontology,
        shapes,
    )
    assert not conforms
    found = {(r["path"], r["component"]) for r in _results(report)}
    assert found == {
        (CK.pinOf, SH.ClassConstraintComponent),
        (CK.pinName, SH.MinCountConstraintComponent),
    }


SOURCE_FILE = """
ex:src a ck:SourceFile ;
    ck:sourcePath "iema/connections.csv" ;
    ck:sha256 "{sha}" ;
    ck:readerKind "eplan-connection-list" ;
    ck:ingestedAt "2024-05-01T12:00:00Z"^^xsd:dateTime .
"""


def test_good_source_file_passes(ontology: Graph, shapes: Graph) -> None:
    conforms, report = _validate(SOURCE_FILE.format(sha="0123456789abcdef" * 4), ontology, shapes)
    assert conforms, _results(report)


@pytest.mark.parametrize("sha", ["0123456789ABCDEF" * 4, "abc", "0123456789abcdef" * 4 + "0"])
def test_source_file_with_bad_sha256_fails(ontology: Graph, shapes: Graph, sha: str) -> None:
    conforms, report = _validate(SOURCE_FILE.format(sha=sha), ontology, shapes)
    assert not conforms
    results = _results(report)
    assert len(results) == 1, results
    assert results[0]["path"] == CK.sha256
    assert results[0]["component"] == SH.PatternConstraintComponent
