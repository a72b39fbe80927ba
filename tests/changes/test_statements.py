"""The change set as RDF statements: applied to the old graph, it gives the new one."""

from __future__ import annotations

import pyoxigraph as ox
import pytest

import cadkg
from cadkg.changes import apply_changes, changes_turtle, diff_graphs, read_changes, statement_changes
from cadkg.changes.statements import cell_quads
from cadkg.errors import StoreError
from tests.changes.cells import MINI, copy_cell, edit


@pytest.fixture(scope="module")
def pair(tmp_path_factory: pytest.TempPathFactory) -> tuple[cadkg.KnowledgeGraph, cadkg.KnowledgeGraph]:
    manifest = copy_cell(MINI, tmp_path_factory.mktemp("changes") / "new")
    edit(manifest.parent / "connections.tsv", "\tW1\t", "\tW11\t")
    edit(manifest.parent / "connections.tsv", "W3\t0,75 mm²\tBU", "W3\t1,5 mm²\tRD")
    edit(manifest.parent / "scene.x3d", 'translation="0.3 0.5 0.0075"', 'translation="0.32 0.5 0.0075"')
    return cadkg.build(MINI / "manifest.toml"), cadkg.build(manifest)


def test_the_change_set_applied_to_the_old_graph_gives_the_new_one(
    pair: tuple[cadkg.KnowledgeGraph, cadkg.KnowledgeGraph],
) -> None:
    old, new = pair
    removed, added = statement_changes(old, new)
    assert removed and added
    data = changes_turtle(removed, added, diff_graphs(old, new))
    store = ox.Store()
    store.extend(cell_quads(old))
    assert set(store) != set(cell_quads(new))
    assert apply_changes(store, data) == (len(removed), len(added))
    assert set(store) == set(cell_quads(new))


def test_statements_are_grouped_by_thing(pair: tuple[cadkg.KnowledgeGraph, cadkg.KnowledgeGraph]) -> None:
    old, new = pair
    removed, added = statement_changes(old, new)
    data = changes_turtle(removed, added, diff_graphs(old, new))
    graph = ox.Store()
    graph.load(data, ox.RdfFormat.TURTLE)
    answers = graph.query(
        """PREFIX ck: <https://w3id.org/cadkg#>
           PREFIX rdf: <http://www.w3.org/1999/02/22-rdf-syntax-ns#>
           SELECT DISTINCT ?kind ?id ?change WHERE {
             ?set a ck:ChangeSet ; ck:hasChange ?c .
             ?c ck:thingKind ?kind ; ck:thingId ?id ; ck:changeKind ?change ; ck:changeOf ?thing .
             ?c ck:addedStatement|ck:removedStatement ?s .
             ?s rdf:subject ?thing }"""
    )
    rows = {(s["kind"].value, s["id"].value, s["change"].value) for s in answers}
    assert {("wire", "W3", "changed"), ("component", "K2", "changed")} <= rows
    # The renumbered wire: its number's statement removed and added on the same node.
    assert ("wire", "W11", "changed") in rows


def test_a_change_set_that_is_not_turtle_is_refused() -> None:
    with pytest.raises(StoreError, match="not Turtle"):
        read_changes(b"<not turtle")
    with pytest.raises(StoreError, match="lacks"):
        read_changes(
            b"@prefix ck: <https://w3id.org/cadkg#> . <urn:c> ck:addedStatement <urn:s> . "
            b"<urn:s> <http://www.w3.org/1999/02/22-rdf-syntax-ns#subject> <urn:x> ."
        )
