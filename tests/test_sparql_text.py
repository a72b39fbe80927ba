"""SPARQL text: bound values, query forms and the WHERE group (no store but an embedded one).

A bound value goes into the query text as an escaped SPARQL term; these tests check that
no value can change the query, by running the written text on an embedded store.
"""

from __future__ import annotations

from decimal import Decimal

import pyoxigraph as ox
import pytest

from cadkg.errors import QueryError
from cadkg.sparql_text import bind_values, query_form, syntax_error_message, values_clause

EX = "http://example.org/"
HOSTILE = [
    'F1"} ; DROP ALL ; SELECT * WHERE { ?s ?p ?o',
    "line one\nline two } }",
    "back\\slash\\",
    'quote \' and """ triple',
    "# not a comment } VALUES",
    "<http://example.org/a>",
    "é ✓ \t tab",
]


@pytest.fixture
def store() -> ox.Store:
    """Each hostile value is the label of its own node, plus one plain node."""
    store = ox.Store()
    label = ox.NamedNode(EX + "label")
    for i, value in enumerate([*HOSTILE, "plain"]):
        store.add(ox.Quad(ox.NamedNode(f"{EX}n{i}"), label, ox.Literal(value)))
    return store


QUERY = f"""# the nodes with a label
PREFIX ex: <{EX}>
SELECT ?node ?label WHERE {{ ?node ex:label ?label }} ORDER BY ?node"""


@pytest.mark.parametrize("value", HOSTILE)
def test_a_hostile_value_matches_only_itself(store: ox.Store, value: str) -> None:
    text = bind_values(QUERY, {"label": value})
    result = store.query(text)
    assert isinstance(result, ox.QuerySolutions)
    rows = [(s["node"], s["label"]) for s in result]
    index = HOSTILE.index(value)
    assert rows == [(ox.NamedNode(f"{EX}n{index}"), ox.Literal(value))]


def test_values_block_escapes_the_value() -> None:
    block = values_clause({"label": 'a"b\nc}'})
    assert block == 'VALUES (?label) { ("a\\"b\\nc}") }'
    assert "\n" not in block


def test_values_types_numbers_and_iris() -> None:
    block = values_clause({"n": 3, "d": Decimal("0.75"), "x": 1.5, "ok": True, "iri": ox.NamedNode(EX + "a")})
    assert block == (
        "VALUES (?n ?d ?x ?ok ?iri) { ("
        '"3"^^<http://www.w3.org/2001/XMLSchema#integer> '
        '"0.75"^^<http://www.w3.org/2001/XMLSchema#decimal> '
        '"1.5"^^<http://www.w3.org/2001/XMLSchema#double> '
        '"true"^^<http://www.w3.org/2001/XMLSchema#boolean> '
        "<http://example.org/a>) }"
    )


@pytest.mark.parametrize("name", ["a) { }", "x y", "", "?x"])
def test_a_bad_variable_name_is_refused(name: str) -> None:
    with pytest.raises(QueryError, match="not a SPARQL variable name"):
        values_clause({name: "v"})


def test_an_iri_that_would_break_out_is_refused() -> None:
    with pytest.raises(ValueError):
        values_clause({"iri": ox.NamedNode("http://example.org/a> } DROP ALL <x")})


def test_block_opens_the_where_group_not_a_template_string_or_comment() -> None:
    text = """PREFIX ex: <http://example.org/#x>
# a comment with { a brace
CONSTRUCT { ?node ex:seen "{" } WHERE { ?node ex:label ?label }"""
    bound = bind_values(text, {"label": "plain"})
    assert bound.endswith('WHERE { VALUES (?label) { ("plain") }  ?node ex:label ?label }')
    # Short CONSTRUCT WHERE, ASK, and a SELECT whose projection holds a group.
    assert "WHERE { VALUES (?a)" in bind_values("CONSTRUCT WHERE { ?s ?p ?a }", {"a": 1})
    assert bind_values("ASK { ?s ?p ?a }", {"a": 1}).startswith("ASK { VALUES (?a)")
    select = "SELECT (EXISTS { ?s ?p ?o } AS ?e) ?a WHERE { ?s ?p ?a }"
    assert "WHERE { VALUES (?a)" in bind_values(select, {"a": 1})
    # No group at all: the grammar's trailing VALUES.
    described = bind_values("DESCRIBE <http://example.org/a>", {"a": 1})
    assert described.endswith('\nVALUES (?a) { ("1"^^<http://www.w3.org/2001/XMLSchema#integer>) }')


def test_bound_sub_select_query_keeps_its_meaning(store: ox.Store) -> None:
    text = f"""SELECT ?label ?node WHERE {{
      {{ SELECT ?label ?node WHERE {{ ?node <{EX}label> ?label }} }}
    }}"""
    result = store.query(bind_values(text, {"label": "plain"}))
    assert isinstance(result, ox.QuerySolutions)
    assert [s["node"] for s in result] == [ox.NamedNode(f"{EX}n{len(HOSTILE)}")]


def test_no_bindings_leave_the_text_alone() -> None:
    assert bind_values(QUERY, {}) == QUERY


@pytest.mark.parametrize(
    ("text", "form"),
    [
        ("select * { ?s ?p ?o }", "SELECT"),
        ("# SELECT in a comment\nPREFIX a: <urn:a#>\nBASE <urn:b>\n ASK { ?s ?p ?o }", "ASK"),
        ("PREFIX : <urn:x#> CONSTRUCT WHERE { ?s ?p ?o }", "CONSTRUCT"),
        ("DESCRIBE <urn:x>", "DESCRIBE"),
    ],
)
def test_query_form(text: str, form: str) -> None:
    assert query_form(text) == form


def test_an_update_is_not_a_query() -> None:
    with pytest.raises(QueryError, match="not a SPARQL query"):
        query_form("DROP ALL")


def _parse_error(text: str) -> SyntaxError:
    with pytest.raises(SyntaxError) as info:
        ox.Store().query(text)
    return info.value


@pytest.mark.parametrize(
    ("text", "line"),
    [
        (
            "SELECT * WHERE { ?s ?p ?o }\nLIMIT x",
            "SPARQL syntax error at line 2, column 7 (found 'x', expected one of HAVING, OFFSET, "
            "OPTIONAL, VALUES)",
        ),
        (
            "SELECT * WHERE { ?s foo:bar ?o }",
            "SPARQL syntax error at line 1, column 28 (found '?o', expected a prefix declared with "
            "PREFIX name: <iri> or one of ck, rdf)",
        ),
        ("SELECT * WHERE { ?s ?p", "SPARQL syntax error at line 1, column 23 (found the end of the query, "),
    ],
)
def test_a_parse_error_is_one_line_saying_where_what_and_what_would_do(text: str, line: str) -> None:
    message = syntax_error_message(_parse_error(text), text, ["rdf", "ck"])
    assert "\n" not in message
    assert message.startswith(line)
    assert "[" not in message  # the parser's character classes are left out
    assert message.count(", ") <= 20  # at most twelve tokens, then "…"


def test_a_message_in_another_form_is_kept_whole() -> None:
    assert syntax_error_message("unexpected", "SELECT") == "SPARQL syntax error: unexpected"
