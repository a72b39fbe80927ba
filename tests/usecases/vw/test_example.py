"""The Volkswagen example cell: it builds, holds what its README says, validates, serves
``harness_topology`` from the command line, and a broken harness file leaves the store as it was."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.graph import KnowledgeGraph
from tests.cli import run
from tests.conftest import EXAMPLES

CELL = EXAMPLES / "vw-harness"
KBL = "kblxml_2.3sr-1_000971619_ltgs_movo_170718.kbl"

COUNTS = """
SELECT ?harness
  (COUNT(DISTINCT ?connector) AS ?connectors) (COUNT(DISTINCT ?cavity) AS ?cavities)
  (COUNT(DISTINCT ?node) AS ?nodes) (COUNT(DISTINCT ?segment) AS ?segments)
  (COUNT(DISTINCT ?wire) AS ?wires) (COUNT(DISTINCT ?routed) AS ?routedWires)
  (COUNT(DISTINCT ?fixing) AS ?fixings) (COUNT(DISTINCT ?protection) AS ?protections)
WHERE {
  ?h a ck:Harness ; ck:label ?harness .
  { ?h ck:hasConnector ?connector . OPTIONAL { ?connector ck:hasCavity ?cavity } }
  UNION { ?node a ck:HarnessNode ; ck:partOf ?h }
  UNION { ?segment a ck:Segment ; ck:partOf ?h }
  UNION { ?wire a ck:Wire ; ck:partOf ?h . OPTIONAL { ?wire ck:routedThrough ?s . BIND(?wire AS ?routed) } }
  UNION { ?fixing a ck:Fixing ; ck:partOf ?h }
  UNION { ?protection a ck:Protection ; ck:partOf ?h }
}
GROUP BY ?harness ORDER BY ?harness
"""


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    target = tmp_path_factory.mktemp("vw") / "store"
    result = run("build", CELL / "manifest.toml", "--store", target)
    assert result.returncode == 0, result.stderr
    assert "harness-text" in result.stdout and "kbl" in result.stdout
    return target


def test_the_counts_of_the_readme(store: Path) -> None:
    with KnowledgeGraph.open(store) as kg:
        rows = kg.query(COUNTS).rows
        assert [tuple(r.values()) for r in rows] == [
            # harness, connectors, cavities, nodes, segments, wires, routed, fixings, protections
            ("000971619", 20, 31, 31, 30, 18, 18, 0, 0),
            ("DOOR-L", 4, 15, 6, 5, 7, 7, 2, 2),
        ]
        profile = kg.query("SELECT ?p WHERE { ?c a ck:Cell ; ck:profile ?p }").rows
        assert profile == ({"p": "vw"},)


def test_the_example_validates(store: Path) -> None:
    result = run("validate", store)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "0 error(s)" in result.stderr


def test_call_harness_topology(store: Path) -> None:
    result = run("call", store, "harness_topology", "harness=DOOR-L", "view=wires")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert (data["success"], data["harness"], len(data["nodes"]), len(data["segments"])) == (
        True,
        "DOOR-L",
        6,
        5,
    )
    assert data["wires"][0] == {
        "id": "wire/DOOR-L/W1",
        "label": "W1",
        "from_connector": "X1",
        "from_cavity": "1",
        "to_connector": "X2",
        "to_cavity": "1",
        "section_mm2": 0.35,
        "colour": "RD",
        "length_m": 0.5,
        "segments": ["segment/DOOR-L/S1", "segment/DOOR-L/S2"],
    }
    assert data["graphml"].startswith("<?xml version='1.0' encoding='utf-8'?>\n<graphml ")
    services = run("services")
    assert "harness_topology" in services.stdout and "vw" in services.stdout


def broken_copy(tmp_path: Path, name: str, old: str, new: str) -> Path:
    cell = tmp_path / "cell"
    shutil.copytree(CELL, cell)
    text = (cell / name).read_text(encoding="utf-8")
    assert text.count(old) == 1
    (cell / name).write_text(text.replace(old, new), encoding="utf-8")
    return cell / "manifest.toml"


@pytest.mark.parametrize(
    ("name", "old", "new", "where", "reason"),
    [
        (
            KBL,
            "<Contacted_cavity>id_370_50</Contacted_cavity>",
            "<Contacted_cavity>id_370_500</Contacted_cavity>",
            f"{KBL}:2819:",
            "<Contacted_cavity> of <Contact_points> names nothing in the file (found 'id_370_500'",
        ),
        (
            KBL,
            'version_id="2.3 SR-1"',
            'version_id="3.0"',
            f"{KBL}:6:",
            "unknown KBL version (found '3.0', expected version_id 2.3 SR-1 or 2.4 or 2.4 SR-1)",
        ),
        (
            "door-l.harness",
            "segment S5 B2 X4",
            "segment S5 B3 X4",
            "door-l.harness:18:",
            "segment S5 leads to an unknown node (found 'B3', expected one of: B1, B2, X1, X2, X3, X4)",
        ),
    ],
    ids=["kbl-missing-cavity", "kbl-version", "text-unknown-node"],
)
def test_a_bad_file_leaves_the_store_as_it_was(
    store: Path, tmp_path: Path, name: str, old: str, new: str, where: str, reason: str
) -> None:
    live = (store / "CURRENT").read_text(encoding="utf-8")
    with pytest.raises(IngestError) as caught:
        KnowledgeGraph.build(broken_copy(tmp_path, name, old, new), store)
    assert where in str(caught.value) and reason in str(caught.value)
    assert (store / "CURRENT").read_text(encoding="utf-8") == live
    with KnowledgeGraph.open(store) as kg:
        assert len(kg.query("SELECT ?w WHERE { ?w a ck:Wire }")) == 25
        assert len(kg.query("SELECT ?h WHERE { ?h a ck:Harness }")) == 2


def test_the_command_line_reports_a_bad_file_in_one_line(store: Path, tmp_path: Path) -> None:
    manifest = broken_copy(tmp_path, "door-l.harness", "X2:3 X4:1", "X2:3 X4:7")
    result = run("build", manifest, "--store", store)
    assert result.returncode == 2
    assert result.stderr.strip().endswith(
        "door-l.harness:25: wire W5 ends in a cavity connector X4 does not have (found 'X4:7', "
        "expected a cavity of X4: 1, 2, 3)"
    )


def test_the_kbl_harness_of_the_readme_in_its_topology_view(store: Path) -> None:
    from cadkg.usecases.vw.views import topology_graph

    with KnowledgeGraph.open(store) as kg:
        graph = topology_graph(kg, "000971619")
    node = graph.nodes["node/000971619/Node_21"]
    assert (node["label"], node["node_name"], node["connectors"]) == ("D25", "PNID21", "D25")
    assert all({"x", "y", "z"} <= set(d) for _, d in graph.nodes(data=True))
    assert graph.graph["frame"] == "REP 103: x forward, y left, z up; metres"
