"""Deriving from the records of a build must give what deriving from the graph gives."""

from __future__ import annotations

from pathlib import Path

import pyoxigraph as ox
import pytest

import cadkg
from cadkg.ingest.manifest import load_manifest
from cadkg.mapping.pipeline import read_manifest_graphs
from cadkg.query.placements import Placements, placements
from cadkg.usecases.iema.derive.cabinet import derive_cell
from cadkg.usecases.iema.derive.collect import InputCollector
from cadkg.usecases.iema.derive.extract import extract
from tests.conftest import BAD, EXAMPLES, ROOT, synthetic_manifest

IEMA_DIR = EXAMPLES / "iema-switchgear"
CELLS = [
    IEMA_DIR / "manifest.toml",
    IEMA_DIR / "manifest-fig3.toml",
    IEMA_DIR / "manifest-komax.toml",
    IEMA_DIR / "manifest-vrml.toml",
    ROOT / "tests" / "data" / "cells" / "mini" / "manifest.toml",
    BAD,
]


def _collected(manifest_path: Path) -> InputCollector:
    manifest = load_manifest(manifest_path)
    collector = InputCollector(manifest)
    # As a build feeds it: each source's records as they are mapped.
    for _ in read_manifest_graphs(manifest, on_record=lambda source: collector.source(source.rel)):
        pass
    return collector


def _derived(kg: cadkg.KnowledgeGraph) -> set[str]:
    base = kg.cell_model().base
    quads = kg._store.quads_for_pattern(None, None, None, ox.NamedNode(base + "derived"))
    return {f"{q.subject} {q.predicate} {q.object}" for q in quads}


def _check(manifest_path: Path) -> None:
    collector = _collected(manifest_path)
    assert collector.complete
    kg = cadkg.build(manifest_path)
    from_graph = extract(kg)
    from_records = collector.inputs()
    assert from_records == from_graph
    # What the ROS node reads beside the kept model: the same frames and meshes, read alone.
    assert placements(kg) == Placements(from_graph.frames, from_graph.meshes)
    # The build derived from the records; deriving again from the graph changes nothing.
    built = _derived(kg)
    steps = [(s.wire, s.performer, s.keypoints) for s in kg.cell_model().steps]
    kg.derive()
    assert _derived(kg) == built
    assert [(s.wire, s.performer, s.keypoints) for s in kg.cell_model().steps] == steps
    assert derive_cell(from_records).rails == kg.cell_model().rails


@pytest.mark.parametrize("manifest_path", CELLS, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_records_give_the_graphs_inputs(manifest_path: Path) -> None:
    _check(manifest_path)


@pytest.mark.parametrize("cabinet", [False, True], ids=["cell", "cabinet"])
def test_records_give_the_graphs_inputs_synthetic(tmp_path: Path, cabinet: bool) -> None:
    _check(synthetic_manifest(tmp_path, 300, cabinet=cabinet))


def test_example_inputs_are_not_empty() -> None:
    inputs = _collected(IEMA_DIR / "manifest.toml").inputs()
    assert inputs.items_of["F1500.1"]
    # The example's strips come from its terminal diagram (schema-morsetti.ods), not a terminal schema.
    assert inputs.diagrams and inputs.wires and inputs.models and inputs.frames and inputs.assignments
    # A strip's rows in rail order; the relay's pins from EPLAN's parts management alone.
    kinds = [kind for _, kind, _ in inputs.diagrams["X1600"]]
    assert kinds == ["start", *["terminal"] * 4, "end"]
    assert set(inputs.models["6400170"].points) == {"A1", "A2", "11", "12", "14"}


def test_other_profiles_fall_back_to_the_graph() -> None:
    collector = _collected(EXAMPLES / "elvez-cell" / "manifest.toml")
    assert not collector.complete


@pytest.mark.parametrize("example", ["elvez-cell", "elimco-bench"])
def test_placements_of_the_other_profiles_are_those_of_the_extraction(example: str) -> None:
    with cadkg.build(EXAMPLES / example / "manifest.toml") as kg:
        inputs, placed = extract(kg), placements(kg)
    assert placed == Placements(inputs.frames, inputs.meshes)
    assert placed.frames
