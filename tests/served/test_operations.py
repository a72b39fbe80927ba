"""The operations every cell offers, from the one table: the same answers through ``cadkg call``
and through the services' ``call``, whatever the use case."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import cadkg
from cadkg.errors import NotFound, QueryError, StoreError
from cadkg.served.holder import GraphHolder
from cadkg.services.frames import shown
from cadkg.services.operations import OPERATIONS
from cadkg.services.service import Effect
from cadkg.services.table import SERVICES, call, served_for
from tests.cli import run
from tests.conftest import EXAMPLES, IEMA


def test_every_transport_serves_the_operations_with_the_use_case_services() -> None:
    for profile in ("iema", "elvez", "elimco", "vw", "enki"):
        names = [s.name for s in served_for(profile)]
        assert names[:6] == ["assign", "plan", "progress", "replan", "label_frames", "reload"]
        assert len(names) == len(set(names)) and all(n in SERVICES for n in names)
    assert {n: s.effect for n, s in OPERATIONS.items()} == {
        "assign": Effect.WRITES,
        "plan": Effect.READS,
        "progress": Effect.WRITES,
        "replan": Effect.WRITES,
        "label_frames": Effect.READS,
        "reload": Effect.RELOADS,
    }


def test_assign_by_cadkg_call_writes_a_new_generation_as_cadkg_assign(tmp_path: Path) -> None:
    store = tmp_path / "store"
    cadkg.build(IEMA, store).close()
    before = (store / "CURRENT").read_text()
    done = run("call", store, "assign", "kind=wire", "id=1500.51", "performer=human")
    assert done.returncode == 0, done.stderr
    answer = json.loads(done.stdout)
    assert answer["success"] is True and answer["target"].endswith("wire/1500.51")
    assert answer["message"] == "wire 1500.51 → human (kept in the store)"
    assert (store / "CURRENT").read_text() != before
    with cadkg.KnowledgeGraph.open(store) as kg:
        assert kg.ask("ASK { ?a ck:assignedTo ck:human ; ck:assignmentOf/ck:wireNumber '1500.51' }")
    refused = run("call", store, "assign", "kind=wire", "id=NO-SUCH", "performer=human")
    assert refused.returncode == 2 and "NO-SUCH" in refused.stderr


def test_plan_and_label_frames_answer_from_the_session(tmp_path: Path) -> None:
    store = tmp_path / "store"
    cadkg.build(IEMA, store).close()
    missing = run("call", store, "plan")
    assert missing.returncode == 2 and "holds no plan" in missing.stderr
    assert run("plan", store, "-o", str(tmp_path / "plan.txt")).returncode == 0
    plan = json.loads(run("call", store, "plan").stdout)
    made = json.loads(run("plan", store, "--format", "json").stdout)
    assert {k: plan[k] for k in ("summary", "steps", "precedence")} == made
    frames = json.loads(run("call", store, "label_frames", "label=F1500.1").stdout)
    assert frames["success"] is True and frames["labels"] == ["F1500.1"] * len(frames["frame_ids"])
    assert "F1500.1/target" in frames["frame_ids"]
    nothing = json.loads(run("call", store, "label_frames", "label=NO-SUCH").stdout)
    assert nothing["success"] is False and nothing["frame_ids"] == []


def test_reload_needs_a_served_cell_and_carries_the_cursors(tmp_path: Path) -> None:
    store = tmp_path / "store"
    cadkg.build(IEMA, store).close()
    one_shot = run("call", store, "reload")
    assert one_shot.returncode == 2 and "only a served cell reloads" in one_shot.stderr
    holder = GraphHolder(cadkg.KnowledgeGraph.open(store), lambda: cadkg.KnowledgeGraph.open(store))
    try:
        session = holder.current.session()
        first = call(session, "group_connection_provider", {}, client="arm")
        cadkg.build(IEMA, store).close()
        reloaded = call(session, "reload", {})
        assert reloaded.previous != reloaded.generation == (store / "CURRENT").read_text().strip()
        fresh = holder.current.session()
        assert fresh is not session
        assert any(note.startswith("iema cursor of arm: ") for note in holder.current.cursor_notes)
        second = call(fresh, "group_connection_provider", {}, client="arm")
        assert second.wire != first.wire
    finally:
        holder.close()


def test_a_graph_handed_in_is_not_reloaded_and_a_plan_is_not_found(iema: cadkg.KnowledgeGraph) -> None:
    holder = GraphHolder(iema)
    try:
        with pytest.raises(NotFound, match="holds no plan"):
            call(holder.current.session(), "plan", {})
        with pytest.raises(Exception, match="cannot reopen"):
            call(holder.current.session(), "reload", {})
        with pytest.raises(QueryError, match="missing parameter"):
            call(holder.current.session(), "assign", {"kind": "wire"})
    finally:
        holder.close()


def test_the_operations_serve_every_use_case_the_same_way() -> None:
    elvez = EXAMPLES / "elvez-cell" / "manifest.toml"
    holder = GraphHolder(cadkg.build(elvez), lambda: cadkg.build(elvez))
    try:
        session = holder.current.session()
        # The platform's frames are published (ID0002platform ...), and belong to no label.
        assert any(f.child.endswith("platform") for f in shown(session).frames)
        assert call(session, "label_frames", {}).success
        assert call(holder.current.session(), "reload", {}).success
    finally:
        holder.close()


def test_a_reload_that_fails_keeps_the_old_cell_and_says_so(tmp_path: Path) -> None:
    manifest = tmp_path / "manifest.toml"

    def load() -> cadkg.KnowledgeGraph:
        return cadkg.build(manifest)

    holder = GraphHolder(cadkg.build(IEMA), load)
    try:
        manifest.write_text("[cell\n", encoding="utf-8")
        served = holder.current
        with pytest.raises(StoreError, match=r"reload failed, still serving the old cell: .*manifest\.toml"):
            call(served.session(), "reload", {})
        assert holder.current is served and holder.reloads == 0
    finally:
        holder.close()
