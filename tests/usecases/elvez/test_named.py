"""The ELVEZ named queries on the example: the graph answers the process and harness questions."""

from __future__ import annotations

from collections.abc import Iterator
from decimal import Decimal

import pyoxigraph as ox
import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.query.named import named_queries
from tests.conftest import ROOT

CK = "https://w3id.org/cadkg#"
ELVEZ = ROOT / "examples" / "elvez-cell" / "manifest.toml"


@pytest.fixture(scope="module")
def kg() -> Iterator[KnowledgeGraph]:
    graph = KnowledgeGraph.build(ELVEZ)
    yield graph
    graph.close()


def test_the_queries_are_declared() -> None:
    queries = named_queries()
    for name in (
        "elvez-operations-at-spot",
        "elvez-tool-of-operation",
        "elvez-cable-length-per-harness",
        "elvez-harness-cables",
        "elvez-plan",
    ):
        assert queries[name].description
    assert [p.name for p in queries["elvez-operations-at-spot"].params] == ["label"]
    assert [(p.name, p.type) for p in queries["elvez-tool-of-operation"].params] == [("index", "integer")]


def test_operations_that_touch_guide_g4(kg: KnowledgeGraph) -> None:
    rows = kg.named_query("elvez-operations-at-spot", label="G4").rows
    assert [(r["index"], r["type"]) for r in rows] == [
        (3, "route"),
        (7, "route"),
        (8, "route"),
        (9, "tape"),
        (12, "route"),
        (13, "route"),
        (14, "tape"),
    ]
    assert rows[0]["components"] == "W104;W105;W106" and rows[0]["tool"] == "gripper_right"
    assert [r["index"] for r in kg.named_query("elvez-operations-at-spot", label="H1").rows] == [1]


def test_tool_of_operation_7(kg: KnowledgeGraph) -> None:
    (row,) = kg.named_query("elvez-tool-of-operation", index=7).rows
    assert (row["type"], row["tool"], row["toolType"], row["slot"]) == (
        "route",
        "gripper_right",
        "gripper",
        "ATC2",
    )
    (tape,) = kg.named_query("elvez-tool-of-operation", index="4").rows
    assert (tape["tool"], tape["slot"]) == ("taping_gun", "ATC3")


def test_total_cable_length_per_harness(kg: KnowledgeGraph) -> None:
    rows = kg.named_query("elvez-cable-length-per-harness").rows
    # Sums of the length_mm column of harness-components.csv, per harness (README).
    assert [(r["harness"], r["label"], r["cables"], r["totalLengthM"]) for r in rows] == [
        (1, "WH1", 6, Decimal("2.45")),
        (2, "WH2", 10, Decimal("5.43")),
        (3, "WH3", 11, Decimal("4.18")),
    ]


def test_a_length_stated_by_two_files_counts_once() -> None:
    graph = KnowledgeGraph.build(ELVEZ)
    try:
        # Another file stating the same harness label and the same cable lengths again.
        another = ox.NamedNode("urn:another-file")
        rows = graph.raw_query(
            "SELECT ?h ?label ?cable ?length WHERE { ?h a ck:Harness ; ck:label ?label ;"
            " ck:hasBranch/ck:containsCable ?cable . ?cable ck:lengthM ?length }"
        )
        for row in rows:
            graph._store.add(ox.Quad(row["h"], ox.NamedNode(CK + "label"), row["label"], another))
            graph._store.add(ox.Quad(row["cable"], ox.NamedNode(CK + "lengthM"), row["length"], another))
        assert "urn:another-file" in graph.named_graphs()
        rows = graph.named_query("elvez-cable-length-per-harness").rows
        assert [(r["cables"], r["totalLengthM"]) for r in rows] == [
            (6, Decimal("2.45")),
            (10, Decimal("5.43")),
            (11, Decimal("4.18")),
        ]
    finally:
        graph.close()


def test_harness_cables_end_to_end(kg: KnowledgeGraph) -> None:
    rows = kg.named_query("elvez-harness-cables", harness=3).rows
    assert len(rows) == 11
    assert [(r["cable"], r["fromConnector"], r["fromCavity"], r["toConnector"], r["toCavity"]) for r in rows][
        -2:
    ] == [
        ("W310", "C30", 10, "C33", 2),
        ("W311", "C30", 12, "C33", 3),
    ]


def test_plan_query_is_the_plan(kg: KnowledgeGraph) -> None:
    rows = kg.named_query("elvez-plan").rows
    assert [r["index"] for r in rows] == list(range(1, 15))
    assert rows[9]["spots"] == "H3;CH3" and rows[9]["components"] == "C30"
