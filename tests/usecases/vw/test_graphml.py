"""GraphML export of harnesses: golden files, typed scalar keys, networkx round trip, the CLI.

Set ``CADKG_REGENERATE_GOLDEN=1`` to rewrite the golden files (see tests/data/README.md).
"""

from __future__ import annotations

import io
import os
from pathlib import Path

import networkx as nx
import pytest
from lxml import etree

import cadkg
from cadkg.errors import QueryError
from cadkg.graph import KnowledgeGraph
from cadkg.usecases.vw.graphml import graphml_text, harness_graph, harness_graphml, write_harness_graphml
from cadkg.usecases.vw.views import View
from tests.cli import run
from tests.conftest import ROOT
from tests.usecases.vw.test_views import VW, one_harness_cell, vw  # noqa: F401 - the fixture

GOLDEN = ROOT / "tests" / "data" / "golden"
GRAPHML = "{http://graphml.graphdrawing.org/xmlns}"
CASES = [(h, v) for h in ("DOOR-L", "000971619") for v in ("topology", "wires")]


def golden(harness: str, view: str) -> Path:
    return GOLDEN / f"vw-harness-{harness}-{view}.graphml"


def canonical(text: str) -> str:
    return etree.canonicalize(text, strip_text=True)


@pytest.mark.parametrize(("harness", "view"), CASES)
def test_export_matches_golden(vw: KnowledgeGraph, harness: str, view: str) -> None:  # noqa: F811
    text = harness_graphml(vw, view, harness)
    path = golden(harness, view)
    if os.environ.get("CADKG_REGENERATE_GOLDEN"):
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text, encoding="utf-8")
    assert canonical(text) == canonical(path.read_text(encoding="utf-8"))


@pytest.mark.parametrize(("harness", "view"), CASES)
def test_golden_reads_back_into_networkx(vw: KnowledgeGraph, harness: str, view: str) -> None:  # noqa: F811
    """networkx reads the file to the graph it was written from: ids, keys, types and values."""
    original = harness_graph(vw, view, harness)
    read = nx.read_graphml(golden(harness, view), force_multigraph=True)
    assert {k: v for k, v in read.graph.items() if not k.endswith("_default")} == original.graph
    assert dict(read.nodes(data=True)) == dict(original.nodes(data=True))
    assert sorted(read.edges(keys=True, data=True)) == sorted(
        (min(u, v), max(u, v), k, d) for u, v, k, d in original.edges(keys=True, data=True)
    )


@pytest.mark.parametrize(("harness", "view"), CASES)
def test_keys_are_typed_scalars_and_plain_graphml(harness: str, view: str) -> None:
    root = etree.parse(str(golden(harness, view))).getroot()
    keys = {k.get("id"): k for k in root.iter(f"{GRAPHML}key")}
    assert {k.get("attr.type") for k in keys.values()} <= {"string", "long", "double"}
    # One key per name and scope, every value a scalar (lists are ;-joined, never a Python repr).
    assert len({(k.get("attr.name"), k.get("for")) for k in keys.values()}) == len(keys)
    for data in root.iter(f"{GRAPHML}data"):
        assert data.get("key") in keys
        assert not (data.text or "").startswith(("[", "(", "{"))
    # Plain GraphML: no yEd (y:) or other extension elements.
    assert {etree.QName(e).namespace for e in root.iter() if isinstance(e.tag, str)} == {GRAPHML[1:-1]}
    element_ids = [e.get("id") for e in root.iter(f"{GRAPHML}node")] + [
        e.get("id") for e in root.iter(f"{GRAPHML}edge")
    ]
    assert len(element_ids) == len(set(element_ids)) and all(element_ids)


def test_topology_golden_by_hand() -> None:
    read = nx.read_graphml(golden("DOOR-L", "topology"), force_multigraph=True)
    assert read.nodes["node/DOOR-L/B2"] == {
        "label": "B2",
        "node_name": "B2",
        "kind": "fixing",
        "degree": 3,
        "connectors": "",
        "fixings": "F2",
    }
    s2 = read.edges["node/DOOR-L/B1", "node/DOOR-L/X2", "segment/DOOR-L/S2"]
    assert (s2["length_m"], s2["diameter_m"], s2["wires"], s2["wire_count"]) == (
        0.12,
        0.006,
        "W1;W2;W5;W6",
        4,
    )


def test_output_is_stable() -> None:
    """Two builds give the same bytes; nodes and edges are in id order."""
    first = harness_graphml(cadkg.build(VW), "wires", "000971619")
    assert first == harness_graphml(cadkg.build(VW), "wires", "000971619")
    root = etree.fromstring(first.encode())
    node_ids = [e.get("id") for e in root.iter(f"{GRAPHML}node")]
    assert node_ids == sorted(node_ids)


def test_lists_are_refused() -> None:
    view = View(
        {"harness": "H", "harness_id": "harness/H", "view": "topology"}, [("a", {"fixings": ["F1"]})], []
    )
    with pytest.raises(TypeError, match="node a: attribute 'fixings' is not a text"):
        graphml_text(view)
    view.nodes = [("a", {"colour": "red"})]
    with pytest.raises(TypeError, match="a node attribute GraphML does not declare: 'colour'"):
        graphml_text(view)


def test_markup_and_forbidden_characters() -> None:
    """Markup characters are escaped; tab, newline and carriage return come back as they were;
    what XML 1.0 forbids (other control characters, U+FFFE) is written as U+FFFD."""
    label = "a<b & \"c\" 'd'>\te\nf\rg\x01h\x1fi\ufffej"
    view = View(
        {"harness": "H<&>", "harness_id": "harness/H", "view": "wires"},
        [("n&1", {"label": label, "connector": "X&1"}), ("n2", {"label": "plain"})],
        [("n2", "n&1", "w<1>", {"label": label, "colour": "RD\x00"})],
    )
    text = graphml_text(view)
    root = etree.fromstring(text.encode())  # well-formed, read by a validating parser
    assert root.tag == f"{GRAPHML}graphml"
    read = nx.read_graphml(io.StringIO(text), force_multigraph=True)
    written = "a<b & \"c\" 'd'>\te\nf\rg\ufffdh\ufffdi\ufffdj"
    assert read.graph["harness"] == "H<&>"
    assert read.nodes["n&1"] == {"label": written, "connector": "X&1"}
    assert read.nodes["n2"] == {"label": "plain"}
    [(u, v, key, data)] = read.edges(keys=True, data=True)
    assert {u, v} == {"n&1", "n2"} and key == "w<1>"
    assert data == {"label": written, "colour": "RD\ufffd"}


def test_unknown_view(vw: KnowledgeGraph) -> None:  # noqa: F811
    with pytest.raises(QueryError, match="unknown harness view '3d'; one of topology, wires"):
        harness_graphml(vw, "3d", "DOOR-L")


def test_write_to_a_file(vw: KnowledgeGraph, tmp_path: Path) -> None:  # noqa: F811
    path = tmp_path / "door.graphml"
    view = write_harness_graphml(vw, path, "topology", "DOOR-L")
    assert path.read_text(encoding="utf-8") == golden("DOOR-L", "topology").read_text(encoding="utf-8")
    assert (len(view.nodes), len(view.edges), view.warnings) == (6, 5, [])
    assert [p.name for p in tmp_path.iterdir()] == ["door.graphml"]  # no partial file left beside


# -- the command line ---------------------------------------------------------------------------------


def test_cli_export_views(tmp_path: Path) -> None:
    out = tmp_path / "movo.graphml"
    result = run("export", VW, "--format", "graphml", "--view", "wires", "--harness", "000971619", "-o", out)
    assert result.returncode == 0, result.stderr
    assert canonical(out.read_text(encoding="utf-8")) == canonical(
        golden("000971619", "wires").read_text(encoding="utf-8")
    )


def test_cli_harness_may_be_left_out_with_one_harness(tmp_path: Path) -> None:
    out = tmp_path / "gearbox.graphml"
    result = run("export", one_harness_cell(tmp_path), "--view", "topology", "-o", out)
    assert result.returncode == 0, result.stderr
    graph = nx.read_graphml(out, force_multigraph=True)
    assert graph.graph["harness"] == "000971250"
    assert sorted(d["kind"] for _, d in graph.nodes(data=True)) == ["connector", "connector"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("--view", "topology"), "the graph holds 2 harnesses; name one: 000971619, DOOR-L"),
        (("--view", "wires", "--harness", "DOOR-R"), "no harness 'DOOR-R'"),
    ],
)
def test_cli_export_errors(tmp_path: Path, args: tuple[str, ...], message: str) -> None:
    result = run("export", VW, "--format", "graphml", *args, "-o", tmp_path / "x.graphml")
    assert result.returncode == 2
    assert message in result.stderr
    assert not (tmp_path / "x.graphml").exists()


def test_cli_view_needs_graphml(tmp_path: Path) -> None:
    result = run("export", VW, "--view", "wires", "-o", tmp_path / "x.ttl")
    assert result.returncode == 2
    assert "--view wires writes GraphML, not ttl" in result.stderr


def test_cli_structure_export_is_unchanged(tmp_path: Path) -> None:
    """Without --view the GraphML export is the structural view of the whole graph, as before."""
    out = tmp_path / "all.graphml"
    result = run("export", VW, "-o", out)
    assert result.returncode == 0, result.stderr
    graph = nx.read_graphml(io.BytesIO(out.read_bytes()))
    relations = {d["relation"] for _, _, d in graph.edges(data=True)}
    assert {"segmentFrom", "segmentTo", "routedThrough", "hasCavity", "fromPin"} <= relations
