"""The kinds a use case reads from its derived model give what their queries find in the graph
written from it, so a diff is the same whichever it reads."""

from __future__ import annotations

import shutil
import warnings
from pathlib import Path

import pyoxigraph as ox
import pytest

import cadkg
from cadkg.changes import diff_graphs
from cadkg.changes.kinds import kinds_for
from cadkg.changes.revisions import open_generation, open_previous
from cadkg.changes.things import Thing, _derived_things, _queried_things, read_things
from cadkg.errors import StoreError
from cadkg.ontology.terms import CK, RDF_TYPE
from cadkg.store import GraphStore
from tests.changes.cells import MINI, copy_cell, edit
from tests.conftest import EXAMPLES, synthetic_manifest
from tests.ingest.workbooks import replace_in_member

KINDS = {kind.name: kind for kind in kinds_for(["iema"])}
PIN = KINDS["pin"]
DERIVED = [KINDS["pin"], KINDS["wire"]]  # the kinds the cabinet's model gives
EXAMPLE_OF = {"elimco": "elimco-bench", "vw": "vw-harness"}
IEMA_MANIFESTS = sorted((EXAMPLES / "iema-switchgear").glob("manifest*.toml"))


def _same(derived: list[Thing], queried: list[Thing]) -> None:
    # By IRI: wires share numbers (several 0V), and each thing's IRI is one.
    by_iri = {thing.iri: thing for thing in queried}
    assert len(by_iri) == len(queried) == len(derived)
    assert sorted(by_iri) == sorted(str(thing.iri) for thing in derived)
    for thing in derived:
        other = by_iri[thing.iri]
        assert thing.id == other.id
        assert (thing.iri, thing.attributes, thing.keys) == (other.iri, other.attributes, other.keys), (
            thing.id
        )
        if thing.pose is None or other.pose is None:
            assert thing.pose is other.pose is None, thing.id
        else:
            assert thing.pose.position == pytest.approx(other.pose.position, abs=1e-9), thing.id
            turned = [abs(a - b) for a, b in zip(thing.pose.orientation, other.pose.orientation, strict=True)]
            flipped = [
                abs(a + b) for a, b in zip(thing.pose.orientation, other.pose.orientation, strict=True)
            ]
            assert min(max(turned), max(flipped)) < 1e-9, thing.id


def check_derived(kg: cadkg.KnowledgeGraph) -> int:
    """How many pins; for every kind the model gives, what it gives is what the queries find."""
    counts = {}
    for kind in DERIVED:
        derived = _derived_things(kg, kind)
        assert derived is not None, f"the graph's model was not read for {kind.name}"
        _same(derived, _queried_things(kg, kind))
        counts[kind.name] = len(derived)
    assert counts["wire"] > 0
    return counts["pin"]


@pytest.mark.parametrize("manifest", IEMA_MANIFESTS, ids=lambda p: p.stem)
def test_the_models_pins_are_the_queries_pins(manifest: Path) -> None:
    count = check_derived(cadkg.build(manifest))
    # Figure 3's cell is an ID table and a list: no model places a pin.
    assert count == 0 if manifest.stem == "manifest-fig3" else count > 100


def test_the_same_on_a_synthetic_cabinet_and_its_store(tmp_path: Path) -> None:
    manifest = synthetic_manifest(tmp_path / "cell", 300, cabinet=True)
    count = check_derived(cadkg.build(manifest))
    store = _built(manifest, tmp_path / "store")
    with cadkg.KnowledgeGraph.open(store) as kg:
        assert check_derived(kg) == count  # the kept model, read back from the store
    # Without its kept model a read-only store is read by the queries, never derived.
    model = store / (store / "CURRENT").read_text().strip() / "cell-model.json"
    model.unlink()
    with cadkg.KnowledgeGraph.open(store) as kg:
        assert _derived_things(kg, PIN) is None
        assert len(read_things(kg, PIN)) == count
    assert not model.exists()


def test_the_previous_generation_is_read_with_its_kept_model(tmp_path: Path) -> None:
    """``cadkg diff STORE``: the generation served before the live one keeps its model too."""
    manifest = copy_cell(MINI, tmp_path / "cell")
    store = _built(manifest, tmp_path / "store")
    edit(manifest.parent / "connections.tsv", "\tW1\t", "\tW11\t")
    _built(manifest, store)
    before, old_name, new_name = open_previous(store)
    with before, cadkg.KnowledgeGraph.open(store) as after:
        assert before.open_generation == old_name != new_name == after.open_generation
        assert _derived_things(before, PIN) is not None
        assert check_derived(before) == check_derived(after) > 0
        changes = diff_graphs(before, after)
        plain = (GraphStore.of_quads(list(kg.quads())) for kg in (before, after))
        assert changes.to_json() == diff_graphs(*plain, kinds=kinds_for(["iema"])).to_json()
    assert [c.id for c in changes.changed if c.kind != "file"] == ["W11"]


@pytest.mark.parametrize("name", ["../store", "..", "gen-missing", "CURRENT", "", "gen-x/../.."])
def test_only_a_kept_generation_of_the_store_opens(tmp_path: Path, name: str) -> None:
    store = _built(copy_cell(MINI, tmp_path / "cell"), tmp_path / "store")
    with pytest.raises(StoreError, match="no generation"):
        open_generation(store, name)
    live = (store / "CURRENT").read_text().strip()
    with pytest.raises(StoreError, match="no generation"):
        cadkg.KnowledgeGraph.open(store, read_only=False, generation=live)


def _built(manifest: Path, store: Path) -> Path:
    cadkg.build(manifest, store).close()
    return store


def test_a_pin_moved_in_its_model_is_found_either_way(tmp_path: Path) -> None:
    old = cadkg.build(MINI / "manifest.toml")
    manifest = copy_cell(MINI, tmp_path / "new")
    screw = '<couple name="A1">\n      <subitem name="screw"><pos name="x">0.005</pos>'
    edit(manifest.parent / "models.xml", screw, screw.replace("0.005", "0.008"))
    new = cadkg.build(manifest)
    through_model = diff_graphs(old, new)
    # The same graphs without their models: every kind read by its queries.
    plain_old, plain_new = (GraphStore.of_quads(list(kg.quads())) for kg in (old, new))
    assert _derived_things(plain_old, PIN) is None
    through_queries = diff_graphs(plain_old, plain_new, kinds=kinds_for(["iema"]))
    assert through_model.to_json() == through_queries.to_json()
    assert sorted(c.id for c in through_model.changed if c.kind == "pin") == ["K1:A1", "K2:A1"]


def test_a_graph_of_two_cells_is_read_by_the_queries() -> None:
    kg = cadkg.build(MINI / "manifest.toml")
    assert _derived_things(kg, PIN) is not None
    other = ox.NamedNode("https://example.org/cell/other/")
    kg._store.add(ox.Quad(other, RDF_TYPE, CK["Cell"]))
    kg._store.add(ox.Quad(other, CK["profile"], ox.Literal("iema")))
    assert _derived_things(kg, PIN) is None
    assert read_things(kg, PIN)


def test_the_same_with_a_wire_end_the_workbook_lost(tmp_path: Path) -> None:
    cell = tmp_path / "cell"
    shutil.copytree(EXAMPLES / "iema-switchgear", cell)
    replace_in_member(
        cell / "lista-cablaggio.xlsx",
        "xl/worksheets/sheet1.xml",
        b'<c r="F5" t="inlineStr"><is><t>=-Q1500.1:A1</t></is></c>',
        b'<c r="F5" t="e"><f>-basta</f><v>#NAME?</v></c>',
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        kg = cadkg.build(cell / "manifest-vrml.toml")
    assert check_derived(kg) > 100


@pytest.mark.parametrize("profile", ["elimco", "vw"])
def test_another_use_cases_wires_are_read_by_their_own_queries(profile: str) -> None:
    manifest = next((EXAMPLES / EXAMPLE_OF[profile]).glob("manifest*.toml"))
    kg = cadkg.build(manifest)
    (wire,) = [kind for kind in kinds_for([profile]) if kind.name == "wire"]
    assert wire.profile == profile and _derived_things(kg, wire) is None
    assert len(read_things(kg, wire)) == len(_queried_things(kg, wire)) > 0
