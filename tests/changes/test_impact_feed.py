"""The change feed's impact: the work the cursors had passed before a change, on real graphs
and over a served store's ``/api/changes``."""

from __future__ import annotations

import json
import queue
import threading
from pathlib import Path
from typing import Any

import httpx
import pytest

import cadkg
from cadkg.changes.feed import ChangeFeed
from cadkg.graph import KnowledgeGraph
from cadkg.plan.cell import store_plan
from cadkg.server import Settings, create_app
from cadkg.services.session import Session
from cadkg.services.table import call
from tests.changes.cells import MINI, copy_cell, edit
from tests.changes.test_feed_http import _listen, _next
from tests.conftest import EXAMPLES
from tests.server.serving import serving_app

AUTH = {"Authorization": "Bearer t0ken"}


def test_operations_passed_then_removed_or_changed_are_dropped_or_to_redo(tmp_path: Path) -> None:
    folder = EXAMPLES / "elvez-cell"
    old = cadkg.build(folder / "manifest.toml")
    session = Session(old.cell_model(), kg=old)
    handed = [call(session, "CAD_platform.next_operation", {}, client="left") for _ in range(3)]
    done = session.done()
    assert [w.kind for w in done["elvez cursor of left"]] == ["operation"] * 3
    manifest = copy_cell(folder, tmp_path / "elvez")
    sequence = manifest.parent / "Assembly_sequence.csv"
    header, _, second, third, *rest = sequence.read_text(encoding="utf-8").splitlines(keepends=True)
    # The first operation is gone; the third now works at another spot.
    code = third.split(";")
    moved = ";".join([*code[:3], code[3].replace("J2.1-", "")])
    sequence.write_text("".join([header, second, moved, *rest]), encoding="utf-8")
    feed = ChangeFeed()
    assert feed.observe(old, "old") is None
    changes = feed.observe(cadkg.build(manifest), "new", done, ["elvez cursor of left: on ..."])
    assert changes is not None and changes.impact is not None
    impact = changes.impact.to_json()
    first_id = f"{handed[0].type} {';'.join(handed[0].label)}"
    third_id = f"{handed[2].type} {';'.join(handed[2].label)}"
    assert [(i["id"], i["done"], i["passed_by"]) for i in impact["dropped"]] == [
        (first_id, True, ["elvez cursor of left"])
    ]
    assert [(i["id"], i["passed_by"]) for i in impact["redo"]] == [(third_id, ["elvez cursor of left"])]
    assert "spots" in impact["redo"][0]["attributes"]
    assert impact["plan"] is False and impact["cursors"] == ["elvez cursor of left: on ..."]


@pytest.mark.slow  # a served store rebuilt under a live SSE client
def test_the_sse_feed_says_a_landed_wire_must_be_redone_after_a_rebuild(tmp_path: Path) -> None:
    store = tmp_path / "store"
    with KnowledgeGraph.build(MINI / "manifest.toml", store) as kg:
        plan = store_plan(kg, None)
    robot = [s.key for s in plan.steps if s.performer == "robot"]
    settings = Settings(token="t0ken", watch_seconds=0)
    heard: queue.Queue[Any] = queue.Queue()
    connected = threading.Event()
    with serving_app(create_app(lambda: KnowledgeGraph.open(store), settings)) as base:
        listener = threading.Thread(target=_listen, args=(base, heard, connected), daemon=True)
        listener.start()
        assert connected.wait(60)
        assert _next(heard)[0] == "status"
        landed = httpx.post(f"{base}/api/group_connection_provider", data={"client": "a"}, headers=AUTH)
        assert landed.json()["wire"] == robot[0]
        manifest = copy_cell(MINI, tmp_path / "new")
        edit(
            manifest.parent / "connections.tsv", f"\t{robot[0]}\t0,75 mm²\tBU", f"\t{robot[0]}\t0,75 mm²\tRD"
        )
        KnowledgeGraph.build(manifest, store).close()
        assert httpx.post(f"{base}/reload", headers=AUTH).status_code == 200
        event, data = _next(heard)
    assert event == "changes"
    impact = data["impact"]
    assert impact["plan"] is True
    assert [(i["id"], i["task"], i["attributes"], i["passed_by"]) for i in impact["redo"]] == [
        (robot[0], robot[0], ["colour"], ["iema cursor of http:a"])
    ]
    assert impact["new"] == impact["dropped"] == impact["changed"] == []
    json.dumps(data)  # as sent
