"""The cadkg ↔ VEC alignment holds for the data read: where vec-alignment.ttl says a cadkg term
closely matches a VEC term, a graph built from VEC files holds one cadkg thing per VEC element of
that class, and the related things correspond (a segment's start node, a routing's wire)."""

from __future__ import annotations

from pathlib import Path

import pytest
import rdflib
from lxml import etree
from rdflib.namespace import SKOS

import cadkg
from cadkg.graph import KnowledgeGraph
from cadkg.ontology.terms import CK_NS, ontology_path

DATA = Path(__file__).resolve().parents[1] / "data" / "vec"
FILES = [DATA / "routing-examples.vec", DATA / "harness-1.1.vec", DATA / "modules-2.0.vec"]
VEC = "http://www.prostep.org/ontologies/ecad/2024/03/vec#"
NS = {"vec": "http://www.prostep.org/ecad-if/2011/vec", "xsi": "http://www.w3.org/2001/XMLSchema-instance"}


def typed(kind: str) -> str:
    return f"//*[@xsi:type='vec:{kind}']"


# closeMatch class pairs checked on the data: the VEC elements (XPath) of the class that a
# harness reader turns into one cadkg thing each. A role is its part occurrence's only one of
# the kind: the occurrence's id names the thing.
def occurrence_of(role: str) -> str:
    return f"//Component[Role/@xsi:type='vec:{role}']"


CLASSES = {
    ("Connector", "ConnectorHousingRole"): occurrence_of("ConnectorHousingRole"),
    ("Cavity", "CavityReference"): f"{typed('ConnectorHousingRole')}/SlotReference/CavityReference",
    # Wire element references with ends: the routable conductors; one without ends is the
    # outer element of a multi-core cable (a ck:Cable).
    ("Wire", "WireElementReference"): f"{typed('WireRole')}/WireElementReference[WireEnd]",
    ("Segment", "TopologySegment"): "//TopologySegment",
    ("HarnessNode", "TopologyNode"): "//TopologyNode",
    ("Fixing", "FixingRole"): occurrence_of("FixingRole"),
    ("Protection", "WireProtectionRole"): occurrence_of("WireProtectionRole"),
    ("Routing", "Routing"): "//Routing",
    ("ModuleFamily", "ModuleFamily"): "//ModuleFamily",
}
PROPERTIES = {("segmentFrom", "topologySegmentStartNode"), ("segmentTo", "topologySegmentEndNode")}
PROPERTIES |= {("routingOf", "routingRoutedElement")}
# closeMatch pairs of things a harness file does not bring (part masters are not read from it).
NOT_READ = {("CommercialModel", "PartVersion"), ("commercialCode", "partVersionPartNumber")}


def close_matches() -> set[tuple[str, str]]:
    alignment = rdflib.Graph().parse(ontology_path("vec-alignment.ttl"), format="turtle")
    return {
        (str(s).removeprefix(CK_NS), str(o).removeprefix(VEC))
        for s, o in alignment.subject_objects(SKOS.closeMatch)
        if str(o).startswith(VEC)
    }


def test_every_close_match_is_checked_here() -> None:
    assert close_matches() == set(CLASSES) | PROPERTIES | NOT_READ


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> dict[Path, KnowledgeGraph]:
    graphs = {}
    for path in FILES:
        directory = tmp_path_factory.mktemp(path.stem)
        (directory / path.name).write_bytes(path.read_bytes())
        manifest = directory / "manifest.toml"
        manifest.write_text(
            f'[cell]\nname = "{path.stem}"\nprofile = "vw"\nbase_iri = "https://example.org/cell/v/"\n'
            f'[[source]]\npath = "{path.name}"\n',
            encoding="utf-8",
        )
        graphs[path] = cadkg.build(manifest)
    return graphs


def last_part(iri: str) -> str:
    return iri.rpartition("/")[2]


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_classes_hold_one_to_one(built: dict[Path, KnowledgeGraph], path: Path) -> None:
    kg = built[path]
    tree = etree.parse(str(path))
    for (ck, vec), xpath in CLASSES.items():
        things = {r["x"] for r in kg.query(f"SELECT ?x WHERE {{ ?x a ck:{ck} }}").rows}
        elements = {e.get("id") for e in tree.xpath(xpath, namespaces=NS)}
        assert len(things) == len(elements), (ck, vec)
        if ck != "Cavity":  # a cavity is named by its connector and number
            # The things are the elements themselves: their IRIs end in the XML ids.
            assert {last_part(t) for t in things} == elements, (ck, vec)
    assert not kg.query(
        "SELECT ?x WHERE { { ?x a ck:CommercialModel } UNION { ?x ck:commercialCode ?c } }"
    ).rows


@pytest.mark.parametrize("path", FILES, ids=lambda p: p.stem)
def test_segment_ends_and_routed_wires_correspond(built: dict[Path, KnowledgeGraph], path: Path) -> None:
    kg = built[path]
    tree = etree.parse(str(path))
    ids = {e.get("id"): e for e in tree.iter() if isinstance(e.tag, str) and e.get("id")}
    expected = {
        s.get("id"): (s.findtext("StartNode"), s.findtext("EndNode"))
        for s in tree.iterfind(".//TopologySegment")
    }
    rows = kg.query(
        "SELECT ?s ?from ?to WHERE { ?s a ck:Segment ; ck:segmentFrom ?from ; ck:segmentTo ?to }"
    ).rows
    assert {last_part(r["s"]): (last_part(r["from"]), last_part(r["to"])) for r in rows} == expected
    # A routing is of the wire its RoutedElement names; a cable's outer element's routing is of
    # those of its cores that have none of their own.
    own = {r.findtext("RoutedElement") for r in tree.iterfind(".//Routing")}
    found: dict[str, set[str]] = {}
    for row in kg.query("SELECT ?r ?w WHERE { ?r a ck:Routing ; ck:routingOf ?w }").rows:
        found.setdefault(last_part(row["r"]), set()).add(last_part(row["w"]))
    assert set(found) == set(ids[r].get("id") for r in (e.get("id") for e in tree.iterfind(".//Routing")))
    for routing, wires in found.items():
        target = ids[ids[routing].findtext("RoutedElement")]
        if target.find("WireEnd") is not None:
            assert wires == {target.get("id")}
        else:
            cores = {
                c.get("id")
                for c in target.getparent().iterfind("WireElementReference")
                if c.find("WireEnd") is not None
            }
            assert wires == cores - own
