"""Cursors survive a rebuild: on the same wire or operation, found by identity, not by index."""

from __future__ import annotations

from pathlib import Path

import httpx

import cadkg
from cadkg.graph import KnowledgeGraph
from cadkg.server import Settings, create_app
from cadkg.services.session import Session
from cadkg.services.table import call
from tests.changes.cells import MINI, copy_cell, edit
from tests.conftest import EXAMPLES
from tests.server.serving import serving_app

AUTH = {"Authorization": "Bearer t0ken"}
NEW_FIRST = (
    "1\tQ\t=-K2:A1\t1\tQ\t=-X1:2:a\tW0\t0,75 mm²\tBU\t+\t24V\t0,2 m\t\tPUNTALINO_vite\tPUNTALINO_vite\n"
)


def _session(kg: cadkg.KnowledgeGraph) -> Session:
    return Session(kg.cell_model(), kg=kg)


def _robot_wires(kg: cadkg.KnowledgeGraph) -> list[str]:
    return [s.wire for s in kg.cell_model().steps if s.performer == "robot"]


def _edited_mini(folder: Path, *edits: tuple[str, str]) -> cadkg.KnowledgeGraph:
    manifest = copy_cell(MINI, folder)
    for old, new in edits:
        edit(manifest.parent / "connections.tsv", old, new)
    return cadkg.build(manifest)


def test_a_wire_cursor_follows_its_wire_renumbered_with_a_wire_before_it(tmp_path: Path) -> None:
    old = cadkg.build(MINI / "manifest.toml")
    wires = _robot_wires(old)
    assert len(wires) >= 2
    session = _session(old)
    assert call(session, "group_connection_provider", {}, client="arm").wire == wires[0]
    next_wire = wires[1]
    header_end = "Terminazione Destinazione\n"
    new = _edited_mini(
        tmp_path / "new", (f"\t{next_wire}\t", f"\t{next_wire}X\t"), (header_end, header_end + NEW_FIRST)
    )
    assert _robot_wires(new).index(f"{next_wire}X") != wires.index(next_wire)  # its index moved
    fresh = _session(new)
    (note,) = fresh.carry_over(session)
    assert note == f"iema cursor of arm: on wire {next_wire}X (was {next_wire})"
    assert call(fresh, "group_connection_provider", {}, client="arm").wire == f"{next_wire}X"
    # A client that never moved starts at the start, the new first wire.
    assert call(fresh, "group_connection_provider", {}, client="other").wire == "W0"


def test_a_cursor_on_a_removed_wire_goes_to_the_next_one_still_there(tmp_path: Path) -> None:
    old = cadkg.build(MINI / "manifest.toml")
    wires = _robot_wires(old)
    session = _session(old)
    call(session, "group_connection_provider", {}, client="arm")
    text = (MINI / "connections.tsv").read_text(encoding="utf-8")
    (line,) = [line for line in text.splitlines(keepends=True) if f"\t{wires[1]}\t" in line]
    fresh = _session(_edited_mini(tmp_path / "new", (line, "")))
    (note,) = fresh.carry_over(session)
    assert f"wire {wires[1]} is gone" in note
    after = wires[2] if len(wires) > 2 else None
    answer = call(fresh, "group_connection_provider", {}, client="arm")
    assert (answer.wire if not answer.end else None) == after


def test_an_operation_cursor_follows_its_operation(tmp_path: Path) -> None:
    folder = EXAMPLES / "elvez-cell"
    old = cadkg.build(folder / "manifest.toml")
    session = _session(old)
    for _ in range(3):
        call(session, "CAD_platform.next_operation", {}, client="left")
    manifest = copy_cell(folder, tmp_path / "elvez")
    sequence = manifest.parent / "Assembly_sequence.csv"
    lines = sequence.read_text(encoding="utf-8").splitlines(keepends=True)
    header, first, second, third, *rest = lines
    # The first two operations swap places, the third moves to other spots.
    code = third.split(";")
    moved = ";".join([*code[:3], code[3].replace("J3.2", "J3.1")])
    sequence.write_text("".join([header, second, first, moved, *rest]), encoding="utf-8")
    fresh = _session(cadkg.build(manifest))
    (note,) = fresh.carry_over(session)
    assert note.startswith("elvez cursor of left: on operation")
    answer = call(fresh, "CAD_platform.next_operation", {}, client="left")
    expected = call(_session(old), "CAD_platform.index_operation", {"index": 3}, client="x")
    assert (answer.type, answer.label) == (expected.type, expected.label)


def test_a_served_store_keeps_the_cursor_across_a_rebuild_and_reload(tmp_path: Path) -> None:
    store = tmp_path / "store"
    KnowledgeGraph.build(MINI / "manifest.toml", store).close()
    wires = _robot_wires(cadkg.build(MINI / "manifest.toml"))
    settings = Settings(token="t0ken", watch_seconds=0)
    with serving_app(create_app(lambda: KnowledgeGraph.open(store), settings)) as base:
        first = httpx.post(f"{base}/api/group_connection_provider", data={"client": "a"}, headers=AUTH).json()
        assert first["wire"] == wires[0]
        header_end = "Terminazione Destinazione\n"
        manifest = copy_cell(MINI, tmp_path / "new")
        edit(manifest.parent / "connections.tsv", header_end, header_end + NEW_FIRST)
        KnowledgeGraph.build(manifest, store).close()
        assert httpx.post(f"{base}/reload", headers=AUTH).status_code == 200
        second = httpx.post(
            f"{base}/api/group_connection_provider", data={"client": "a"}, headers=AUTH
        ).json()
        assert second["wire"] == wires[1]
