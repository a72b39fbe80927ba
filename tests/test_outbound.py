"""Finding SERVICE and LOAD in SPARQL text, held against rdflib's query algebra wherever rdflib
parses the text, and the allow-list check."""

from __future__ import annotations

from typing import Any

import pytest
from rdflib.plugins.sparql.algebra import translateQuery, translateUpdate
from rdflib.plugins.sparql.parser import parseQuery, parseUpdate
from rdflib.plugins.sparql.parserutils import CompValue
from rdflib.term import URIRef

from cadkg.errors import QueryError
from cadkg.outbound import check_outbound, outbound_requests
from cadkg.query.named import named_queries
from cadkg.store import PREFIXES

E = "http://127.0.0.1:18999/sparql"
QUERIES = [
    f"SELECT * WHERE {{ SERVICE <{E}> {{ ?s ?p ?o }} }}",
    f"select * where {{ service <{E}> {{ ?s ?p ?o }} }}",
    f"SELECT * WHERE {{ SeRvIcE SiLeNt <{E}> {{ ?s ?p ?o }} }}",
    "SELECT * WHERE { SERVICE SILENT ?e { ?s ?p ?o } }",
    "SELECT * WHERE { service ?endpoint { ?s ?p ?o } }",
    "PREFIX e: <http://127.0.0.1:18999/> SELECT * WHERE { SERVICE e:sparql { ?s ?p ?o } }",
    "PREFIX : <http://127.0.0.1:18999/> SELECT * WHERE { SERVICE :sparql { ?s ?p ?o } }",
    "BASE <http://127.0.0.1:18999/> SELECT * WHERE { SERVICE <sparql> { ?s ?p ?o } }",
    f"SELECT * WHERE {{ ?s ?p ?o OPTIONAL {{ SERVICE <{E}> {{ ?s ?q ?r }} }} }}",
    f"SELECT * WHERE {{ {{ SELECT ?s WHERE {{ SERVICE <{E}> {{ ?s ?p ?o }} }} }} }}",
    f"ASK {{ FILTER EXISTS {{ SERVICE <{E}> {{ ?s ?p ?o }} }} }}",
    f"SELECT * WHERE {{ {{ ?s ?p ?o }} UNION {{ SERVICE <{E}> {{ ?s ?p ?o }} }} }}",
    f"SELECT * WHERE {{ SERVICE <{E}> {{ SERVICE <{E}2> {{ ?s ?p ?o }} }} }}",
    f"CONSTRUCT {{ ?s ?p ?o }} WHERE {{ SERVICE <{E}> {{ ?s ?p ?o }} }}",
    f"SELECT * WHERE{{SERVICE<{E}>{{?s ?p ?o}}}}",
    f"SELECT * WHERE {{ # SERVICE <{E}> {{ }}\n ?s ?p ?o }}",
    f"SELECT * WHERE {{ ?s ?p 'SERVICE <{E}> {{ }}' }}",
    f'SELECT * WHERE {{ ?s ?p """a\nSERVICE <{E}> {{ }}""" }}',
    f'SELECT * WHERE {{ ?s ?p "it\'s SERVICE <{E}>"@en }}',
    "PREFIX service: <urn:x:> SELECT ?service WHERE { ?service service:load ?load }",
    "SELECT * WHERE { ?s <urn:x:service> ?o ; <urn:x:load> ?l }",
    "SELECT * WHERE { ?s ?p ?o FILTER(?o = 'load') }",
    "SELECT (COUNT(*) AS ?n) WHERE { ?a ?b ?c . ?d ?e ?f . ?g ?h ?i }",
    "SELECT * WHERE { ?s ck:label ?l } ORDER BY ?l LIMIT 3",
]
UPDATES = [
    f"LOAD <{E}>",
    f"load silent <{E}> into graph <urn:g>",
    f"INSERT {{ GRAPH <urn:g> {{ ?s ?p ?o }} }} WHERE {{ SERVICE <{E}> {{ ?s ?p ?o }} }}",
    "INSERT DATA { GRAPH <urn:g> { <urn:s> <urn:p> 'LOAD <http://x/>' } }",
    "CLEAR GRAPH <urn:load>",
]


def _named_queries() -> list[str]:
    return [query.text for query in named_queries().values()]


def _walk(node: Any) -> list[CompValue]:
    found = []
    if isinstance(node, CompValue):
        found.append(node)
        children: Any = node.values()
    elif isinstance(node, list | tuple):
        children = node
    else:
        return found
    for child in children:
        found += _walk(child)
    return found


def _rdflib_targets(text: str, update: bool) -> list[tuple[str, str | None]] | None:
    """What rdflib's algebra says the text reaches, or None when rdflib does not parse it."""
    try:
        algebra = (
            translateUpdate(parseUpdate(text), initNs=PREFIXES).algebra
            if update
            else translateQuery(parseQuery(text), initNs=PREFIXES).algebra
        )
    except Exception:
        return None
    targets = []
    for node in _walk(algebra):
        if node.name == "ServiceGraphPattern":
            term = node["term"]
            targets.append(("SERVICE", str(term) if isinstance(term, URIRef) else None))
        elif node.name == "Load":
            targets.append(("LOAD", str(node["iri"])))
    return targets


@pytest.mark.parametrize(
    ("text", "update"),
    [(q, False) for q in QUERIES + _named_queries()] + [(u, True) for u in UPDATES],
)
def test_as_rdflibs_algebra_says(text: str, update: bool) -> None:
    expected = _rdflib_targets(text, update)
    if expected is None:
        pytest.skip("rdflib does not parse this text")
    found = [(o.keyword, o.target) for o in outbound_requests(text, PREFIXES)]
    assert sorted(found, key=str) == sorted(expected, key=str)


def test_what_rdflib_cannot_parse_is_found_too() -> None:
    star = f"SELECT * WHERE {{ << ?s ?p ?o >> ?q ?r . SERVICE <{E}> {{ ?s ?p ?o }} }}"
    assert _rdflib_targets(star, False) is None
    assert [o.target for o in outbound_requests(star)] == [E]
    escaped = "SELECT * WHERE { SERVICE <http://127.0.0.1\\u003A18999/sparql> { ?s ?p ?o } }"
    assert [o.target for o in outbound_requests(escaped)] == [E]


def test_the_allow_list() -> None:
    check_outbound("SELECT * WHERE { ?s ?p ?o }", ())
    with pytest.raises(QueryError, match=r"^SERVICE <http.*> is refused: cadkg makes no outbound requests"):
        check_outbound(QUERIES[0], ())
    check_outbound(QUERIES[0], (E,))
    check_outbound(QUERIES[5], (E,))  # a prefixed name resolved
    with pytest.raises(QueryError, match=r"SERVICE <http://127.0.0.1:18999/sparql2> is refused: not one of"):
        check_outbound(QUERIES[12], (E,))
    with pytest.raises(QueryError, match=r"^SERVICE \?e is refused: only an endpoint written as an IRI"):
        check_outbound(QUERIES[3], (E,))
    with pytest.raises(QueryError, match=r"^LOAD <.*> is refused"):
        check_outbound(UPDATES[0], ())
