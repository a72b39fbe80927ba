from __future__ import annotations

from decimal import Decimal

import pytest

import cadkg
from cadkg.errors import QueryError
from cadkg.query.named import named_queries

REQUIRED = {
    "components",
    "pins-of-component",
    "wires-of-component",
    "wire-endpoints",
    "connections-in-order",
    "wires-by-colour-section",
}


def test_the_named_queries_are_there_with_headers() -> None:
    queries = named_queries()
    assert set(queries) >= REQUIRED
    for query in queries.values():
        assert query.description
    assert [p.name for p in queries["wires-of-component"].params] == ["label"]


@pytest.mark.parametrize("name", sorted(REQUIRED | {"sources"}))
def test_every_named_query_runs_on_the_example(iema: cadkg.KnowledgeGraph, name: str) -> None:
    query = named_queries()[name]
    params = {p.name: {"label": "Q1500.1", "wireNumber": "1500.51"}[p.name] for p in query.params}
    assert len(iema.named_query(name, **params)) > 0


def test_connections_in_order_follow_figure_3(fig3: cadkg.KnowledgeGraph) -> None:
    rows = fig3.named_query("connections-in-order").rows
    assert len(rows) == 19
    assert [r["sequence"] for r in rows] == list(range(1, 20))
    first, seventh, last = rows[0], rows[6], rows[18]
    assert (first["wireNumber"], first["origin"], first["destination"]) == (
        "1500.51",
        "F1500.1:14",
        "Q1500.1:A1",
    )
    assert (first["section"], first["colour"], first["lengthM"]) == (Decimal("0.75"), "BU", Decimal("0.746"))
    assert (seventh["origin"], seventh["destination"], seventh["lengthM"]) == (
        "X0030.1:1L+.2:a2",
        "X1600:1:a",
        None,
    )
    assert (last["wireNumber"], last["origin"], last["destination"]) == ("1500.01", "F1500.1:2", "Q1500.1:1")


def test_pins_of_a_terminal_block(fig3: cadkg.KnowledgeGraph) -> None:
    rows = fig3.named_query("pins-of-component", label="X1600").rows
    assert [(r["pinName"], r["level"], r["wires"]) for r in rows] == [
        ("1", "a", 1),
        ("2", "a", 1),
        ("3", "a", 1),
        ("4", "a", 1),
    ]


def test_wires_of_component(fig3: cadkg.KnowledgeGraph) -> None:
    rows = fig3.named_query("wires-of-component", label="Q1500.2").rows
    assert [(r["wireNumber"], r["pin"], r["otherEnd"]) for r in rows] == [
        ("1500.53", "A1", "F1500.2:14"),
        ("0V", "A2", "Q1500.1:A2"),
        ("0V", "A2", "Q1500.3:A2"),
        ("1500.10", "2", "X1500:5:a"),
        ("1500.11", "4", "X1500:6:a"),
        ("1500.12", "6", "X1500:7:a"),
    ]


def test_wire_endpoints(fig3: cadkg.KnowledgeGraph) -> None:
    rows = fig3.named_query("wire-endpoints", wireNumber="1500.50").rows
    assert [(r["end"], r["component"], r["pinName"], r["level"]) for r in rows] == [
        ("origin", "F1500.1", "13", None),
        ("destination", "X1600", "2", "a"),
    ]


def test_wires_by_colour_and_section(fig3: cadkg.KnowledgeGraph) -> None:
    rows = {(r["colour"], r["section"]): r for r in fig3.named_query("wires-by-colour-section")}
    assert rows[("BK", Decimal("1.5"))]["wires"] == 10
    assert rows[("BU", Decimal("0.75"))]["wires"] == 6
    assert rows[("BU", Decimal("1"))]["wires"] == 3
    assert rows[("BU", Decimal("0.75"))]["totalLengthM"] == Decimal("5.523")


def test_components_count_items_from_the_wri(fig3: cadkg.KnowledgeGraph) -> None:
    rows = {r["label"]: r for r in fig3.named_query("components")}
    assert rows["F1500.1"]["items"] == 2
    assert rows["X00005.2"]["items"] == 1


@pytest.mark.parametrize(
    ("name", "params", "message"),
    [
        ("no-such-query", {}, "no named query"),
        ("wires-of-component", {}, "needs label"),
        ("wires-of-component", {"label": "F1", "colour": "BU"}, "no parameter 'colour'"),
    ],
)
def test_named_query_errors(
    iema: cadkg.KnowledgeGraph, name: str, params: dict[str, str], message: str
) -> None:
    with pytest.raises(QueryError, match=message):
        iema.named_query(name, **params)
