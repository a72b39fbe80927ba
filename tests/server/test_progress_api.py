"""``POST /api/progress``: the cell's reports over HTTP, with the token, kept in the store as
``cadkg progress`` keeps them; ``GET /api/plan`` gives each step's status; every refused input
a 4xx JSON error that changes nothing. The change feed publishes each report."""

from __future__ import annotations

from pathlib import Path

import httpx

import cadkg
from cadkg.changes.feed import ChangeFeed
from cadkg.generations import read_pointer
from cadkg.graph import KnowledgeGraph
from cadkg.plan.cell import store_plan
from cadkg.plan.progress import read_progress
from cadkg.server import Settings, create_app
from cadkg.services.session import Session
from cadkg.services.table import call
from tests.changes.cells import MINI
from tests.server.serving import serving_app

TOKEN = "t0ken"
AUTH = {"Authorization": f"Bearer {TOKEN}"}


def test_progress_needs_post_and_the_token_and_is_kept_in_the_store(tmp_path: Path) -> None:
    store = tmp_path / "store"
    with KnowledgeGraph.build(MINI / "manifest.toml", store) as kg:
        store_plan(kg)
    settings = Settings(allow_update=True, token=TOKEN, watch_seconds=0)
    app = create_app(lambda: KnowledgeGraph.open(store, read_only=False), settings)
    with serving_app(app) as base:
        form = {"task": "W1", "state": "done"}
        generation = read_pointer(store)
        refused = [
            httpx.get(f"{base}/api/progress", params=form),
            httpx.post(f"{base}/api/progress", data=form),
            httpx.post(f"{base}/api/progress", data=form, headers={"Authorization": "Bearer nope"}),
            httpx.post(f"{base}/api/progress", data={"task": "W1"}, headers=AUTH),
            httpx.post(f"{base}/api/progress", data={**form, "task": "NO-SUCH"}, headers=AUTH),
            httpx.post(f"{base}/api/progress", data={**form, "state": "finished"}, headers=AUTH),
            httpx.post(f"{base}/api/progress", data={**form, "colour": "red"}, headers=AUTH),
        ]
        assert [r.status_code for r in refused] == [405, 401, 401, 400, 404, 400, 400]
        assert "no task 'NO-SUCH'" in refused[4].json()["error"]
        assert "unknown state 'finished'" in refused[5].json()["error"]
        assert read_pointer(store) == generation  # nothing changed
        # A change of a store directory writes a new generation: seconds on a busy machine.
        done = httpx.post(f"{base}/api/progress", data=form, headers=AUTH, timeout=120)
        assert done.status_code == 200, done.text
        assert done.json()["status"] == "done" and done.json()["target"].endswith("wire/W1")
        failed = httpx.post(
            f"{base}/api/progress",
            json={"task": "W2", "state": "failed", "reason": "would not seat", "client": "arm"},
            headers=AUTH,
            timeout=120,
        )
        assert failed.status_code == 200 and failed.json()["replanned"] is True, failed.text
        plan = httpx.get(f"{base}/api/plan").json()
        assert plan["summary"]["status"] == {"pending": 2, "started": 0, "done": 1, "failed": 1}
        steps = {s["key"]: s for s in plan["steps"]}
        assert (steps["W1"]["status"], steps["W1"]["step"]) == ("done", 0)
        assert steps["W2"]["performer"] == "human" and "would not seat" in steps["W2"]["reason"]
        # The providers hand out neither.
        walked = []
        while not (
            step := httpx.post(
                f"{base}/api/group_connection_provider", data={"client": "b"}, headers=AUTH
            ).json()
        )["end"]:
            walked.append(step["wire"])
        assert "W1" not in walked and "W2" not in walked
    assert read_pointer(store) != generation
    with KnowledgeGraph.open(store) as kg:
        assert sorted((r.label, r.state, r.by) for r in read_progress(kg).values()) == [
            ("W1", "done", "http:"),
            ("W2", "failed", "http:arm"),
        ]


def test_progress_on_a_read_only_endpoint_is_refused() -> None:
    app = create_app(lambda: cadkg.build(MINI / "manifest.toml"), Settings(token=TOKEN, watch_seconds=0))
    with serving_app(app) as base:
        refused = httpx.post(f"{base}/api/progress", data={"task": "W1", "state": "done"}, headers=AUTH)
        assert refused.status_code == 403 and "read-only" in refused.json()["error"]


def test_the_change_feed_publishes_a_report() -> None:
    kg = cadkg.build(MINI / "manifest.toml")
    feed = ChangeFeed()
    assert feed.observe(kg, "before") is None
    call(Session(kg.cell_model(), kg=kg), "progress", {"task": "W1", "state": "started"}, client="arm")
    changes = feed.observe(kg, "after")
    assert changes is not None
    added = [c.to_json() for c in changes if c.kind == "progress"]
    assert [(c["id"], c["iri"]) for c in added] == [("W1", "https://example.org/cell/mini/progress/W1")]
    call(Session(kg.cell_model(), kg=kg), "progress", {"task": "W1", "state": "done"}, client="arm")
    changes = feed.observe(kg, "later")
    assert changes is not None
    (changed,) = [c.to_json() for c in changes if c.kind == "progress"]
    assert changed["id"] == "W1" and changed["attributes"]["state"] == ["started", "done"]
