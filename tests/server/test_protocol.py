"""The SPARQL 1.1 Protocol over a real uvicorn server on the IEMA example (examples/iema-switchgear).

Expected values come from the example's files: ``lista-cablaggio.csv`` has 110 wires (114 lines,
4 of them preamble and header); its first wire ``1500.51`` goes from ``=-F1500.1:14`` to
``=-Q1500.1:A1``, 0,75 mm², colour BU, 0,746 m.
"""

from __future__ import annotations

import asyncio
import csv
import io
import json
import re
import shutil
import subprocess
import xml.etree.ElementTree as ET

import httpx
import pyoxigraph as ox
import pytest
from SPARQLWrapper import JSON, XML, SPARQLWrapper
from starlette.requests import Request

import cadkg
from cadkg.ontology.terms import CK_NS
from cadkg.server.protocol import BodyTooLargeError, read_body
from tests.server.serving import serving

BASE = "https://example.org/cell/iema-qe01/"
WIRE = f"{BASE}wire/1500.51"
LIST_GRAPH = f"{BASE}graph/lista-cablaggio.csv"
WRI_GRAPH = f"{BASE}graph/ids.wri"
WIRES = "SELECT (COUNT(DISTINCT ?w) AS ?n) WHERE { ?w a ck:Wire }"
ENDS = (
    f"SELECT ?from ?to ?section ?colour WHERE {{ <{WIRE}> ck:fromPin ?from ; ck:toPin ?to ; "
    "ck:crossSectionMm2 ?section ; ck:colour ?colour }"
)
SRJ = "application/sparql-results+json"


def bindings(response: httpx.Response) -> list[dict[str, str]]:
    assert response.status_code == 200, response.text
    data = response.json()
    return [{k: v["value"] for k, v in row.items()} for row in data["results"]["bindings"]]


def test_get_post_form_and_body_answer_alike(url: str) -> None:
    expected = [
        {
            "from": f"{BASE}pin/F1500.1/14",
            "to": f"{BASE}pin/Q1500.1/A1",
            "section": "0.75",
            "colour": "BU",
        }
    ]
    get = httpx.get(f"{url}/sparql", params={"query": ENDS}, headers={"Accept": SRJ})
    form = httpx.post(f"{url}/sparql", data={"query": ENDS}, headers={"Accept": SRJ})
    body = httpx.post(
        f"{url}/sparql", content=ENDS, headers={"Content-Type": "application/sparql-query", "Accept": SRJ}
    )
    for response in (get, form, body):
        assert response.headers["content-type"].startswith(SRJ)
        assert bindings(response) == expected
    typed = get.json()["results"]["bindings"][0]
    assert typed["section"] == {
        "type": "literal",
        "value": "0.75",
        "datatype": "http://www.w3.org/2001/XMLSchema#decimal",
    }
    assert typed["from"]["type"] == "uri"
    assert typed["colour"] == {"type": "literal", "value": "BU"}  # xsd:string: no datatype written


def test_results_as_xml_csv_tsv(url: str) -> None:
    query = f"SELECT ?n ?len WHERE {{ <{WIRE}> ck:wireNumber ?n ; ck:lengthM ?len }}"
    xml = httpx.get(
        f"{url}/sparql", params={"query": query}, headers={"Accept": "application/sparql-results+xml"}
    )
    assert xml.headers["content-type"].startswith("application/sparql-results+xml")
    ns = {"s": "http://www.w3.org/2005/sparql-results#"}
    root = ET.fromstring(xml.content)
    assert [v.get("name") for v in root.findall("s:head/s:variable", ns)] == ["n", "len"]
    literal = root.find("s:results/s:result/s:binding[@name='len']/s:literal", ns)
    assert literal is not None and literal.text == "0.746"
    assert literal.get("datatype") == "http://www.w3.org/2001/XMLSchema#decimal"

    text = httpx.get(f"{url}/sparql", params={"query": query}, headers={"Accept": "text/csv"})
    assert text.headers["content-type"].startswith("text/csv")
    assert list(csv.reader(io.StringIO(text.text))) == [["n", "len"], ["1500.51", "0.746"]]

    tsv = httpx.get(f"{url}/sparql", params={"query": query, "format": "tsv"})
    assert tsv.headers["content-type"].startswith("text/tab-separated-values")
    assert tsv.text.splitlines() == [
        "?n\t?len",
        '"1500.51"\t"0.746"^^<http://www.w3.org/2001/XMLSchema#decimal>',
    ]


def test_ask(url: str) -> None:
    yes = httpx.get(
        f"{url}/sparql", params={"query": f"ASK {{ <{WIRE}> a ck:Wire }}"}, headers={"Accept": SRJ}
    )
    assert yes.json() == {"head": {}, "boolean": True}
    no = httpx.get(
        f"{url}/sparql", params={"query": "ASK { ?w ck:wireNumber 'no such wire' }", "format": "xml"}
    )
    assert b"<boolean>false</boolean>" in no.content


@pytest.mark.parametrize(
    ("accept", "rdf_format"),
    [
        ("text/turtle", ox.RdfFormat.TURTLE),
        ("application/n-triples", ox.RdfFormat.N_TRIPLES),
        ("application/ld+json", ox.RdfFormat.JSON_LD),
        ("application/rdf+xml", ox.RdfFormat.RDF_XML),
    ],
)
def test_construct_as_graph_formats(url: str, accept: str, rdf_format: ox.RdfFormat) -> None:
    query = f"CONSTRUCT {{ <{WIRE}> ?p ?o }} WHERE {{ GRAPH <{LIST_GRAPH}> {{ <{WIRE}> ?p ?o }} }}"
    response = httpx.get(f"{url}/sparql", params={"query": query}, headers={"Accept": accept})
    assert response.status_code == 200, response.text
    assert response.headers["content-type"].split(";")[0] == accept
    triples = {q.triple for q in ox.parse(response.content, format=rdf_format)}
    colour = ox.Triple(ox.NamedNode(WIRE), ox.NamedNode(CK_NS + "colour"), ox.Literal("BU"))
    assert colour in triples
    # The wire's row of the list: 14 columns become 20 triples (type, plan, index, line ...).
    assert len(triples) == 20


def test_describe_defaults_to_turtle(url: str) -> None:
    response = httpx.get(f"{url}/sparql", params={"query": f"DESCRIBE <{WIRE}>"})
    assert response.headers["content-type"].startswith("text/turtle")
    assert "1500.51" in response.text


def test_not_acceptable(url: str) -> None:
    construct = "CONSTRUCT { ?s ?p ?o } WHERE { ?s ?p ?o } LIMIT 1"
    response = httpx.get(f"{url}/sparql", params={"query": construct}, headers={"Accept": "text/csv"})
    assert response.status_code == 406
    assert "text/turtle" in response.text
    bad = httpx.get(f"{url}/sparql", params={"query": WIRES, "format": "yaml"})
    assert bad.status_code == 406


def test_default_and_named_graph_uri(url: str) -> None:
    def count(**params: str | list[str]) -> int:
        response = httpx.get(f"{url}/sparql", params={"query": WIRES, **params}, headers={"Accept": SRJ})
        return int(bindings(response)[0]["n"])

    assert count() == 110
    assert count(**{"default-graph-uri": LIST_GRAPH}) == 110
    assert count(**{"default-graph-uri": WRI_GRAPH}) == 0
    assert count(**{"default-graph-uri": [WRI_GRAPH, LIST_GRAPH]}) == 110
    graphs = "SELECT DISTINCT ?g WHERE { GRAPH ?g { ?s ?p ?o } } ORDER BY ?g"
    only = httpx.get(
        f"{url}/sparql",
        params={"query": graphs, "named-graph-uri": [WRI_GRAPH, LIST_GRAPH]},
        headers={"Accept": SRJ},
    )
    assert [row["g"] for row in bindings(only)] == [WRI_GRAPH, LIST_GRAPH]


def test_syntax_error_is_400_with_the_parsers_message_and_position(url: str) -> None:
    response = httpx.get(f"{url}/sparql", params={"query": "SELECT ?x WHERE {\n  ?x ck:label }"})
    assert response.status_code == 400
    assert response.headers["content-type"].startswith("text/plain")
    lines = response.text.splitlines()
    assert lines[0].startswith("SPARQL syntax error at line 2, column ")
    assert "expected" in lines[0]
    assert lines[1] == "  ?x ck:label }"
    assert lines[2].strip() == "^"
    assert "Traceback" not in response.text


def test_protocol_misuse_is_400_or_415(url: str) -> None:
    assert httpx.get(f"{url}/sparql").status_code == 400
    both = httpx.post(f"{url}/sparql", data={"query": WIRES, "update": "CLEAR ALL"})
    assert both.status_code == 400
    update_by_get = httpx.get(f"{url}/sparql", params={"update": "CLEAR ALL"})
    assert update_by_get.status_code == 400 and "POST" in update_by_get.text
    wrong_type = httpx.post(f"{url}/sparql", content=WIRES, headers={"Content-Type": "text/plain"})
    assert wrong_type.status_code == 415


def test_updates_refused_by_default(url: str) -> None:
    response = httpx.post(f"{url}/sparql", data={"update": "CLEAR ALL"})
    assert response.status_code == 403
    assert "--allow-update" in response.text
    gsp = httpx.delete(f"{url}/graph-store", params={"graph": LIST_GRAPH})
    assert gsp.status_code == 403
    count = httpx.get(f"{url}/sparql", params={"query": WIRES}, headers={"Accept": SRJ})
    assert bindings(count)[0]["n"] == "110"


def test_graph_store_read(url: str) -> None:
    response = httpx.get(
        f"{url}/graph-store", params={"graph": LIST_GRAPH}, headers={"Accept": "application/n-triples"}
    )
    assert response.status_code == 200
    wires = {
        q.triple.subject
        for q in ox.parse(response.content, format=ox.RdfFormat.N_TRIPLES)
        if q.triple.object == ox.NamedNode(CK_NS + "Wire")
    }
    assert len(wires) == 110
    missing = httpx.get(f"{url}/graph-store", params={"graph": f"{BASE}graph/nothing"})
    assert missing.status_code == 404


def test_foreign_host_header_is_refused(url: str) -> None:
    response = httpx.get(f"{url}/sparql", params={"query": WIRES}, headers={"Host": "attacker.example:7878"})
    assert response.status_code == 400
    assert "not this machine" in response.text
    assert (
        httpx.get(f"{url}/sparql", params={"query": WIRES}, headers={"Host": "localhost:7878"}).status_code
        == 200
    )


def test_page_and_security_headers(url: str) -> None:
    page = httpx.get(f"{url}/")
    assert page.status_code == 200, "the web page is not built: run scripts/build-web.sh"
    assert 'id="query"' in page.text
    assert page.headers["content-security-policy"].startswith("default-src 'self'")
    assert "unsafe" not in page.headers["content-security-policy"]
    # The page loads its own files only, each from this endpoint.
    assets = re.findall(r'(?:src|href)="([^"]+)"', page.text)
    assert assets and all(a.startswith("/") and not a.startswith("//") for a in assets), assets
    for asset in assets:
        assert httpx.get(f"{url}{asset}").status_code == 200, asset


def test_sparqlwrapper_as_a_client(url: str) -> None:
    client = SPARQLWrapper(f"{url}/sparql")
    client.setQuery(f"PREFIX ck: <{CK_NS}> SELECT ?n WHERE {{ <{WIRE}> ck:wireNumber ?n }}")
    client.setReturnFormat(JSON)
    data = client.query().convert()
    assert isinstance(data, dict)
    assert data["results"]["bindings"] == [{"n": {"type": "literal", "value": "1500.51"}}]
    client.setReturnFormat(XML)
    client.setMethod("POST")
    document = client.query().convert()
    assert "1500.51" in document.toxml()  # type: ignore[union-attr]


@pytest.mark.skipif(shutil.which("curl") is None, reason="curl is not installed")
def test_curl_as_a_client(url: str) -> None:
    result = subprocess.run(
        [
            "curl",
            "-sS",
            "--fail-with-body",
            "-H",
            f"Accept: {SRJ}",
            "--data-urlencode",
            f"query={WIRES}",
            f"{url}/sparql",
        ],
        capture_output=True,
        text=True,
        timeout=30,
        check=False,
    )
    assert result.returncode == 0, result.stderr + result.stdout
    assert json.loads(result.stdout)["results"]["bindings"][0]["n"]["value"] == "110"


# -- limits -------------------------------------------------------------------------------------


def test_row_cap(iema: cadkg.KnowledgeGraph) -> None:
    with serving(iema, max_rows=5) as base:
        query = "SELECT DISTINCT ?n WHERE { ?w ck:wireNumber ?n } ORDER BY ?n"
        response = httpx.get(f"{base}/sparql", params={"query": query}, headers={"Accept": SRJ})
        assert response.headers["x-cadkg-truncated"] == "5"
        assert [row["n"] for row in bindings(response)] == [
            "0010.01",
            "0010.02",
            "0010.03",
            "0010.04",
            "0010.05",
        ]
        small = httpx.get(f"{base}/sparql", params={"query": f"{query} LIMIT 3"}, headers={"Accept": SRJ})
        assert "x-cadkg-truncated" not in small.headers
        assert len(bindings(small)) == 3


def test_time_limit_is_503_and_frees_the_worker(iema: cadkg.KnowledgeGraph) -> None:
    # About 10^9 solutions that stream: the reader stops at the deadline.
    endless = "SELECT * WHERE { ?a ?p ?b . ?c ?q ?d }"
    with serving(iema, timeout=0.5, max_rows=10**9, workers=1) as base:
        response = httpx.get(f"{base}/sparql", params={"query": endless}, headers={"Accept": SRJ}, timeout=30)
        assert response.status_code == 503
        assert response.headers["retry-after"] == "5"
        assert "time limit of 0.5 s" in response.text
        assert response.elapsed.total_seconds() < 5
        # The single worker is free again: a quick query answers.
        quick = httpx.get(f"{base}/sparql", params={"query": WIRES}, headers={"Accept": SRJ}, timeout=30)
        assert bindings(quick)[0]["n"] == "110"


def test_time_limit_holds_for_a_blocking_query(iema: cadkg.KnowledgeGraph) -> None:
    # A count over 110 wires × every triple, compared as strings: one blocking step of about
    # 2 s that pyoxigraph cannot interrupt; the client still gets its 503 at the limit.
    blocking = (
        "SELECT (COUNT(*) AS ?n) WHERE { ?a a ck:Wire . ?b ?p ?o "
        "FILTER(STR(?o) != STR(?a) && STR(?b) != STR(?a)) }"
    )
    with serving(iema, timeout=0.3) as base:
        response = httpx.get(f"{base}/sparql", params={"query": blocking}, timeout=30)
        assert response.status_code == 503
        assert response.elapsed.total_seconds() < 1.2
        quick = httpx.get(f"{base}/sparql", params={"query": WIRES}, headers={"Accept": SRJ}, timeout=30)
        assert quick.status_code == 200


def test_body_size_limit(iema: cadkg.KnowledgeGraph) -> None:
    with serving(iema, max_body=200) as base:
        padded = WIRES + " #" + "x" * 300
        response = httpx.post(
            f"{base}/sparql", content=padded, headers={"Content-Type": "application/sparql-query"}
        )
        assert response.status_code == 413
        assert "limit of 200 bytes" in response.text
        fits = httpx.post(
            f"{base}/sparql", content=WIRES, headers={"Content-Type": "application/sparql-query"}
        )
        assert fits.status_code == 200


# -- updates --------------------------------------------------------------------------------------

TOKEN = "s3cret-for-tests"
INSERT = 'INSERT DATA { GRAPH <urn:test:notes> { <urn:test:n1> rdfs:label "first note" } }'
ASK_NOTE = 'ASK { <urn:test:n1> rdfs:label "first note" }'


def test_updates_need_the_token() -> None:
    from cadkg.server import Settings

    kg = cadkg.KnowledgeGraph.memory()
    with serving(kg, Settings(allow_update=True, token=TOKEN, watch_seconds=0)) as base:
        none = httpx.post(f"{base}/sparql", data={"update": INSERT})
        assert none.status_code == 401
        assert none.headers["www-authenticate"].startswith("Bearer")
        wrong = httpx.post(
            f"{base}/sparql", data={"update": INSERT}, headers={"Authorization": "Bearer nope"}
        )
        assert wrong.status_code == 401
        assert not kg.ask(ASK_NOTE)
        right = httpx.post(
            f"{base}/sparql",
            content=INSERT,
            headers={"Content-Type": "application/sparql-update", "Authorization": f"Bearer {TOKEN}"},
        )
        assert right.status_code == 200, right.text
        assert kg.ask(ASK_NOTE)
        seen = httpx.get(f"{base}/sparql", params={"query": ASK_NOTE}, headers={"Accept": SRJ})
        assert seen.json()["boolean"] is True
        broken = httpx.post(
            f"{base}/sparql",
            data={"update": "INSERT DATA { <a> }"},
            headers={"Authorization": f"Bearer {TOKEN}"},
        )
        assert broken.status_code == 400 and "syntax error" in broken.text


def test_graph_store_writes_with_the_token() -> None:
    from cadkg.server import Settings

    kg = cadkg.KnowledgeGraph.memory()
    graph = "urn:test:uploaded"
    turtle = '@prefix ck: <https://w3id.org/cadkg#> . <urn:test:w> a ck:Wire ; ck:wireNumber "9.99" .'
    auth = {"Authorization": f"Bearer {TOKEN}", "Content-Type": "text/turtle"}
    with serving(kg, Settings(allow_update=True, token=TOKEN, watch_seconds=0)) as base:
        store = f"{base}/graph-store"
        assert (
            httpx.put(
                store, params={"graph": graph}, content=turtle, headers={"Content-Type": "text/turtle"}
            ).status_code
            == 401
        )
        created = httpx.put(store, params={"graph": graph}, content=turtle, headers=auth)
        assert created.status_code == 201
        assert graph in kg.named_graphs()
        assert kg.query("SELECT ?n WHERE { ?w ck:wireNumber ?n }").rows == ({"n": "9.99"},)
        added = httpx.post(
            store, params={"graph": graph}, content='<urn:test:w> <urn:test:p> "x" .', headers=auth
        )
        assert added.status_code == 204
        read = httpx.get(store, params={"graph": graph}, headers={"Accept": "application/n-triples"})
        assert len(list(ox.parse(read.content, format=ox.RdfFormat.N_TRIPLES))) == 3
        replaced = httpx.put(
            store, params={"graph": graph}, content="<urn:test:a> <urn:test:b> <urn:test:c> .", headers=auth
        )
        assert replaced.status_code == 204
        assert len(kg.query(f"SELECT * WHERE {{ GRAPH <{graph}> {{ ?s ?p ?o }} }}")) == 1
        bad = httpx.put(store, params={"graph": graph}, content="<urn:a> <urn:b> .", headers=auth)
        assert bad.status_code == 400 and "does not parse" in bad.text
        assert httpx.delete(store, params={"graph": graph}, headers=auth).status_code == 204
        assert graph not in kg.named_graphs()
        assert httpx.delete(store, params={"graph": graph}, headers=auth).status_code == 404


def test_settings_refuse_updates_without_a_token() -> None:
    from cadkg.server import Settings

    with pytest.raises(ValueError, match="token"):
        Settings(allow_update=True)


@pytest.mark.parametrize("declared", ["9" * 5000, "0" * 40 + "201", "12345678901234567890"])
def test_declared_body_length_over_the_limit(declared: str) -> None:
    # Beside the served test above: a declared length is compared without int() on all of it,
    # which refuses more than 4,300 digits.
    async def nothing() -> dict[str, object]:
        return {"type": "http.request", "body": b"", "more_body": False}

    scope = {"type": "http", "method": "POST", "headers": [(b"content-length", declared.encode())]}
    with pytest.raises(BodyTooLargeError, match="over the limit of 200 bytes"):
        asyncio.run(read_body(Request(scope, nothing), 200))
