"""A build names each of its stages as it starts them, and their times add up to the build's."""

from __future__ import annotations

import time
from pathlib import Path

import cadkg
from cadkg.graph import KnowledgeGraph
from cadkg.ingest.manifest import load_manifest
from tests.cli import run
from tests.conftest import IEMA

FILES = [source.rel for source in load_manifest(IEMA).sources]


def test_stages_are_named_in_order_and_add_up_to_the_build(tmp_path: Path) -> None:
    heard: list[str] = []
    began = time.perf_counter()
    kg = KnowledgeGraph.build(IEMA, tmp_path / "store", on_stage=heard.append)
    wall = time.perf_counter() - began
    names = [name for name, _ in kg.stages]
    assert names == heard
    assert names == [
        "opening the store",
        *(f"reading {f}" for f in FILES),
        "deriving the cell model",
        "writing the derived graph",
        "loading into the store",
        "indexing the store",
    ]
    assert all(seconds >= 0 for _, seconds in kg.stages)
    # Only reading the manifest itself lies outside the stages.
    assert 0 < wall - sum(s for _, s in kg.stages) < 1.0
    kg.close()


def test_an_in_memory_build_has_no_indexing_stage() -> None:
    kg = cadkg.build(IEMA)
    assert [n for n, _ in kg.stages][-1] == "loading into the store"


def test_the_build_table_accounts_for_every_stage(tmp_path: Path) -> None:
    result = run("build", IEMA, "--store", tmp_path / "store")
    assert result.returncode == 0, result.stderr
    rows = [line.strip("│ ").split("│") for line in result.stdout.splitlines() if line.startswith("│")]
    seconds = {row[0].strip(): float(row[-1]) for row in rows}
    assert {"deriving the cell model", "loading into the store", "indexing the store", "total"} <= set(
        seconds
    )
    parts = sum(v for k, v in seconds.items() if k != "total")
    assert abs(parts - seconds["total"]) < 0.01
