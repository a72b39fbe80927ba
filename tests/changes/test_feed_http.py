"""``GET /api/changes``: a real SSE client hears each change set of a served store."""

from __future__ import annotations

import json
import queue
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.server import Settings, create_app
from tests.changes.cells import MINI, copy_cell, edit
from tests.server.serving import serving_app

AUTH = {"Authorization": "Bearer t0ken"}


def _events(response: httpx.Response) -> Iterator[tuple[str, str]]:
    """``(event, data)`` of a Server-Sent Events stream, as a browser's EventSource reads it."""
    event, data = "message", []
    for line in response.iter_lines():
        if not line:
            if data:
                yield event, "\n".join(data)
            event, data = "message", []
        elif line.startswith("event:"):
            event = line[6:].strip()
        elif line.startswith("data:"):
            data.append(line[5:].strip())


def _listen(base: str, heard: queue.Queue[Any], connected: threading.Event) -> None:
    with (
        httpx.Client(timeout=httpx.Timeout(10, read=120)) as http,
        http.stream("GET", f"{base}/api/changes") as r,
    ):
        heard.put(("status", r.status_code, r.headers["content-type"]))
        connected.set()
        for event, data in _events(r):
            heard.put((event, json.loads(data)))


def _next(heard: queue.Queue[Any]) -> Any:
    return heard.get(timeout=120)


@pytest.mark.slow  # a served store rebuilt under a live SSE client
def test_an_sse_client_hears_a_rebuild_and_an_assignment(tmp_path: Path) -> None:
    store = tmp_path / "store"
    KnowledgeGraph.build(MINI / "manifest.toml", store).close()
    settings = Settings(token="t0ken", allow_update=True, watch_seconds=0)
    heard: queue.Queue[Any] = queue.Queue()
    connected = threading.Event()
    app = create_app(lambda: KnowledgeGraph.open(store, read_only=False), settings)
    with serving_app(app) as base:
        listener = threading.Thread(target=_listen, args=(base, heard, connected), daemon=True)
        listener.start()
        assert connected.wait(60)
        assert _next(heard) == ("status", 200, "text/event-stream; charset=utf-8")
        manifest = copy_cell(MINI, tmp_path / "new")
        edit(manifest.parent / "connections.tsv", "\tW1\t", "\tW11\t")
        KnowledgeGraph.build(manifest, store).close()
        assert httpx.post(f"{base}/reload", headers=AUTH).status_code == 200
        event, data = _next(heard)
        assert event == "changes"
        assert [(c["kind"], c["id"], c["attributes"]) for c in data["changed"] if c["kind"] == "wire"] == [
            ("wire", "W11", {"number": ["W1", "W11"]})
        ]
        assigned = httpx.post(
            f"{base}/api/assign", data={"kind": "wire", "id": "W2", "performer": "human"}, headers=AUTH
        )
        assert assigned.status_code == 200, assigned.text
        event, data = _next(heard)
        assert event == "changes"
        (wire,) = [c for c in data["changed"] if c["kind"] == "wire"]
        assert (wire["id"], wire["attributes"]["performer"][1]) == ("W2", "human")
        # A client connecting now is sent the latest change set first (latched).
        with httpx.stream("GET", f"{base}/api/changes", timeout=httpx.Timeout(10, read=60)) as late:
            first = next(_events(late))
        assert first[0] == "changes" and json.loads(first[1]) == data
