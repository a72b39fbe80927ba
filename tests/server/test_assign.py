"""``POST /api/assign``: robot/human decisions edited over HTTP with the token, kept in the store
as ``cadkg assign`` keeps them, and seen by the cursor services from their next call on."""

from __future__ import annotations

import time
from pathlib import Path

import httpx

from cadkg.generations import read_pointer
from cadkg.graph import KnowledgeGraph
from cadkg.server import Settings, create_app
from tests.conftest import IEMA
from tests.server.serving import serving_app

TOKEN = "t0ken"
AUTH = {"Authorization": f"Bearer {TOKEN}"}


def test_assign_needs_post_and_the_token_and_is_kept_in_the_store(tmp_path: Path) -> None:
    store = tmp_path / "store"
    KnowledgeGraph.build(IEMA, store).close()

    def load() -> KnowledgeGraph:
        return KnowledgeGraph.open(store, read_only=False)

    settings = Settings(allow_update=True, token=TOKEN, watch_seconds=0)
    with serving_app(create_app(load, settings)) as base:
        first = httpx.post(f"{base}/api/group_connection_provider", data={"client": "a"}, headers=AUTH).json()
        assert first["end"] is False
        wire = first["wire"]
        # Never by GET, never without the token, never with half a request.
        assert httpx.get(f"{base}/api/assign", params={"kind": "wire", "id": wire}).status_code == 405
        form = {"kind": "wire", "id": wire, "performer": "human"}
        assert httpx.post(f"{base}/api/assign", data=form).status_code == 401
        assert httpx.post(f"{base}/api/assign", data={"kind": "wire"}, headers=AUTH).status_code == 400
        unknown = httpx.post(f"{base}/api/assign", data={**form, "id": "NO-SUCH-WIRE"}, headers=AUTH)
        assert unknown.status_code == 404 and "NO-SUCH-WIRE" in unknown.text
        # A change of a store directory writes a new generation: seconds on a busy machine.
        done = httpx.post(f"{base}/api/assign", data=form, headers=AUTH, timeout=120)
        assert done.status_code == 200, done.text
        assert done.json()["target"].endswith(f"wire/{wire}")
        # Client a goes on where it was; a new client never gets the person's wire.
        walked = []
        while not (
            step := httpx.post(
                f"{base}/api/group_connection_provider", data={"client": "b"}, headers=AUTH
            ).json()
        )["end"]:
            walked.append(step["wire"])
        assert walked and wire not in walked
    with KnowledgeGraph.open(store) as kg:
        rows = kg.query(
            "SELECT ?who WHERE { ?a ck:assignmentOf ?w ; ck:assignedTo ?who . ?w ck:wireNumber ?n }", n=wire
        )
        assert [str(r["who"]).rsplit("#", 1)[-1] for r in rows] == ["human"]


def test_assign_on_a_read_only_endpoint_is_refused(tmp_path: Path) -> None:
    app = create_app(lambda: KnowledgeGraph.build(IEMA), Settings(token=TOKEN, watch_seconds=0))
    with serving_app(app) as base:
        refused = httpx.post(
            f"{base}/api/assign", data={"kind": "wire", "id": "1500.51", "performer": "human"}, headers=AUTH
        )
        assert refused.status_code == 403 and "read-only" in refused.json()["error"]


def test_an_assign_over_http_moves_the_served_store_to_its_new_generation(tmp_path: Path) -> None:
    """A change of a store directory is a new generation: the endpoint serves it from then on,
    and its watch (which reloads when another process rebuilds the store) does not reload."""
    store = tmp_path / "store"
    KnowledgeGraph.build(IEMA, store).close()
    first = read_pointer(store)

    def load() -> KnowledgeGraph:
        return KnowledgeGraph.open(store, read_only=False)

    settings = Settings(allow_update=True, token=TOKEN, watch_seconds=0.2)
    with serving_app(create_app(load, settings)) as base:
        form = {"kind": "wire", "id": "1500.51", "performer": "human"}
        done = httpx.post(f"{base}/api/assign", data=form, headers=AUTH, timeout=120)
        assert done.status_code == 200, done.text
        assert read_pointer(store) != first
        assert done.headers["x-cadkg-generation"] == read_pointer(store)
        time.sleep(1.5)  # several watch periods
        info = httpx.get(f"{base}/api/info").json()
        assert (info["reloads"], info["generation"]) == (0, read_pointer(store))
        query = "ASK { ?a ck:assignmentOf ?w ; ck:assignedTo ck:human . ?w ck:wireNumber '1500.51' }"
        asked = httpx.get(f"{base}/sparql", params={"query": query}, headers={"Accept": "application/json"})
        assert asked.json()["boolean"] is True
    # Kept: the new generation and the one it replaced ('cadkg diff STORE' compares them).
    kept = {read_pointer(store), first}
    assert {p.name for p in store.iterdir() if p.name.startswith("gen-")} == kept
