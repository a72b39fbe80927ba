"""The impact of a rebuild on the plan and the cursors: ``cadkg diff``'s ``impact``, and the
cursors ``cadkg call`` keeps beside a store, carried across ``cadkg build`` by identity."""

from __future__ import annotations

import json
from pathlib import Path

from tests.changes.cells import MINI, copy_cell, edit
from tests.cli import run

NEW_WIRE = (
    "1\tQ\t=-K2:A1\t1\tQ\t=-X1:2:a\t{number}\t0,75 mm²\tBU\t+\t24V\t0,2 m\t\tPUNTALINO_vite\tPUNTALINO_vite\n"
)
HEADER_END = "Terminazione Destinazione\n"


def _ok(*args: str | Path) -> str:
    result = run(*args)
    assert result.returncode == 0, result.stderr
    return result.stdout


def _wire(store: Path, client: str) -> tuple[str, str]:
    """The wire ``group_connection_provider`` hands ``client``, and what stderr said."""
    result = run("call", store, "group_connection_provider", "--client", client)
    assert result.returncode == 0, result.stderr
    return str(json.loads(result.stdout)["wire"]), result.stderr


def _cell(tmp_path: Path) -> tuple[Path, Path]:
    manifest = copy_cell(MINI, tmp_path / "cell")
    store = tmp_path / "store"
    _ok("build", manifest, "--store", store)
    return manifest.parent / "connections.tsv", store


def test_diff_says_which_tasks_are_new_to_redo_and_dropped(tmp_path: Path) -> None:
    connections, store = _cell(tmp_path)
    _ok("plan", store)
    plan = json.loads(_ok("plan", store, "--format", "json"))
    robot = [s["task"] for s in plan["steps"] if s["performer"] == "robot"]
    assert len(robot) >= 2
    first, second = robot[0], robot[1]
    assert _wire(store, "arm")[0] == first  # the arm has landed the first wire of the plan
    edit(connections, f"\t{first}\t0,75 mm²\tBU", f"\t{first}\t0,75 mm²\tRD")
    text = connections.read_text(encoding="utf-8")
    kept = "".join(line for line in text.splitlines(keepends=True) if f"\t{second}\t" not in line)
    connections.write_text(kept + NEW_WIRE.format(number="W5"), encoding="utf-8")
    _ok("build", connections.parent / "manifest.toml", "--store", store)

    result = run("diff", store, "--format", "json")
    assert result.returncode == 0, result.stderr
    impact = json.loads(result.stdout)["impact"]
    assert impact["plan"] is True
    assert [(i["id"], i["task"], i["attributes"], i["passed_by"]) for i in impact["redo"]] == [
        (first, first, ["colour"], ["iema cursor of arm"])
    ]
    assert [(i["id"], i["task"], i["done"]) for i in impact["dropped"]] == [(second, second, False)]
    assert [i["id"] for i in impact["new"]] == ["W5"]
    assert impact["changed"] == []
    assert any(note.startswith("iema cursor of arm: ") for note in impact["cursors"])
    assert "tasks: 1 new, 1 to redo, 0 changed, 1 dropped" in result.stderr

    table = run("diff", store)
    assert table.returncode == 0
    assert "redo" in table.stdout and "passed it" in table.stdout and "dropped" in table.stdout


def test_a_diff_without_plan_or_cursor_has_no_impact(tmp_path: Path) -> None:
    connections, store = _cell(tmp_path)
    edit(connections, "\tW1\t", "\tW11\t")
    _ok("build", connections.parent / "manifest.toml", "--store", store)
    data = json.loads(_ok("diff", store, "--format", "json"))
    assert "impact" not in data and data["changed"]


def test_cadkg_call_keeps_its_cursor_on_the_wire_across_a_build(tmp_path: Path) -> None:
    connections, store = _cell(tmp_path)
    first, _ = _wire(store, "arm")
    following, _ = _wire(store, "probe")
    second, _ = _wire(store, "probe")
    assert first == following and second != first
    # The next wire of the arm is renumbered, and a new wire comes before it: its index moves.
    edit(connections, f"\t{second}\t", f"\t{second}X\t")
    edit(connections, HEADER_END, HEADER_END + NEW_WIRE.format(number="W0"))
    _ok("build", connections.parent / "manifest.toml", "--store", store)

    wire, said = _wire(store, "arm")
    assert wire == f"{second}X"
    assert f"iema cursor of arm: on wire {second}X (was {second})" in said
    # Carried once: the next call goes on from where the cursor is, saying nothing.
    again, said = _wire(store, "arm")
    assert again != wire and said == ""
    # A client that never moved starts at the start: the new first wire.
    assert _wire(store, "fresh")[0] == "W0"


def test_cursors_of_a_generation_the_store_no_longer_keeps_start_afresh(tmp_path: Path) -> None:
    connections, store = _cell(tmp_path)
    assert _wire(store, "arm")[0]
    for number in ("W0", "W00"):  # two builds: the generation the cursor was made on is removed
        edit(connections, HEADER_END, HEADER_END + NEW_WIRE.format(number=number))
        _ok("build", connections.parent / "manifest.toml", "--store", store)
    wire, said = _wire(store, "arm")
    assert "cursors start afresh: the generation they were made on" in said
    assert wire == "W00"  # the first wire of the list now
