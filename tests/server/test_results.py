"""The result writers against pyoxigraph's own, and content negotiation."""

from __future__ import annotations

import pyoxigraph as ox
import pytest

from cadkg.server.context import syntax_message
from cadkg.server.limits import Deadline, TimeLimitError
from cadkg.server.results import (
    GRAPH_FORMATS,
    RESULT_FORMATS,
    NotAcceptableError,
    negotiate,
    read_solutions,
    write_table,
)

XSD = "http://www.w3.org/2001/XMLSchema#"
# Every kind of term a SELECT can bind, with the characters each format must escape.
DATA = f"""
<urn:a> <urn:p> "plain, with \\"quotes\\"\\nand a line\\tand a tab" .
<urn:a> <urn:p> "ciao"@it .
<urn:a> <urn:p> "0.746"^^<{XSD}decimal> .
<urn:a> <urn:p> "<b>&amp;</b>" .
<urn:a> <urn:p> _:blank .
<urn:a> <urn:p> <urn:x?a=1&b=2> .
"""
QUERY = "SELECT ?s ?o ?missing WHERE { ?s <urn:p> ?o } ORDER BY STR(?o)"


@pytest.fixture(scope="module")
def store() -> ox.Store:
    store = ox.Store()
    store.load(DATA, format=ox.RdfFormat.N_TRIPLES)
    return store


def solutions(parsed: ox.QuerySolutions) -> list[tuple[object, ...]]:
    # Blank node labels are the writer's choice: compare them as "a blank node".
    return [
        tuple("_:" if isinstance(term, ox.BlankNode) else term for term in solution) for solution in parsed
    ]


@pytest.mark.parametrize("name", ["json", "xml", "tsv"])
def test_writers_agree_with_pyoxigraph(store: ox.Store, name: str) -> None:
    fmt = RESULT_FORMATS[name]
    ours = write_table(read_solutions(store.query(QUERY), 100), fmt)
    theirs = store.query(QUERY).serialize(format=getattr(ox.QueryResultsFormat, name.upper()))
    results_format = getattr(ox.QueryResultsFormat, name.upper())
    mine = ox.parse_query_results(ours, format=results_format)
    reference = ox.parse_query_results(theirs, format=results_format)
    assert isinstance(mine, ox.QuerySolutions) and isinstance(reference, ox.QuerySolutions)
    assert [v.value for v in mine.variables] == ["s", "o", "missing"]
    expected = solutions(reference)
    assert solutions(mine) == expected
    assert len(expected) == 6


def test_csv_writes_plain_values_quoted_where_needed(store: ox.Store) -> None:
    text = write_table(read_solutions(store.query(QUERY), 100), RESULT_FORMATS["csv"]).decode()
    assert text.startswith("s,o,missing\r\n")
    assert 'urn:a,"plain, with ""quotes""\nand a line\tand a tab",\r\n' in text
    assert "urn:a,ciao,\r\n" in text
    assert "urn:a,0.746,\r\n" in text
    assert "urn:a,urn:x?a=1&b=2,\r\n" in text


def test_row_cap_marks_the_table_truncated(store: ox.Store) -> None:
    table = read_solutions(store.query(QUERY), 4)
    assert len(table.rows) == 4 and table.truncated
    exact = read_solutions(store.query(QUERY), 6)
    assert len(exact.rows) == 6 and not exact.truncated


def test_reading_stops_at_the_deadline(store: ox.Store) -> None:
    many = ox.Store()
    many.extend(
        ox.Quad(ox.NamedNode(f"urn:n{i}"), ox.NamedNode("urn:p"), ox.Literal(str(i)), ox.DefaultGraph())
        for i in range(2000)
    )
    deadline = Deadline(0.001)
    deadline.abandon()
    with pytest.raises(TimeLimitError, match="time limit"):
        read_solutions(many.query("SELECT * WHERE { ?s ?p ?o }"), 10_000, deadline)


@pytest.mark.parametrize(
    ("accept", "expected"),
    [
        (None, "json"),
        ("*/*", "json"),
        ("application/sparql-results+xml", "xml"),
        ("text/csv;q=0.5, text/tab-separated-values", "tsv"),
        ("text/html, application/xhtml+xml, application/xml;q=0.9, */*;q=0.8", "xml"),
        ("application/json", "json"),
        ("text/*", "csv"),
    ],
)
def test_negotiate_results(accept: str | None, expected: str) -> None:
    assert negotiate(accept, None, RESULT_FORMATS).name == expected


def test_negotiate_graphs_and_format_parameter() -> None:
    assert negotiate("application/sparql-results+json, text/turtle;q=0.9", None, GRAPH_FORMATS).name == "ttl"
    assert negotiate("application/json", None, GRAPH_FORMATS).name == "jsonld"
    assert negotiate("text/csv", "turtle", GRAPH_FORMATS).name == "ttl"
    with pytest.raises(NotAcceptableError, match="text/turtle"):
        negotiate("text/csv", None, GRAPH_FORMATS)
    with pytest.raises(NotAcceptableError, match="format='yaml'"):
        negotiate(None, "yaml", RESULT_FORMATS)


def test_syntax_message_marks_the_position() -> None:
    text = "SELECT ?x\nWHERE { ?x ?p }"
    line = "SPARQL syntax error at line 2, column 15 (found '}', expected one of LATERAL, SERVICE)"
    message = syntax_message(line, text)
    assert message.splitlines() == [
        line,
        "WHERE { ?x ?p }",
        "              ^",
    ]
    assert syntax_message("some other error", text) == "some other error"
