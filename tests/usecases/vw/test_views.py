"""Harness views from the graph: topology and wires of the example harnesses, harnesses found by
the terms alone, the named harness queries and the ``harness_topology`` service."""

from __future__ import annotations

import shutil
import warnings
from collections import Counter
from decimal import Decimal
from pathlib import Path

import networkx as nx
import pyoxigraph as ox
import pytest

import cadkg
from cadkg.errors import NotFound, QueryError
from cadkg.graph import KnowledgeGraph
from cadkg.ingest.harness.kbl import read_kbl
from cadkg.ingest.harness.records import HarnessNode, HarnessSegment
from cadkg.services.session import Session
from cadkg.services.table import call
from cadkg.usecases.vw.harness_data import find_harness, harnesses
from cadkg.usecases.vw.services import HarnessTopologyResult, TopologySegment, TopologyWire
from cadkg.usecases.vw.views import topology_graph, wire_graph
from tests.conftest import EXAMPLES, ROOT

VW = EXAMPLES / "vw-harness" / "manifest.toml"
GETRIEBE = ROOT / "tests" / "data" / "kbl" / "kblxml_2.3sr-1_000971250_ltgs_getriebe_170718.kbl"
MOVO = EXAMPLES / "vw-harness" / "kblxml_2.3sr-1_000971619_ltgs_movo_170718.kbl"


def one_harness_cell(directory: Path) -> Path:
    """A cell of the gearbox harness alone, written into ``directory``."""
    shutil.copy(GETRIEBE, directory / GETRIEBE.name)
    manifest = directory / "manifest.toml"
    manifest.write_text(
        '[cell]\nname = "gearbox"\nprofile = "vw"\nbase_iri = "https://example.org/cell/gearbox/"\n'
        f'[[source]]\npath = "{GETRIEBE.name}"\n',
        encoding="utf-8",
    )
    return manifest


@pytest.fixture(scope="module")
def vw() -> KnowledgeGraph:
    """The Volkswagen example built in memory once; tests must not change it."""
    return cadkg.build(VW)


def test_harnesses_of_the_example(vw: KnowledgeGraph) -> None:
    assert [(h.label, h.id, h.description, h.file_format) for h in harnesses(vw)] == [
        ("000971619", "harness/000971619", "LTGS Movo", "KBL 2.3 SR-1"),
        ("DOOR-L", "harness/DOOR-L", "front door harness, left (demo)", "cadkg harness text 1"),
    ]


def test_find_harness(vw: KnowledgeGraph) -> None:
    door = find_harness(vw, "DOOR-L")
    assert find_harness(vw, "harness/DOOR-L") == door == find_harness(vw, door.iri)
    with pytest.raises(QueryError, match="holds 2 harnesses; name one: 000971619, DOOR-L"):
        find_harness(vw)
    with pytest.raises(NotFound, match="no harness 'DOOR-R'"):
        find_harness(vw, "DOOR-R")
    with pytest.raises(NotFound, match="no harness"):
        find_harness(cadkg.KnowledgeGraph.memory())


def test_door_topology(vw: KnowledgeGraph) -> None:
    graph = topology_graph(vw, "DOOR-L")
    assert graph.graph == {"harness": "DOOR-L", "harness_id": "harness/DOOR-L", "view": "topology"}
    assert {
        n: (d["kind"], d["degree"], d["connectors"], d["fixings"]) for n, d in graph.nodes(data=True)
    } == {
        "node/DOOR-L/X1": ("connector", 1, "X1", ""),
        "node/DOOR-L/X2": ("connector", 1, "X2", ""),
        "node/DOOR-L/X3": ("connector", 1, "X3", ""),
        "node/DOOR-L/X4": ("connector", 1, "X4", ""),
        "node/DOOR-L/B1": ("branch", 3, "", ""),
        "node/DOOR-L/B2": ("fixing", 3, "", "F2"),
    }
    edges = {key: data for _, _, key, data in graph.edges(keys=True, data=True)}
    assert edges["segment/DOOR-L/S1"] == {
        "label": "S1",
        "from_node": "node/DOOR-L/X1",
        "to_node": "node/DOOR-L/B1",
        "length_m": 0.35,
        "diameter_m": 0.009,
        "wires": "W1;W2;W3;W4;W7",
        "wire_ids": "wire/DOOR-L/W1;wire/DOOR-L/W2;wire/DOOR-L/W3;wire/DOOR-L/W4;wire/DOOR-L/W7",
        "wire_count": 5,
        "fixings": "F1",
        "protections": "P1",
    }
    assert {k: d["wire_count"] for k, d in edges.items()} == {
        "segment/DOOR-L/S1": 5,
        "segment/DOOR-L/S2": 4,
        "segment/DOOR-L/S3": 5,
        "segment/DOOR-L/S4": 2,
        "segment/DOOR-L/S5": 3,
    }
    assert edges["segment/DOOR-L/S4"]["protections"] == "P2"
    assert sum(d["length_m"] for d in edges.values()) == pytest.approx(1.0)
    assert nx.is_tree(nx.Graph(graph))


def test_door_wires(vw: KnowledgeGraph) -> None:
    graph = wire_graph(vw, "DOOR-L")
    assert graph.number_of_nodes() == 15  # every cavity, used or not: 6 + 4 + 2 + 3
    assert graph.nodes["cavity/DOOR-L/X1/6"] == {
        "label": "X1:6",
        "connector": "X1",
        "cavity": "6",
        "harness_node": "node/DOOR-L/X1",
    }
    assert graph.degree("cavity/DOOR-L/X1/6") == 0
    edges = {key: data for _, _, key, data in graph.edges(keys=True, data=True)}
    assert edges["wire/DOOR-L/W5"] == {
        "label": "W5",
        "wire_number": "W5",
        "from_cavity": "cavity/DOOR-L/X2/3",
        "to_cavity": "cavity/DOOR-L/X4/1",
        "section_mm2": 0.5,
        "length_m": 0.55,
        "colour": "GN",
        "segments": "segment/DOOR-L/S2;segment/DOOR-L/S3;segment/DOOR-L/S5",  # in route order
    }
    assert len(edges) == 7


def test_movo_views_agree_with_the_kbl(vw: KnowledgeGraph) -> None:
    """Node kinds follow from the file's segments and referenced components, counted here anew."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # its Segment_6's centre curve: tests/ingest/test_kbl_modules.py
        records = read_kbl(MOVO)
    degree: Counter[str] = Counter()
    for segment in (r for r in records if isinstance(r, HarnessSegment)):
        degree[segment.start] += 1
        degree[segment.end] += 1
    expected = Counter(
        "connector" if n.connectors else "branch" if degree[n.ident] >= 3 else "inline"
        for n in records
        if isinstance(n, HarnessNode)
    )
    graph = topology_graph(vw, "000971619")
    assert Counter(d["kind"] for _, d in graph.nodes(data=True)) == expected
    assert expected == Counter({"connector": 20, "branch": 10, "inline": 1})
    assert graph.number_of_edges() == 30
    assert sum(d["length_m"] for _, _, d in graph.edges(data=True)) == pytest.approx(4.057624198)
    wires = wire_graph(vw, "000971619")
    assert (wires.number_of_nodes(), wires.number_of_edges()) == (31, 18)
    # Every wire's route is a walk from the node of its first connector to that of its second.
    for _, _, key, data in wires.edges(keys=True, data=True):
        here = wires.nodes[data["from_cavity"]]["harness_node"]
        for segment in data["segments"].split(";"):
            attributes = next(d for _, _, k, d in graph.edges(keys=True, data=True) if k == segment)
            assert here in (attributes["from_node"], attributes["to_node"]), key
            here = attributes["to_node"] if here == attributes["from_node"] else attributes["from_node"]
        assert here == wires.nodes[data["to_cavity"]]["harness_node"], key


TERMS_ONLY = """
@prefix ck: <https://w3id.org/cadkg#> .
@prefix e: <https://example.org/other/> .
<https://example.org/other/cell/this> a ck:Cell .
e:h a ck:Harness ; ck:harnessNumber 7 ; ck:hasConnector e:main .
e:main a ck:Connector ; ck:label "J1" ; ck:hasCavity e:cav1 .
e:cav1 a ck:Cavity ; ck:pinIndex 1 .
e:branch ck:hasConnector e:j2 .
e:h ck:hasBranch e:branch .
e:j2 a ck:Connector ; ck:label "J2" .
e:c a ck:Cable ; ck:label "red" ; ck:partOf e:h ; ck:fromPin e:p1 ; ck:toPin e:p2 ; ck:diameterM 0.002 .
e:p1 a ck:Pin ; ck:pinOf e:main ; ck:inCavity e:cav1 .
e:p2 a ck:Pin ; ck:pinOf e:j2 ; ck:pinName "3" .
"""


def test_a_harness_described_by_the_terms_alone() -> None:
    """A harness of another source (cables between cavities, no topology) has a wire view."""
    store = ox.Store()
    store.load(TERMS_ONLY.encode(), ox.RdfFormat.TURTLE)
    kg = KnowledgeGraph(store)
    (ref,) = harnesses(kg)
    assert (ref.label, ref.id) == ("WH7", "h")
    assert topology_graph(kg).number_of_nodes() == 0
    graph = wire_graph(kg)
    assert sorted(d["label"] for _, d in graph.nodes(data=True)) == ["J1:1", "J2:3"]
    ((u, v, key, data),) = graph.edges(keys=True, data=True)
    assert (key, data["label"], data["diameter_m"], data["segments"]) == ("c", "red", 0.002, "")
    assert {u, v} == {"cav1", "p2"}


# -- named queries -------------------------------------------------------------------------------------


def test_named_wires_of_connector(vw: KnowledgeGraph) -> None:
    rows = vw.named_query("harness-wires-of-connector", connector="X2").rows
    assert [(r["cavity"], r["wire"], r["otherEnd"], r["colour"]) for r in rows] == [
        ("1", "W1", "X1:1", "RD"),
        ("2", "W2", "X1:2", "BK"),
        ("3", "W5", "X4:1", "GN"),
        ("4", "W6", "X4:2", "YE"),
    ]
    assert rows[0]["section"] == Decimal("0.35") and rows[0]["length"] == Decimal("0.5")
    splice = vw.named_query("harness-wires-of-connector", connector="D25").rows
    assert sorted(r["wire"] for r in splice) == ["1", "2", "3", "4"]


def test_named_segment_lengths(vw: KnowledgeGraph) -> None:
    rows = vw.named_query("harness-segment-lengths", harness="DOOR-L").rows
    assert [(r["segment"], r["from"], r["to"], r["length"], r["wires"]) for r in rows] == [
        ("S1", "X1", "B1", Decimal("0.35"), 5),
        ("S3", "B1", "B2", Decimal("0.2"), 5),
        ("S5", "B2", "X4", Decimal("0.18"), 3),
        ("S4", "B2", "X3", Decimal("0.15"), 2),
        ("S2", "B1", "X2", Decimal("0.12"), 4),
    ]
    movo = vw.named_query("harness-segment-lengths", harness="000971619").rows
    assert len(movo) == 30
    assert sum(r["length"] for r in movo) == Decimal("4.057624198")


def test_named_wires_through_segment(vw: KnowledgeGraph) -> None:
    rows = vw.named_query("harness-wires-through-segment", segment="S4").rows
    assert [(r["wire"], r["from"], r["to"], r["section"]) for r in rows] == [
        ("W3", "X1:3", "X3:1", Decimal("1.5")),
        ("W4", "X1:4", "X3:2", Decimal("1.5")),
    ]


# -- the harness_topology service ---------------------------------------------------------------------


@pytest.fixture(scope="module")
def session(vw: KnowledgeGraph) -> Session:
    return Session(vw.cell_model(), kg=vw)


def test_harness_topology_service(session: Session) -> None:
    result = call(session, "harness_topology", {"harness": "DOOR-L"})
    assert isinstance(result, HarnessTopologyResult)
    assert (result.success, result.message) == (True, "DOOR-L: 6 nodes, 5 segments, 7 wires")
    assert result.file_format == "cadkg harness text 1"
    assert [n.label for n in result.nodes] == ["B1", "B2", "X1", "X2", "X3", "X4"]
    assert result.nodes[1].fixings == ("F2",)
    assert result.segments[2] == TopologySegment(
        "segment/DOOR-L/S3",
        "S3",
        "node/DOOR-L/B1",
        "node/DOOR-L/B2",
        0.2,
        0.007,
        ("W3", "W4", "W5", "W6", "W7"),
        (),
        ("P2",),
    )
    assert result.wires[3] == TopologyWire(
        "wire/DOOR-L/W4",
        "W4",
        "X1",
        "4",
        "X3",
        "2",
        1.5,
        "BN",
        0.75,
        ("segment/DOOR-L/S1", "segment/DOOR-L/S3", "segment/DOOR-L/S4"),
    )
    topology = nx.parse_graphml(result.graphml, force_multigraph=True)
    assert (topology.number_of_nodes(), topology.number_of_edges()) == (6, 5)
    wires = call(session, "harness_topology", {"harness": "000971619", "view": "wires"})
    assert (wires.success, len(wires.nodes), len(wires.segments), len(wires.wires)) == (True, 31, 30, 18)
    assert nx.parse_graphml(wires.graphml, force_multigraph=True).number_of_edges() == 18


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({}, "the graph holds 2 harnesses; name one: 000971619, DOOR-L"),
        ({"harness": "DOOR-R"}, "no harness 'DOOR-R'; known: 000971619, DOOR-L"),
        ({"harness": "DOOR-L", "view": "3d"}, "unknown view '3d'; one of topology, wires"),
    ],
)
def test_harness_topology_failures(session: Session, params: dict[str, str], message: str) -> None:
    result = call(session, "harness_topology", params)
    assert (result.success, result.message, result.nodes, result.graphml) == (False, message, (), "")


def test_harness_may_be_left_out_with_one_harness(tmp_path: Path) -> None:
    kg = cadkg.build(one_harness_cell(tmp_path))
    result = call(Session(kg.cell_model(), kg=kg), "harness_topology", {})
    assert (result.success, result.harness, len(result.wires)) == (True, "000971250", 1)
    assert result.wires[0].length_m == pytest.approx(0.62508)
    assert result.segments[0].length_m == pytest.approx(0.625086846)
