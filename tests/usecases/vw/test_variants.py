"""Views of one variant of a modular harness, positions and yEd graphics in the GraphML, VEC
harnesses in the views, by the Python API, ``cadkg export --modules`` and ``harness_topology``."""

from __future__ import annotations

import shutil
from pathlib import Path

import networkx as nx
import pytest
from lxml import etree

import cadkg
from cadkg.errors import QueryError
from cadkg.graph import KnowledgeGraph
from cadkg.services.session import Session
from cadkg.services.table import call
from cadkg.usecases.vw.graphml import harness_graph, harness_graphml, harness_view
from tests.cli import run
from tests.conftest import ROOT

DATA = ROOT / "tests" / "data"
OWN = DATA / "kbl" / "modular-three-modules.kbl"
MODULAR = DATA / "kbl" / "kblxml_2.4sr-1_tab016120_modulare_ltgs._160718.kbl"
ROUTING = DATA / "vec" / "routing-examples.vec"
GRAPHML = "{http://graphml.graphdrawing.org/xmlns}"
YED = "{http://www.yworks.com/xml/graphml}"


def cell(directory: Path, *files: Path) -> Path:
    for path in files:
        shutil.copy(path, directory / path.name)
    manifest = directory / "manifest.toml"
    sources = "".join(f'[[source]]\npath = "{p.name}"\n' for p in files)
    manifest.write_text(
        '[cell]\nname = "variants"\nprofile = "vw"\nbase_iri = "https://example.org/cell/v/"\n' + sources,
        encoding="utf-8",
    )
    return manifest


@pytest.fixture(scope="module")
def own(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return cell(tmp_path_factory.mktemp("own"), OWN)


@pytest.fixture(scope="module")
def own_kg(own: Path) -> KnowledgeGraph:
    return cadkg.build(own)


def ids(graph: nx.MultiGraph, kind: str = "") -> set[str]:
    return {n.rpartition("/")[2] for n, d in graph.nodes(data=True) if not kind or d.get("kind") == kind}


@pytest.mark.parametrize(
    ("modules", "nodes", "segments", "wires"),
    [
        ((), {"n1", "n2", "n3", "n4"}, {"s1", "s2", "s3"}, {"o1", "o2", "o3"}),
        (("M-BASE",), {"n1", "n2", "n3"}, {"s1", "s2"}, {"o3"}),
        (("M-BASE", "M-OPT2"), {"n1", "n2", "n3", "n4"}, {"s1", "s2", "s3"}, {"o2", "o3"}),
        (("SMALL",), {"n1", "n2", "n3"}, {"s1", "s2"}, {"o3"}),
        (("m1", "m2"), {"n1", "n2", "n3"}, {"s1", "s2"}, {"o1", "o3"}),
    ],
    ids=["whole", "base", "base+opt2", "configuration", "by-id"],
)
def test_own_file_views_of_a_variant(
    own_kg: KnowledgeGraph, modules: tuple[str, ...], nodes: set[str], segments: set[str], wires: set[str]
) -> None:
    topology = harness_graph(own_kg, "topology", "MOD-3", modules)
    assert ids(topology) == nodes
    assert {k.rpartition("/")[2] for _, _, k in topology.edges(keys=True)} == segments
    wire_view = harness_graph(own_kg, "wires", "MOD-3", modules)
    assert {k.rpartition("/")[2] for _, _, k in wire_view.edges(keys=True)} == wires
    if modules:
        assert topology.graph["modules"]


def test_positions_labels_and_lengths_in_the_topology(own_kg: KnowledgeGraph) -> None:
    graph = harness_graph(own_kg, "topology", "MOD-3")
    n1 = graph.nodes["node/MOD-3/n1"]
    # (1000, -200, 500) mm in the vehicle frame: x forward, y left in REP 103.
    assert (n1["x"], n1["y"], n1["z"]) == (-1.0, 0.2, 0.5)
    assert (n1["label"], n1["node_name"], n1["kind"]) == ("X1", "N1", "connector")
    # Both X2 connectors sit alone; in the whole harness n3 and n4 are both "X2".
    assert {graph.nodes[f"node/MOD-3/{n}"]["label"] for n in ("n3", "n4")} == {"X2"}
    edges = {k: d for _, _, k, d in graph.edges(keys=True, data=True)}
    assert (edges["segment/MOD-3/s1"]["length_source"], edges["segment/MOD-3/s2"]["length_source"]) == (
        "curve",
        "chord",
    )
    assert graph.graph["frame"] == "REP 103: x forward, y left, z up; metres"


def test_a_designation_twice_in_a_view_is_a_warning(own_kg: KnowledgeGraph) -> None:
    view = harness_view(own_kg, "topology", "MOD-3", ("M-BASE", "M-OPT2"))
    assert view.warnings == ["connector designation X2 names several connectors"]
    assert harness_view(own_kg, "topology", "MOD-3", ("M-BASE",)).warnings == []
    both = harness_view(own_kg, "wires", "MOD-3", ("M-OPT1", "M-OPT2"))
    assert both.warnings == [
        "modules M-OPT1, M-OPT2 are of one family (010) and exclude each other",
        "connector designation X2 names several connectors",
    ]


def test_unknown_module_and_a_harness_without_modules(own_kg: KnowledgeGraph) -> None:
    with pytest.raises(
        QueryError, match="harness MOD-3 has no module or configuration 'M-X'; modules: M-BASE,"
    ):
        harness_view(own_kg, "topology", "MOD-3", ("M-X",))
    kg = cadkg.build(ROOT / "examples" / "vw-harness" / "manifest.toml")
    with pytest.raises(QueryError, match="harness DOOR-L has no modules to choose from"):
        harness_view(kg, "topology", "DOOR-L", ("M-BASE",))


def test_the_modular_sample_exports_a_variant_with_coordinates(tmp_path: Path) -> None:
    """The Old Beetle's kit: the base harness with the heating module, from the command line."""
    manifest = cell(tmp_path, MODULAR)
    out = tmp_path / "variant.graphml"
    result = run("export", manifest, "--modules", "aaa108a1aaa,aaa108a1a4a", "-o", out)
    assert result.returncode == 0, result.stderr
    graph = nx.read_graphml(out, force_multigraph=True)
    assert graph.graph["modules"] == "aaa108a1a4a;aaa108a1aaa"
    assert (graph.number_of_nodes(), graph.number_of_edges()) == (116, 115)
    assert nx.is_tree(nx.Graph(graph))
    assert all({"x", "y", "z"} <= set(d) for _, d in graph.nodes(data=True))
    connectors = {c for _, d in graph.nodes(data=True) for c in d["connectors"].split(";") if c}
    # Every connector (78) and component box (3) of the variant sits at a node, 13 connectors
    # through the ring terminal they carry; their designations are all different.
    assert len(connectors) == 78 + 3
    wires = tmp_path / "wires.graphml"
    result = run("export", manifest, "--view", "wires", "--modules", "aaa108a1aaa,aaa108a1a4a", "-o", wires)
    assert result.returncode == 0, result.stderr
    assert nx.read_graphml(wires, force_multigraph=True).number_of_edges() == 131
    whole = run("export", manifest, "--view", "topology", "-o", tmp_path / "whole.graphml")
    assert whole.returncode == 0
    assert nx.read_graphml(tmp_path / "whole.graphml").number_of_nodes() == 184


def test_cli_module_errors_and_warnings(own: Path, tmp_path: Path) -> None:
    out = tmp_path / "x.graphml"
    result = run("export", own, "--modules", "M-X", "-o", out)
    assert result.returncode == 2
    assert "has no module or configuration 'M-X'" in result.stderr and not out.exists()
    result = run("export", own, "--modules", "M-BASE,M-OPT2", "-o", out)
    assert result.returncode == 0
    assert "cadkg: warning: connector designation X2 names several connectors" in result.stderr


def test_yed_graphics(own: Path, tmp_path: Path) -> None:
    out = tmp_path / "yed.graphml"
    result = run("export", own, "--yed", "-o", out)
    assert result.returncode == 0, result.stderr
    root = etree.parse(str(out)).getroot()
    (key,) = [k for k in root.iter(f"{GRAPHML}key") if k.get("yfiles.type") == "nodegraphics"]
    shapes = {
        n.get("id"): n.find(f"{GRAPHML}data[@key='{key.get('id')}']/{YED}ShapeNode")
        for n in root.iter(f"{GRAPHML}node")
    }
    assert len(shapes) == 4 and all(s is not None for s in shapes.values())
    n1 = shapes["node/MOD-3/n1"]
    # Seen from above, front to the left, 1 unit per mm: x = -x, y = y (REP 103) times 1000, centred.
    geometry = n1.find(f"{YED}Geometry")
    assert (float(geometry.get("x")), float(geometry.get("y"))) == (1000.0 - 10, 200.0 - 10)
    assert n1.findtext(f"{YED}NodeLabel") == "X1"
    # networkx still reads the plain keys.
    assert nx.read_graphml(out).nodes["node/MOD-3/n1"]["label"] == "X1"


def test_yed_without_positions_lays_the_graph_out() -> None:
    kg = cadkg.build(ROOT / "examples" / "vw-harness" / "manifest.toml")
    root = etree.fromstring(harness_graphml(kg, "topology", "DOOR-L", yed=True).encode())
    places = {(g.get("x"), g.get("y")) for g in root.iter(f"{YED}Geometry")}
    assert len(places) == 6  # no two nodes drawn on one place
    wires = etree.fromstring(harness_graphml(kg, "wires", "DOOR-L", yed=True).encode())
    assert len({(g.get("x"), g.get("y")) for g in wires.iter(f"{YED}Geometry")}) == 15


def test_a_vec_harness_in_the_views(tmp_path: Path) -> None:
    kg = cadkg.build(cell(tmp_path, ROUTING))
    whole = harness_graph(kg, "topology")
    assert (whole.number_of_nodes(), whole.number_of_edges()) == (8, 8)
    assert len(nx.cycle_basis(nx.Graph(whole))) == 1  # the RL / LL loop
    assert "frame" not in whole.graph  # no geometry in the example
    wires = {d["label"]: d["segments"] for _, _, d in harness_graph(kg, "wires").edges(data=True)}
    segment = {k: d["label"] for _, _, k, d in whole.edges(keys=True, data=True)}
    named = {
        w: "|".join(";".join(segment[s] for s in p.split(";")) for p in path.split("|"))
        for w, path in wires.items()
    }
    assert named == {
        "W1": "SEG-2;SEG-1",
        "W2": "SEG-2;SEG-3;SEG-4;SEG-5;SEG-6|SEG-2;SEG-3;SEG-7;SEG-8;SEG-6",
        "W3": "SEG-2;SEG-3;SEG-3;SEG-1",
    }
    rl = harness_graph(kg, "topology", None, ("RL",))
    assert nx.is_tree(nx.Graph(rl)) and rl.number_of_edges() == 6
    rl_wires = {
        d["label"]: d["segments"] for _, _, d in harness_graph(kg, "wires", None, ("RL",)).edges(data=True)
    }
    assert "|" not in rl_wires["W2"]


def test_harness_topology_service_with_modules(own_kg: KnowledgeGraph) -> None:
    session = Session(own_kg.cell_model(), kg=own_kg)
    result = call(session, "harness_topology", {"modules": "M-BASE"})
    assert (result.success, result.message) == (True, "MOD-3 (M-BASE): 3 nodes, 2 segments, 1 wires")
    n1 = next(n for n in result.nodes if n.id == "node/MOD-3/n1")
    assert (n1.label, n1.x, n1.y, n1.z) == ("X1", -1.0, 0.2, 0.5)
    result = call(session, "harness_topology", {"modules": "M-BASE,M-OPT2", "view": "wires"})
    assert result.success and result.message.endswith(
        "; warning: connector designation X2 names several connectors"
    )
    assert nx.parse_graphml(result.graphml, force_multigraph=True).number_of_edges() == 2
    failed = call(session, "harness_topology", {"modules": "nothing"})
    assert not failed.success and "has no module or configuration 'nothing'" in failed.message
