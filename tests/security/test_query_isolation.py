"""No outbound request where queries from outside run: the query workers (HTTP ``/sparql``,
``query_within``), the child of ``cadkg query`` and the thread of SPARQL updates have no network.

Each test draws generated variants (``outbound_variants.py``) and a loopback listener counts the
connections made to it. Where the recogniser refuses a text first, the tests also run the text
past it (pyoxigraph called directly, in the same confined place): the connection fails there
too, while the same text in the test process does reach the listener, so no test passes
because a variant asks for nothing.
"""

from __future__ import annotations

import asyncio
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import click
import httpx
import pyoxigraph as ox
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import cadkg
from cadkg.cli.limited_query import run_limited_query
from cadkg.errors import QueryError
from cadkg.query.workers import WorkerPool, query_within
from cadkg.server import Limits, Settings, create_app
from cadkg.server.evaluation import pool_maker
from cadkg.server.limits import Deadline, Evaluator
from cadkg.services.table import SERVICES
from tests.cli import run
from tests.conftest import IEMA
from tests.security.outbound_variants import Variant, load_update, service_query
from tests.server.listener import Listener
from tests.server.serving import serving_app

TOKEN = "s3cret"
RAW = "tests.security.test_query_isolation:raw"
# Each example starts processes or requests: no shrinking (a failing variant is printed as drawn).
_SLOW: dict[str, Any] = {
    "deadline": None,
    "database": None,
    "suppress_health_check": list(HealthCheck),
    "phases": [Phase.generate],
}
FEW = settings(max_examples=5, **_SLOW)
SOME = settings(max_examples=30, **_SLOW)


def raw(graph: Any, text: str) -> str:
    """A worker's task: ``text`` evaluated by pyoxigraph itself, past the recogniser; what happened."""
    try:
        list(ox.Store().query(text))
    except (OSError, RuntimeError) as err:
        return f"failed: {err}"
    return "answered"


def _reaching(listener: Listener, variant: Variant) -> str:
    """The variant's text; it does reach the listener when evaluated here, with the network."""
    before = len(listener.requests)
    raw(None, variant.text)
    assert len(listener.requests) > before, f"the variant reaches nothing: {variant.text!r}"
    return variant.text


def _asks(variant: Variant) -> bool:
    """Whether a variant asks for an endpoint (decoys, answered on a real graph, are the
    differential test's: their patterns multiply its triples)."""
    return bool(variant.reaches) or variant.reaches_unknown


def _with_service(base: str) -> st.SearchStrategy[Variant]:
    return service_query(base).filter(lambda v: bool(v.reaches) and not v.reaches_unknown)


@pytest.fixture(scope="module")
def listener() -> Iterator[Listener]:
    with Listener() as listening:
        yield listening


@pytest.fixture(scope="module")
def workers(iema: cadkg.KnowledgeGraph) -> Iterator[WorkerPool]:
    with WorkerPool(iema, 1, preload=("tests.security.test_query_isolation",)) as pool:
        yield pool


@SOME
@given(data=st.data())
def test_a_worker_reaches_no_address_whatever_the_text(
    listener: Listener, workers: WorkerPool, data: st.DataObject
) -> None:
    text = _reaching(listener, data.draw(_with_service(listener.url.removesuffix("sparql"))))
    connections = listener.connections
    outcome = workers.call(RAW, (text,), seconds=60)
    assert listener.connections == connections
    # SERVICE SILENT answers an unreachable endpoint with one empty solution.
    assert "unreachable" in outcome or "SILENT" in text.upper(), outcome


@FEW
@given(data=st.data())
def test_query_within_refuses_and_connects_nowhere(
    listener: Listener, iema: cadkg.KnowledgeGraph, data: st.DataObject
) -> None:
    variant = data.draw(service_query(listener.url.removesuffix("sparql")).filter(_asks))
    connections = listener.connections
    with pytest.raises(QueryError, match="is refused"):
        query_within(iema, variant.text, 60)
    assert listener.connections == connections


def test_the_cli_child_reaches_no_address(listener: Listener) -> None:
    text = f"SELECT * WHERE {{ SERVICE <{listener.url}> {{ ?s ?p ?o }} }}"
    reached: list[str] = []

    def work(ready: Any) -> None:
        ready()
        reached.append(raw(None, text))
        if reached[-1] != "answered":
            raise QueryError(reached[-1])

    connections = listener.connections
    with click.Context(click.Command("query")), pytest.raises(SystemExit) as stopped:
        run_limited_query(work, seconds=60, memory=0, network=False)
    assert stopped.value.code == 2  # the child's one-line error: its connection failed
    assert listener.connections == connections
    # Given the network (an --allow-service), the same child does reach it.
    with click.Context(click.Command("query")):
        run_limited_query(work, seconds=60, memory=0, network=True)
    assert listener.connections == connections + 1


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    target = tmp_path_factory.mktemp("security") / "store"
    cadkg.KnowledgeGraph.build(IEMA, target).close()
    return target


@FEW
@given(data=st.data())
def test_cadkg_query_refuses_and_connects_nowhere(
    listener: Listener, store: Path, data: st.DataObject
) -> None:
    variant = data.draw(_with_service(listener.url.removesuffix("sparql")))
    connections = listener.connections
    result: subprocess.CompletedProcess[str] = run("query", store, variant.text)
    assert result.returncode == 2, result.stderr
    assert result.stderr.startswith("cadkg: error: ") and "is refused" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1, result.stderr
    assert listener.connections == connections


@pytest.fixture(scope="module")
def endpoint(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[str, Any, Settings]]:
    target = tmp_path_factory.mktemp("served") / "store"
    cadkg.KnowledgeGraph.build(IEMA, target).close()
    settings_ = Settings(limits=Limits(workers=1), watch_seconds=0, allow_update=True, token=TOKEN)
    app = create_app(lambda: cadkg.KnowledgeGraph.open(target, read_only=False), settings_)
    with serving_app(app) as base:
        yield base, app, settings_


@SOME
@given(data=st.data())
def test_the_endpoint_refuses_every_variant_and_connects_nowhere(
    listener: Listener, endpoint: tuple[str, Any, Settings], data: st.DataObject
) -> None:
    base, _, _ = endpoint
    query = data.draw(service_query(listener.url.removesuffix("sparql")).filter(_asks))
    update = data.draw(load_update(listener.url.removesuffix("sparql")).filter(_asks))
    connections = listener.connections
    answer = httpx.get(f"{base}/sparql", params={"query": query.text}, timeout=60)
    assert answer.status_code == 400 and "is refused" in answer.text, answer.text
    headers = {"Authorization": f"Bearer {TOKEN}", "Content-Type": "application/sparql-update"}
    written = httpx.post(f"{base}/sparql", content=update.text, headers=headers, timeout=60)
    assert written.status_code == 400 and "is refused" in written.text, written.text
    assert listener.connections == connections


def test_the_endpoints_workers_and_update_thread_have_no_network(
    listener: Listener, endpoint: tuple[str, Any, Settings]
) -> None:
    _, app, settings_ = endpoint
    text = f"SELECT * WHERE {{ SERVICE <{listener.url}> {{ ?s ?p ?o }} }}"
    connections = listener.connections
    served = app.app.state.endpoint.holder.acquire()
    try:
        outcome = served.workers(pool_maker(settings_)).call(RAW, (text,), seconds=60)
    finally:
        served.release()
    assert outcome.startswith("failed:"), outcome
    load = f"LOAD <{listener.url}>"

    def job(_: Deadline) -> str:
        try:
            ox.Store().update(load)
        except (OSError, RuntimeError) as err:
            return f"failed: {err}"
        return "loaded"

    writer: Evaluator = app.app.state.endpoint.writer
    assert asyncio.run(writer.run(job, Deadline(60))).startswith("failed:")
    assert listener.connections == connections
    # The same evaluator without leaving the network does connect: the thread, not the text, is why.
    free = Evaluator(1)
    try:
        asyncio.run(free.run(job, Deadline(60)))
    finally:
        free.shutdown()
    assert listener.connections == connections + 1


def test_head_runs_nothing(endpoint: tuple[str, Any, Settings]) -> None:
    base, _, _ = endpoint
    changing = ["load_files", "CAD_platform.next_operation", "reset_rail_scanner", "rail_scanner"]
    assert set(changing) <= set(SERVICES)
    auth = {"Authorization": f"Bearer {TOKEN}"}
    marker = "<urn:head:s> <urn:head:p> <urn:head:o>"
    ask = f"ASK {{ {marker} }}"
    insert = f"INSERT DATA {{ GRAPH <urn:head:g> {{ {marker} }} }}"
    heads = [
        httpx.head(f"{base}/sparql", params={"update": insert}, headers=auth, timeout=60),
        httpx.head(f"{base}/reload", headers=auth, timeout=60),
        *(
            httpx.head(f"{base}/api/{name}", params={"client": "h"}, headers=auth, timeout=60)
            for name in changing
        ),
    ]
    assert all(h.status_code >= 400 for h in heads), [(h.url, h.status_code) for h in heads]
    found = httpx.get(f"{base}/sparql", params={"query": ask, "format": "json"}, timeout=60)
    assert found.json()["boolean"] is False
    # The same update by POST with the token does run: the HEAD, not the text, was refused.
    done = httpx.post(f"{base}/sparql", data={"update": insert}, headers=auth, timeout=60)
    assert done.status_code == 200, done.text
    found = httpx.get(f"{base}/sparql", params={"query": ask, "format": "json"}, timeout=60)
    assert found.json()["boolean"] is True
