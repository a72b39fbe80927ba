"""``cadkg diff``: two revisions, or a store against its previous build; every format."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import pyoxigraph as ox
import pytest

import cadkg
from cadkg.changes.statements import read_changes
from tests.changes.cells import MINI, copy_cell, edit
from tests.cli import run


@pytest.fixture(scope="module")
def revisions(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The mini cell as a store, rebuilt from an edited copy (W1 renumbered W11, W4 removed)."""
    folder = tmp_path_factory.mktemp("cli-diff")
    manifest = copy_cell(MINI, folder / "new")
    edit(manifest.parent / "connections.tsv", "\tW1\t", "\tW11\t")
    text = (manifest.parent / "connections.tsv").read_text(encoding="utf-8")
    (manifest.parent / "connections.tsv").write_text(
        "".join(line for line in text.splitlines(keepends=True) if "\tW4\t" not in line), encoding="utf-8"
    )
    store = folder / "store"
    cadkg.build(MINI / "manifest.toml", store).close()
    cadkg.build(manifest, store).close()
    return store, manifest


def test_json_of_two_manifests(revisions: tuple[Path, Path]) -> None:
    _, manifest = revisions
    result = run("diff", MINI / "manifest.toml", manifest, "--format", "json")
    assert result.returncode == 0, result.stderr
    data = json.loads(result.stdout)
    assert {k: len(v) for k, v in data.items() if k in ("added", "removed", "changed")} == {
        "added": 0,
        "removed": 2,
        "changed": 2,
    }
    # K9 is named only by W4: it goes with it.
    assert sorted((item["kind"], item["id"]) for item in data["removed"]) == [
        ("component", "K9"),
        ("wire", "W4"),
    ]
    assert {"kind": "wire", "id": "W4", "iri": "https://example.org/cell/mini/wire/W4"} in data["removed"]
    wire = next(item for item in data["changed"] if item["kind"] == "wire")
    assert (wire["id"], wire["attributes"]) == ("W11", {"number": ["W1", "W11"]})
    assert "0 added, 2 removed, 2 changed" in result.stderr


def test_a_store_against_its_previous_build(revisions: tuple[Path, Path]) -> None:
    store, _ = revisions
    result = run("diff", store, "--format", "csv")
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader(io.StringIO(result.stdout)))
    assert {
        "change": "changed",
        "kind": "wire",
        "id": "W11",
        "attribute": "number",
        "old": "W1",
        "new": "W11",
    } in rows
    assert {"change": "removed", "kind": "wire", "id": "W4", "attribute": "", "old": "", "new": ""} in rows


def test_table_and_turtle(revisions: tuple[Path, Path]) -> None:
    store, _ = revisions
    table = run("diff", store)
    assert table.returncode == 0 and "number: W1 → W11" in table.stdout
    turtle = run("diff", store, "--format", "ttl")
    assert turtle.returncode == 0, turtle.stderr
    removed, added = read_changes(turtle.stdout.encode("utf-8"))
    number = ox.NamedNode("https://w3id.org/cadkg#wireNumber")
    assert any(q.predicate == number and q.object == ox.Literal("W11") for q in added)
    assert any(q.predicate == number and q.object == ox.Literal("W1") for q in removed)


def test_a_store_built_once_has_no_previous(tmp_path: Path) -> None:
    store = tmp_path / "store"
    cadkg.build(MINI / "manifest.toml", store).close()
    result = run("diff", store)
    assert result.returncode == 2
    assert result.stderr.count("\n") == 1 and "keeps no previous generation" in result.stderr


def test_bad_revisions_are_one_line_errors(tmp_path: Path) -> None:
    result = run("diff", tmp_path / "missing", MINI / "manifest.toml")
    assert result.returncode == 2 and "neither a store directory nor a manifest" in result.stderr
    assert "Traceback" not in result.stderr
