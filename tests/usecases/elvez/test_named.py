"""The ELVEZ named queries on the example: the graph answers the sequence and harness questions."""

from __future__ import annotations

import pyoxigraph as ox
import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.query.named import named_queries
from tests.conftest import ROOT

CK = "https://w3id.org/cadkg#"
ELVEZ = ROOT / "examples" / "elvez-cell" / "manifest.toml"


@pytest.fixture(scope="module")
def kg(elvez: KnowledgeGraph) -> KnowledgeGraph:
    return elvez  # built once per session (tests/conftest.py)


def test_the_queries_are_declared() -> None:
    queries = named_queries()
    for name in (
        "elvez-operations-at-spot",
        "elvez-cable-length-per-harness",
        "elvez-harness-cables",
        "elvez-plan",
    ):
        assert queries[name].description
    assert "elvez-tool-of-operation" not in queries  # the sequence names no tools
    assert [p.name for p in queries["elvez-operations-at-spot"].params] == ["label"]
    assert [(p.name, p.type) for p in queries["elvez-harness-cables"].params] == [("harness", "string")]


def test_operations_at_jig_j1(kg: KnowledgeGraph) -> None:
    rows = kg.named_query("elvez-operations-at-spot", label="J1").rows
    assert [(r["order"], r["code"], r["labels"]) for r in rows] == [
        (3, "RC", "GR11"),
        (4, "RC", "GR12"),
        (5, "T", "WH1"),
    ]
    assert rows[0]["spots"] == "J1.1;J2.1;J3.1"
    assert [r["order"] for r in kg.named_query("elvez-operations-at-spot", label="C2").rows] == [6]


def test_total_cable_length_per_harness(kg: KnowledgeGraph) -> None:
    rows = kg.named_query("elvez-cable-length-per-harness").rows
    # Sums of the length column of Components_definition.csv, per harness (README).
    assert [(r["harness"], r["firstConnector"], r["cables"], float(r["totalLengthM"])) for r in rows] == [
        ("1", "WH1", 5, pytest.approx(2.69)),
        ("2", "WH2", 2, pytest.approx(0.76)),
    ]


def test_a_length_stated_by_two_files_counts_once() -> None:
    graph = KnowledgeGraph.build(ELVEZ)
    try:
        # Another file stating the same cable lengths again.
        another = ox.NamedNode("urn:another-file")
        for row in graph.raw_query("SELECT ?cable ?length WHERE { ?cable a ck:Cable ; ck:lengthM ?length }"):
            graph._store.add(ox.Quad(row["cable"], ox.NamedNode(CK + "lengthM"), row["length"], another))
        assert "urn:another-file" in graph.named_graphs()
        rows = graph.named_query("elvez-cable-length-per-harness").rows
        assert [(r["cables"], float(r["totalLengthM"])) for r in rows] == [
            (5, pytest.approx(2.69)),
            (2, pytest.approx(0.76)),
        ]
    finally:
        graph.close()


def test_harness_cables_with_their_cavities(kg: KnowledgeGraph) -> None:
    rows = kg.named_query("elvez-harness-cables", harness="1").rows
    assert [(r["cable"], r["row"], r["endConnector"], r["colour"]) for r in rows] == [
        ("CA1", 0, "GR11", "Yellow"),
        ("CA3", 1, "GR11", "Blue"),
        ("CA2", 2, "GR11", "Green"),
        ("CA4", 3, "GR12", "Red"),
        ("CA5", 4, "GR12", "Brown"),
    ]


def test_plan_query_is_the_sequence(kg: KnowledgeGraph) -> None:
    rows = kg.named_query("elvez-plan").rows
    assert [(r["order"], r["code"]) for r in rows] == list(
        enumerate(["EC", "PC", "RC", "RC", "T", "EC", "PC", "RC", "TJ"], start=1)
    )
    assert rows[3]["spots"] == "J1.1;J3.2" and rows[3]["labels"] == "GR12"
