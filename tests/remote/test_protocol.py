"""How a remote query is written and read: prefixes, credentials, push batches, result sets
(no store needed). Bound values and query forms: ``tests/test_sparql_text.py``."""

from __future__ import annotations

import httpx
import pyoxigraph as ox
import pytest

from cadkg.errors import StoreError
from cadkg.push import _batches
from cadkg.remote import (
    RemoteGraph,
    auth_from_env,
    is_url,
    parse_auth,
    with_prefixes,
)
from cadkg.store import PREFIXES

EX = "http://example.org/"


def test_prefixes_are_declared_unless_the_query_does() -> None:
    text = with_prefixes("PREFIX ck: <urn:mine#>\nSELECT * WHERE { ?s a ck:Wire }")
    assert "PREFIX ck: <https://w3id.org/cadkg#>" not in text
    for name in PREFIXES.keys() - {"ck"}:
        assert f"PREFIX {name}: <{PREFIXES[name]}>" in text
    result = ox.Store().query(with_prefixes("SELECT ?c WHERE { ?c a owl:Class ; rdfs:label ?l }"))
    assert isinstance(result, ox.QuerySolutions)


def test_urls_and_credentials() -> None:
    assert is_url("http://127.0.0.1:8890/sparql") and is_url("HTTPS://h/sparql")
    assert not is_url("build/iema") and not is_url("examples/x/manifest.toml")
    auth = parse_auth("cadkg:pa:ss", digest=True)
    assert (auth.user, auth.password, auth.digest) == ("cadkg", "pa:ss", True)
    assert "pa:ss" not in repr(auth)
    assert isinstance(auth.httpx_auth(), httpx.DigestAuth)
    with pytest.raises(StoreError, match="user:password"):
        parse_auth("nocolon")
    assert auth_from_env({}) is None
    assert auth_from_env({"CADKG_STORE_AUTH": "u:p"}) == parse_auth("u:p")
    assert auth_from_env({"CADKG_STORE_AUTH_DIGEST": "u:p"}) == parse_auth("u:p", digest=True)


def test_a_remote_graph_needs_an_http_url() -> None:
    with pytest.raises(StoreError, match="not an http"):
        RemoteGraph("ftp://example.org/sparql")


def test_a_remote_graph_has_no_local_store() -> None:
    graph = RemoteGraph("http://127.0.0.1:9/sparql?default-graph-uri=urn:g")
    with pytest.raises(StoreError, match="read-only"):
        graph.assign("wire", "1", "robot")
    with pytest.raises(StoreError, match="not available on a remote store"):
        graph._store  # noqa: B018 - the property is what is tested
    graph.close()


def test_push_batches_keep_blank_nodes_together() -> None:
    a, p = ox.NamedNode(EX + "a"), ox.NamedNode(EX + "p")
    plain = [ox.Triple(a, p, ox.Literal(str(i))) for i in range(7)]
    blank = [ox.Triple(ox.BlankNode("b"), p, ox.Literal("x")), ox.Triple(a, p, ox.BlankNode("b"))]
    batches = list(_batches([plain[0], blank[0], *plain[1:], blank[1]], 3))
    assert batches[0][:2] == blank and len(batches[0]) == 3
    assert [len(b) for b in batches] == [3, 3, 3]
    assert sorted(str(t) for b in batches for t in b) == sorted(str(t) for t in plain + blank)
    assert list(_batches([], 5)) == [[]]


def test_turtle_result_set_rows_in_document_order() -> None:
    from cadkg.remote import _turtle_solutions

    data = b"""@prefix res: <http://www.w3.org/2005/sparql-results#> .
_:_ a res:ResultSet .
_:_ res:resultVariable "qz" , "n" .
_:_ res:solution [
      res:binding [ res:variable "qz" ; res:value 0.70710678231972268204 ] ;
      res:binding [ res:variable "n" ; res:value 457 ] ] .
_:_ res:solution [
      res:binding [ res:variable "qz" ; res:value 0.25 ] ] .
"""
    rows = _turtle_solutions(data)
    assert rows == [{"qz": "0.70710678231972268204", "n": "457"}, {"qz": "0.25"}]
    assert repr(float(rows[0]["qz"])) == "0.7071067823197227"
    assert _turtle_solutions(b"not turtle {") == []
