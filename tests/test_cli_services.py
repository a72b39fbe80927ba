"""``cadkg call`` and ``cadkg assign`` on a store of the small test cabinet."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from tests.cli import run
from tests.usecases.iema.test_services import MINI


@pytest.fixture
def cell(tmp_path: Path) -> Path:
    """A copy of the mini cell, so a test may edit its files and rebuild."""
    target = tmp_path / "mini"
    shutil.copytree(MINI.parent, target)
    return target


def build(cell: Path) -> Path:
    store = cell / "store"
    result = run("build", cell / "manifest.toml", "--store", store)
    assert result.returncode == 0, result.stderr
    return store


def call(store: Path, *args: str) -> dict[str, object]:
    result = run("call", store, *args)
    assert result.returncode == 0, result.stderr
    data: dict[str, object] = json.loads(result.stdout)
    return data


def test_call_prints_pose_dimensions_and_pins(cell: Path) -> None:
    data = call(build(cell), "cad_service", "label=K1")
    assert data["success"] is True
    assert data["original_pose"]["position"] == pytest.approx({"x": 0.15, "y": 0.5, "z": 0.0075})  # type: ignore[index]
    assert data["dimensions"] == pytest.approx({"x": 0.03, "y": 0.08, "z": 0.06})
    assert [p["pin"] for p in data["pins"]] == ["13", "A1", "A2"]  # type: ignore[attr-defined]


def test_cursor_walks_across_calls_per_client(cell: Path) -> None:
    store = build(cell)
    assert call(store, "group_connection_provider")["wire"] == "W1"
    assert call(store, "group_connection_provider")["wire"] == "W2"
    assert call(store, "group_connection_provider", "--client", "planner2")["wire"] == "W1"
    assert call(store, "reset_connection_list")["success"] is True
    assert call(store, "group_connection_provider")["wire"] == "W1"


def test_assign_persists_across_a_rebuild(cell: Path) -> None:
    store = build(cell)
    result = run("assign", store, "wire", "W2", "human")
    assert result.returncode == 0, result.stderr
    assert call(store, "group_connection_provider")["wire"] == "W1"
    assert call(store, "group_connection_provider")["wire"] == "W4"
    # Rebuild from the files: the hand edit stays, the overlay's W3 too; the cursor stays where
    # it was, past W4, the last robot wire (docs/changes.md, cursors across a rebuild).
    build(cell)
    assert call(store, "group_connection_provider")["end"] is True
    assert call(store, "reset_connection_list")["success"] is True
    wires = [call(store, "group_connection_provider")["wire"] for _ in range(2)]
    assert wires == ["W1", "W4"]
    # A component handed to a human takes its wires and its rail place with it, except
    # wires assigned explicitly: W2 goes back to the robot by name.
    assert run("assign", store, "wire", "W2", "robot").returncode == 0
    assert run("assign", store, "component", "K1", "human").returncode == 0
    assert call(store, "reset_connection_list")["success"] is True
    assert call(store, "group_connection_provider")["wire"] == "W2"
    assert call(store, "group_connection_provider")["end"] is True
    assert call(store, "rail_scanner")["components_label"] == ["X1", "K2"]


def test_assign_unknown_target_is_a_clear_error(cell: Path) -> None:
    store = build(cell)
    result = run("assign", store, "wire", "W99", "human")
    assert result.returncode == 2
    assert "no wire 'W99'" in result.stderr and "Traceback" not in result.stderr


def test_call_errors_are_one_line(cell: Path) -> None:
    store = build(cell)
    result = run("call", store, "cad_service", "colour=red")
    assert result.returncode == 2
    assert result.stderr.strip().startswith("cadkg: error: cad_service: unknown parameter colour")


def test_bad_overlay_row_is_located(cell: Path) -> None:
    (cell / "assignments.csv").write_text("kind,id,performer\nwire,W3,machine\n", encoding="utf-8")
    result = run("build", cell / "manifest.toml", "--store", cell / "store")
    assert result.returncode == 2
    assert "assignments.csv:2: unknown performer (found 'machine'" in result.stderr
