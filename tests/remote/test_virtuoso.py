"""The IEMA cell in a real Virtuoso Open Source: push it, then query it remotely like the embedded store.

``scripts/virtuoso.sh`` installs Debian's virtuoso-opensource when it is missing and starts a
private instance on loopback; the test is skipped only when apt cannot install it (exit 3),
with the script's reason.

Answers are compared row by row with the embedded store's: as multisets of rows, and in
the same order of the ORDER BY keys where the query has them (ties may come in any order).
Values keep their Python type (a typed literal must come back with its datatype); doubles
are compared to 12 significant digits, since Virtuoso writes xsd:double with 15.
"""

from __future__ import annotations

import json
import math
import re
import subprocess
from collections import Counter
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cadkg.errors import QueryError, StoreError
from cadkg.graph import KnowledgeGraph
from cadkg.push import push
from cadkg.query.named import named_queries
from cadkg.remote import Auth, RemoteGraph
from cadkg.services.service import to_jsonable
from cadkg.services.session import Session
from cadkg.services.table import call, services_for
from cadkg.store import QueryResult
from tests.cli import run
from tests.conftest import IEMA, ROOT
from tests.remote.virtuoso import running_virtuoso

pytestmark = pytest.mark.live

# Sample parameters of the named queries: values of the IEMA cell (others answer nothing there).
SAMPLES = {
    "label": "F1500.1",
    "wireNumber": "1500.51",
    "harness": "DOOR-L",
    "connector": "X1",
    "segment": "S1",
}
IEMA_QUERIES = {
    "components",
    "connections-in-order",
    "pins-of-component",
    "sources",
    "wire-endpoints",
    "wires-by-colour-section",
    "wires-of-component",
}
SERVICE_LABELS = {"get_terminal_data": "X1600", "cluster_service": "X1600"}
COUNTS = "SELECT ?g (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } } GROUP BY ?g"


@pytest.fixture(scope="module")
def virtuoso(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, str]]:
    with running_virtuoso(tmp_path_factory.mktemp("virtuoso")) as env:
        yield env


@pytest.fixture(scope="module")
def auth(virtuoso: dict[str, str]) -> Auth:
    return Auth(virtuoso["VIRTUOSO_USER"], virtuoso["VIRTUOSO_PASSWORD"], digest=True)


@pytest.fixture(scope="module")
def local(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Path]:
    store = tmp_path_factory.mktemp("iema") / "store"
    KnowledgeGraph.build(IEMA, store).close()
    yield store


@pytest.fixture(scope="module")
def embedded(local: Path) -> Iterator[KnowledgeGraph]:
    with KnowledgeGraph.open(local) as kg:
        yield kg


@pytest.fixture(scope="module")
def pushed(virtuoso: dict[str, str], local: Path) -> str:
    """The CLI's push through the Graph Store Protocol; its printed report."""
    result = run(
        "push",
        local,
        "--endpoint",
        virtuoso["VIRTUOSO_SPARQL_AUTH"],
        "--graph-store",
        virtuoso["VIRTUOSO_GRAPH_STORE"],
        "--auth-digest",
        f"{virtuoso['VIRTUOSO_USER']}:{virtuoso['VIRTUOSO_PASSWORD']}",
    )
    assert result.returncode == 0, result.stderr
    return result.stdout + result.stderr


@pytest.fixture(scope="module")
def remote(virtuoso: dict[str, str], pushed: str) -> Iterator[RemoteGraph]:
    with RemoteGraph(virtuoso["VIRTUOSO_SPARQL"]) as graph:
        yield graph


def _value(value: Any) -> Any:
    if isinstance(value, float):
        return ("float", float(f"{value:.12g}"))
    return (type(value).__name__, value)


def _rows(result: QueryResult) -> Counter[tuple[Any, ...]]:
    return Counter(tuple(_value(row[v]) for v in result.variables) for row in result.rows)


def _order_keys(text: str) -> list[str]:
    match = re.search(r"ORDER\s+BY\s+(.+)$", text, re.IGNORECASE | re.DOTALL)
    return re.findall(r"\?(\w+)", match.group(1)) if match else []


def _close(a: Any, b: Any) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-12)
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(_close(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(_close(x, y) for x, y in zip(a, b, strict=True))
    return type(a) is type(b) and a == b


def test_push_reports_every_graph_and_skips_the_meshes(pushed: str, embedded: KnowledgeGraph) -> None:
    assert f"{len(embedded)} triples in {len(embedded.named_graphs())} named graphs sent" in pushed
    assert "graph-store" in pushed
    assert "117 file(s) of the store's files directory (STL meshes) were not sent" in pushed


def test_the_store_holds_every_graph_with_every_triple(remote: RemoteGraph, embedded: KnowledgeGraph) -> None:
    graphs = embedded.named_graphs()
    assert remote.named_graphs() == graphs
    here = {row["g"]: row["n"] for row in embedded.query(COUNTS)}
    there = {row["g"]: row["n"] for row in remote.query(COUNTS) if row["g"] in here}
    assert there == here
    assert len(remote) == len(embedded)


@pytest.mark.parametrize("name", sorted(named_queries()))
def test_named_query_answers_as_embedded(name: str, remote: RemoteGraph, embedded: KnowledgeGraph) -> None:
    query = named_queries()[name]
    fallback = {"integer": "0", "decimal": "0", "iri": "urn:none", "string": "-"}
    params = {
        p.name: SAMPLES[p.name] if p.type == "string" and p.name in SAMPLES else fallback[p.type]
        for p in query.params
    }
    here = embedded.named_query(name, **params)
    there = remote.named_query(name, **params)
    assert there.variables == here.variables
    assert _rows(there) == _rows(here)
    keys = _order_keys(query.text)
    if keys:
        assert [[_value(r[k]) for k in keys] for r in there.rows] == [
            [_value(r[k]) for k in keys] for r in here.rows
        ]
    if name in IEMA_QUERIES:
        assert len(here) > 0


def test_known_answers_come_from_the_store(remote: RemoteGraph) -> None:
    ends = remote.named_query("wire-endpoints", wireNumber="1500.51").rows
    assert [(r["end"], r["component"], r["pinName"]) for r in ends] == [
        ("origin", "F1500.1", "14"),
        ("destination", "Q1500.1", "A1"),
    ]
    first = remote.named_query("wires-of-component", label="F1500.1").rows[0]
    assert (first["sequence"], first["wireNumber"], first["otherEnd"]) == (1, "1500.51", "Q1500.1:A1")
    assert remote.ask("ASK { ?w ck:wireNumber ?n }", n="1500.51")
    assert not remote.ask("ASK { ?w ck:wireNumber ?n }", n='1500.51" } ASK { ?s ?p ?o')


def test_every_iema_service_answers_as_embedded(remote: RemoteGraph, embedded: KnowledgeGraph) -> None:
    here = Session(embedded.cell_model(), kg=embedded)
    there = Session(remote.cell_model(), kg=remote)
    pose = "0.01,0,0,0,0,0,1"
    args = {"detected_pose": pose, "cad_pose": pose, "occupancy": "false", "data": "1500.51"}
    answered = 0
    for service in services_for("iema"):
        params = {k: args.get(k, SERVICE_LABELS.get(service.name, "F1500.1")) for k in service.params}
        # Cursor services move on with each call: three calls walk the same way on both.
        for _ in range(3 if not service.params else 1):
            a = to_jsonable(call(here, service.name, params))
            b = to_jsonable(call(there, service.name, params))
            assert _close(b, a), service.name
            answered += bool(a.get("success", True))
    assert answered >= 10


def test_cli_query_and_call_take_the_url(virtuoso: dict[str, str], remote: RemoteGraph, local: Path) -> None:
    url = virtuoso["VIRTUOSO_SPARQL"]
    there = run("query", url, "wires-of-component", "label=F1500.1", "--format", "rows-json")
    here = run("query", local, "wires-of-component", "label=F1500.1", "--format", "rows-json")
    assert there.returncode == 0, there.stderr
    assert json.loads(there.stdout) == json.loads(here.stdout)
    assert len(json.loads(there.stdout)["rows"]) == 8
    there = run("call", url, "cad_service", "label=F1500.1")
    here = run("call", local, "cad_service", "label=F1500.1")
    assert there.returncode == 0, there.stderr
    data = json.loads(there.stdout)
    assert data["success"] is True and [p["pin"] for p in data["pins"]]
    assert _close(data, json.loads(here.stdout))


def test_export_reads_the_graphs_back(remote: RemoteGraph, embedded: KnowledgeGraph) -> None:
    import pyoxigraph as ox

    there = list(ox.parse(remote.serialize("nq"), format=ox.RdfFormat.N_QUADS))
    here = list(ox.parse(embedded.serialize("nq"), format=ox.RdfFormat.N_QUADS))
    assert len(there) == len(here)
    iris = {str(q) for q in here if isinstance(q.object, ox.NamedNode)}
    assert iris == {str(q) for q in there if isinstance(q.object, ox.NamedNode)}
    # Some graphs only: what cadkg validate reads (every graph but the derived one).
    wanted = [g for g in embedded.named_graphs() if g.endswith("ids.wri")]
    there = list(ox.parse(remote.serialize("nq", graphs=wanted), format=ox.RdfFormat.N_QUADS))
    assert {q.graph_name.value for q in there} == set(wanted)
    assert len(there) == len(list(embedded.graph_quads(wanted[0])))


def test_validate_finds_what_it_finds_on_the_embedded_store(
    remote: RemoteGraph, embedded: KnowledgeGraph
) -> None:
    from cadkg.query.validate import validate

    # The shapes run on a copy of the remote graphs (their compiled queries are pyoxigraph's).
    assert validate(remote) == validate(embedded)


def test_update_push_in_batches_keeps_blank_nodes(
    virtuoso: dict[str, str], auth: Auth, remote: RemoteGraph, embedded: KnowledgeGraph
) -> None:
    ontology = "https://w3id.org/cadkg"
    wires = next(g for g in embedded.named_graphs() if g.endswith("lista-cablaggio.csv"))
    report = push(
        embedded,
        virtuoso["VIRTUOSO_SPARQL_AUTH"],
        auth=auth,
        method="update",
        batch=700,
        graphs=[ontology, wires],
    )
    assert report.method == "update"
    sent = {g.graph: g for g in report.graphs}
    assert sent[wires].requests == math.ceil(sent[wires].triples / 700) > 1
    blank = f"""SELECT (COUNT(*) AS ?n) WHERE {{ GRAPH <{ontology}> {{ ?s ?p ?o
                  FILTER(isBlank(?s) || isBlank(?o)) }} }}"""
    assert remote.query(blank).rows == embedded.query(blank).rows
    # The blank nodes still link up: each list node of the ontology still has its rdf:first.
    linked = f"SELECT (COUNT(*) AS ?n) WHERE {{ GRAPH <{ontology}> {{ ?l rdf:rest ?r . ?r rdf:first ?x }} }}"
    assert remote.query(linked).rows == embedded.query(linked).rows
    here = {row["g"]: row["n"] for row in embedded.query(COUNTS)}
    assert {row["g"]: row["n"] for row in remote.query(COUNTS) if row["g"] in (ontology, wires)} == {
        ontology: here[ontology],
        wires: here[wires],
    }


def test_a_store_without_graph_store_protocol_gets_updates(
    virtuoso: dict[str, str], auth: Auth, embedded: KnowledgeGraph, remote: RemoteGraph
) -> None:
    manifest = next(g for g in embedded.named_graphs() if g.endswith("manifest.toml"))
    missing = virtuoso["VIRTUOSO_GRAPH_STORE"] + "-nowhere"
    report = push(
        embedded, virtuoso["VIRTUOSO_SPARQL_AUTH"], graph_store=missing, auth=auth, graphs=[manifest]
    )
    assert report.method == "update"
    # Virtuoso answers 501 for a method on a path it does not serve.
    assert any(re.search(r"no Graph Store Protocol.*HTTP (404|405|501)", note) for note in report.notes)
    count = f"SELECT (COUNT(*) AS ?n) WHERE {{ GRAPH <{manifest}> {{ ?s ?p ?o }} }}"
    assert remote.query(count).rows == embedded.query(count).rows


def test_errors_name_the_url_and_the_store_s_answer(
    virtuoso: dict[str, str], auth: Auth, embedded: KnowledgeGraph, remote: RemoteGraph
) -> None:
    manifest = next(g for g in embedded.named_graphs() if g.endswith("manifest.toml"))
    sparql = virtuoso["VIRTUOSO_SPARQL"]
    # The anonymous endpoint is read-only.
    with pytest.raises(StoreError, match=re.escape(sparql) + r".*HTTP 500.*(permission|SECURITY)"):
        push(embedded, sparql, method="update", graphs=[manifest])
    wrong = Auth(auth.user, "wrong", digest=True)
    with pytest.raises(StoreError, match=r"HTTP 401.*refused the credentials of 'cadkg'"):
        push(embedded, graph_store=virtuoso["VIRTUOSO_GRAPH_STORE"], auth=wrong, graphs=[manifest])
    with pytest.raises(QueryError, match=re.escape(sparql) + r": HTTP 400.*syntax error"):
        remote.query("SELECT ?x WHERE { ?x ?y }")
    with (
        RemoteGraph("http://127.0.0.1:9/sparql", timeout=5) as nowhere,
        pytest.raises(StoreError, match=r"127\.0\.0\.1:9/sparql: cannot reach the store"),
    ):
        nowhere.query("SELECT * WHERE { ?s ?p ?o } LIMIT 1")
    failed = run("query", sparql, "SELECT ?x WHERE { ?x ?y }")
    assert failed.returncode == 2
    assert failed.stderr.startswith(f"cadkg: error: {sparql}: HTTP 400")
    assert "Traceback" not in failed.stderr and len(failed.stderr.strip().splitlines()) == 1


def test_serve_answers_from_the_store(virtuoso: dict[str, str], remote: RemoteGraph) -> None:
    import socket
    import sys
    import time

    import httpx

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    server = subprocess.Popen(
        [sys.executable, "-m", "cadkg.cli", "serve", virtuoso["VIRTUOSO_SPARQL"], "--port", str(port)],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    base = f"http://127.0.0.1:{port}"
    query = "SELECT ?n WHERE { ?w a ck:Wire ; ck:wireNumber ?n } ORDER BY ?n LIMIT 3"
    try:
        deadline = time.monotonic() + 60
        while True:
            try:
                answer = httpx.post(
                    f"{base}/sparql",
                    data={"query": query},
                    headers={"Accept": "application/sparql-results+json"},
                    timeout=30,
                )
                break
            except httpx.TransportError:
                assert server.poll() is None, server.stderr.read() if server.stderr else ""
                assert time.monotonic() < deadline, "cadkg serve did not answer within 60 s"
                time.sleep(0.5)
        assert answer.status_code == 200, answer.text
        served = [b["n"]["value"] for b in answer.json()["results"]["bindings"]]
        assert served == [row["n"] for row in remote.query(query)]
        service = httpx.get(f"{base}/api/cad_service", params={"label": "F1500.1"}, timeout=60)
        assert service.status_code == 200 and service.json()["success"] is True
    finally:
        server.terminate()
        server.wait(timeout=30)


def test_the_page_draws_the_cell_from_the_store(
    virtuoso: dict[str, str], remote: RemoteGraph, browser: Any
) -> None:
    # The workbench against the remote store, in a browser: the same cell, picked and queried as
    # on the embedded store; the items are boxes, since the mesh files stay with the build.
    from tests.server.browser import health, set_editor, text_of, wait
    from tests.server.cell_view import click_on, open_cell, picked
    from tests.server.serving import cadkg_serve

    with cadkg_serve(virtuoso["VIRTUOSO_SPARQL"]) as base:
        open_cell(browser, base)
        status = text_of(browser, "cell-status")
        assert "117 objects" in status and "110 wires" in status, status
        click_on(browser, "F1500.1")
        component = "https://example.org/cell/iema-qe01/component/F1500.1"
        wait(browser, lambda d: picked(d) == component, 60, "F1500.1 picked")
        script = "return document.getElementById('cell-status').dataset.pins"
        wait(browser, lambda d: d.execute_script(script) == "10", 60, "its 10 pins")
        wait(browser, lambda d: "ck:hasPin" in text_of(d, "pick-facts"), 60, "its facts")
        set_editor(browser, "SELECT ?n WHERE { ?w a ck:Wire ; ck:wireNumber ?n }")
        browser.find_element("id", "run").click()
        wait(browser, lambda d: "110 row(s)" in text_of(d, "status"), 60, "the wires")
        assert health(browser, base) == []
