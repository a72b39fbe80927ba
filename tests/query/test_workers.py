"""Queries in worker processes: stopped at their time limit (the process killed, its core idle),
answered as in process otherwise, under the graph's outbound policy."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

import cadkg
from cadkg.errors import QueryError, TimeLimitError
from cadkg.query.workers import WorkerPool, query_within
from tests.conftest import IEMA
from tests.server.listener import Listener

CUBE = "SELECT (COUNT(*) AS ?n) WHERE { ?a ?b ?c . ?d ?e ?f . ?g ?h ?i }"
WIRES = "SELECT (COUNT(DISTINCT ?w) AS ?n) WHERE { ?w a ck:Wire }"


def _alive(pid: int) -> bool:
    try:
        state = (Path("/proc") / str(pid) / "stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def test_a_runaway_query_is_stopped_and_its_process_killed(iema: cadkg.KnowledgeGraph) -> None:
    with WorkerPool(iema, 1) as workers:
        workers.prestart()
        first = workers._idle[0].process.pid  # the worker the runaway will run in
        started = time.monotonic()
        with pytest.raises(TimeLimitError, match="time limit of 1 s and was stopped"):
            workers.query(CUBE, 1)
        assert time.monotonic() - started < 30
        assert not _alive(first)
        assert workers.killed == 1
        # The next query gets a fresh worker and the same answer as in process.
        assert workers.query(WIRES, 60).rows == iema.query(WIRES).rows
        assert workers.started == 2


def test_answers_and_errors_are_those_of_the_graph(iema: cadkg.KnowledgeGraph) -> None:
    query = "SELECT ?n WHERE { ?w ck:wireNumber ?n } ORDER BY ?n LIMIT 3"
    assert query_within(iema, query, 60) == iema.query(query)
    bound = "SELECT ?w WHERE { ?w ck:wireNumber ?n }"
    assert query_within(iema, bound, 60, n="1500.51") == iema.query(bound, n="1500.51")
    with pytest.raises(QueryError, match="SPARQL syntax error at line 1"):
        query_within(iema, "SELECT * WHERE { ?s ?p }", 60)


def test_a_store_directory_is_snapshot_beside_its_generations(tmp_path: Path) -> None:
    store = tmp_path / "store"
    cadkg.KnowledgeGraph.build(IEMA, store).close()
    kg = cadkg.open_store(store)
    try:
        with WorkerPool(kg, 1) as workers:
            snapshot = workers.snapshot.path
            assert snapshot.parent == store and snapshot.name.startswith(".snapshot-")
            assert workers.query(WIRES, 60).rows == kg.query(WIRES).rows
        assert not snapshot.exists()
        assert sorted(p.name for p in store.iterdir()) == ["CURRENT", (store / "CURRENT").read_text().strip()]
    finally:
        kg.close()


def test_workers_keep_the_outbound_policy(iema: cadkg.KnowledgeGraph) -> None:
    with Listener() as listener:
        query = f"SELECT ?s WHERE {{ SERVICE <{listener.url}> {{ ?s ?p ?o }} }}"
        with pytest.raises(QueryError, match="is refused"):
            query_within(iema, query, 60)
        assert listener.connections == 0
        with WorkerPool(iema, 1, allowed_services=[listener.url]) as workers:
            assert workers.query(query, 60).rows == ({"s": "urn:remote:1"},)
        assert listener.connections == 1
