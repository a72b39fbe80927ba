"""Serving a store directory that is rebuilt meanwhile: no request lost, the new generation served."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import httpx
import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.server import Limits, Settings
from tests.conftest import IEMA
from tests.server.serving import serving

WIRES = "SELECT (COUNT(DISTINCT ?w) AS ?n) WHERE { ?w a ck:Wire }"
SRJ = "application/sparql-results+json"


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    directory = tmp_path_factory.mktemp("reload") / "store"
    KnowledgeGraph.build(IEMA, directory).close()
    return directory


@pytest.mark.slow
def test_rebuild_while_serving_loses_no_request(store: Path) -> None:
    settings = Settings(limits=Limits(timeout=30), cache_bytes=0, watch_seconds=0.1)
    answers: list[tuple[int, str, str]] = []
    failures: list[str] = []
    stop = threading.Event()

    def client(base: str) -> None:
        with httpx.Client(base_url=base, timeout=30) as http:
            while not stop.is_set():
                try:
                    response = http.get("/sparql", params={"query": WIRES}, headers={"Accept": SRJ})
                    count = response.json()["results"]["bindings"][0]["n"]["value"]
                    answers.append((response.status_code, count, response.headers["x-cadkg-generation"]))
                except Exception as err:  # any failure is what this test looks for
                    failures.append(repr(err))

    with serving(lambda: KnowledgeGraph.open(store), settings) as base:
        before = httpx.get(f"{base}/api/info").json()["generation"]
        threads = [threading.Thread(target=client, args=(base,)) for _ in range(3)]
        for thread in threads:
            thread.start()
        time.sleep(0.5)
        # The builds write new generations and switch CURRENT; the second deletes the served
        # one's files (the first keeps it as the previous generation).
        KnowledgeGraph.build(IEMA, store).close()
        KnowledgeGraph.build(IEMA, store).close()
        after = (store / "CURRENT").read_text().strip()
        deadline = time.monotonic() + 20
        while not any(g == after for _, _, g in answers[-5:]) and time.monotonic() < deadline:
            time.sleep(0.1)
        time.sleep(0.3)
        stop.set()
        for thread in threads:
            thread.join(30)
        assert httpx.get(f"{base}/api/info").json()["generation"] == after
    assert failures == []
    assert answers and all(status == 200 and count == "110" for status, count, _ in answers)
    generations = {g for _, _, g in answers}
    assert {before, after} <= generations and len(generations) <= 3
    assert not (store / before).exists()


TOKEN = {"Authorization": "Bearer t0ken"}


def test_post_reload(store: Path) -> None:
    settings = Settings(token="t0ken", watch_seconds=0)
    with serving(lambda: KnowledgeGraph.open(store), settings) as base:
        current = (store / "CURRENT").read_text().strip()
        response = httpx.post(f"{base}/reload", headers=TOKEN)
        assert response.status_code == 200
        assert response.json() == {"previous": current, "generation": current}
        count = httpx.get(f"{base}/sparql", params={"query": WIRES}, headers={"Accept": SRJ})
        assert count.json()["results"]["bindings"][0]["n"]["value"] == "110"


def test_reload_with_a_token_needs_it(store: Path) -> None:
    settings = Settings(token="t0ken", watch_seconds=0)
    with serving(lambda: KnowledgeGraph.open(store), settings) as base:
        assert httpx.post(f"{base}/reload").status_code == 401
        assert httpx.post(f"{base}/reload", headers={"Authorization": "Bearer t0ken"}).status_code == 200
        # A token alone does not make the endpoint writable.
        update = httpx.post(
            f"{base}/sparql", data={"update": "CLEAR ALL"}, headers={"Authorization": "Bearer t0ken"}
        )
        assert update.status_code == 403


def test_a_reload_needs_the_token(store: Path) -> None:
    with serving(lambda: KnowledgeGraph.open(store), Settings(watch_seconds=0)) as base:
        refused = httpx.post(f"{base}/reload")
        assert refused.status_code == 403
        assert refused.json() == {"error": "a reload needs the endpoint's token; start it with --token"}
        assert httpx.get(f"{base}/reload").status_code == 405


def test_a_graph_handed_in_cannot_be_reloaded(iema: KnowledgeGraph) -> None:
    with serving(iema, Settings(token="t0ken", watch_seconds=0)) as base:
        response = httpx.post(f"{base}/reload", headers=TOKEN)
        assert response.status_code == 409
        assert "cannot reopen" in response.json()["error"]


def test_a_reload_warms_the_cache_before_the_swap(store: Path) -> None:
    settings = Settings(token="t0ken", watch_seconds=0)
    query = {"query": "SELECT DISTINCT ?n WHERE { ?w ck:wireNumber ?n } ORDER BY ?n LIMIT 3"}
    with serving(lambda: KnowledgeGraph.open(store), settings) as base:
        first = httpx.get(f"{base}/sparql", params=query, headers={"Accept": SRJ})
        before = httpx.get(f"{base}/api/info").json()
        assert before["cache"]["misses"] == 1 and before["cache"]["hits"] == 0
        KnowledgeGraph.build(IEMA, store).close()
        swapped = httpx.post(f"{base}/reload", headers=TOKEN, timeout=60).json()
        assert swapped["generation"] == (store / "CURRENT").read_text().strip()
        again = httpx.get(f"{base}/sparql", params=query, headers={"Accept": SRJ})
        after = httpx.get(f"{base}/api/info").json()
        # Answered from the cache, computed on the new generation before it was served.
        assert again.headers["x-cadkg-generation"] == swapped["generation"]
        assert after["cache"] == {"entries": 2, "hits": 1, "misses": 1}
        assert again.json() == first.json()
