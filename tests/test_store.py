from __future__ import annotations

import gc
import hashlib
import json
import shutil
from pathlib import Path

import pyoxigraph as ox
import pytest

import cadkg
from cadkg.errors import IngestError, QueryError, StoreError
from cadkg.mapping.writer import graph_iri
from tests.conftest import IEMA, ROOT

BASE = "https://example.org/cell/iema-qe01/"


def copy_example(tmp_path: Path) -> Path:
    target = tmp_path / "cell"
    shutil.copytree(IEMA.parent, target)
    return target / "manifest.toml"


def test_one_named_graph_per_file_with_provenance(iema: cadkg.KnowledgeGraph) -> None:
    graphs = iema.named_graphs()
    for rel in ("manifest.toml", "ids.wri", "lista-cablaggio.csv"):
        assert graph_iri(BASE, rel) in graphs
    sources = {row["path"]: row for row in iema.sources()}
    wri = IEMA.parent / "ids.wri"
    assert sources["ids.wri"]["sha256"] == hashlib.sha256(wri.read_bytes()).hexdigest()
    assert sources["ids.wri"]["kind"] == "wri"
    assert sources["lista-cablaggio.csv"]["kind"] == "connection-list"
    assert sources["ids.wri"]["time"].tzinfo is not None


def test_wire_triples_stay_in_their_file_graph(iema: cadkg.KnowledgeGraph) -> None:
    rows = iema.query(
        "SELECT ?wire ?g WHERE { GRAPH ?g { ?wire a ck:Wire ; ck:wireNumber ?wireNumber } }",
        wireNumber="1500.51",
    )
    assert [r["g"] for r in rows] == [graph_iri(BASE, "lista-cablaggio.csv")]


def test_bindings_are_never_pasted_into_the_query(iema: cadkg.KnowledgeGraph) -> None:
    hostile = 'F1500.1" } UNION { ?component ?p ?o } #'
    projected = "SELECT DISTINCT ?component ?label WHERE { ?component a ck:Component ; ck:label ?label }"
    hidden = "SELECT DISTINCT ?component WHERE { ?component a ck:Component ; ck:label ?label }"
    for query in (projected, hidden):
        assert len(iema.query(query, label=hostile)) == 0
        found = iema.query(query, label="F1500.1")
        assert [r["component"] for r in found] == [BASE + "component/F1500.1"]


def test_query_errors_are_query_errors(iema: cadkg.KnowledgeGraph) -> None:
    with pytest.raises(QueryError, match="syntax error"):
        iema.query("SELECT ?x WHERE {")
    with pytest.raises(QueryError, match="SELECT"):
        iema.query("ASK { ?s ?p ?o }")
    with pytest.raises(QueryError):
        iema.query("SELECT ?x WHERE { ?x ck:label ?y }", y=object())


def test_a_bound_query_reports_syntax_errors_where_they_are_written(iema: cadkg.KnowledgeGraph) -> None:
    text = "SELECT ?c WHERE {\n  ?c ck:label ?label .\n  ?c ck:hasPin ?p ?? .\n}"
    messages = []
    for bindings in ({}, {"label": "F1500.1"}):
        with pytest.raises(QueryError) as caught:
            iema.query(text, **bindings)
        messages.append(str(caught.value))
    assert messages[0] == messages[1]
    assert messages[0].startswith("SPARQL syntax error at line 4, column 2 (found the end of the query")


def test_ask_and_construct(iema: cadkg.KnowledgeGraph) -> None:
    assert iema.ask("ASK { ?w ck:wireNumber ?n }", n="0V")
    assert not iema.ask("ASK { ?w ck:wireNumber ?n }", n="no-such-wire")
    triples = iema.construct(
        "CONSTRUCT { ?c ck:hasPin ?p } WHERE { ?c ck:label ?label ; ck:hasPin ?p }", label="Q1500.1"
    )
    # The 8 wired pins and the other couples of its two models (13, 14 and 53, 54, 61, 62).
    assert len(triples) == 14


def test_dataframe_has_the_query_columns(iema: cadkg.KnowledgeGraph) -> None:
    frame = iema.named_query("wires-of-component", label="F1500.1").to_dataframe()
    assert list(frame.columns)[:3] == ["label", "sequence", "wireNumber"]
    assert frame["wireNumber"].tolist()[:2] == ["1500.51", "1500.50"]


def test_an_export_of_some_graphs_holds_those_graphs_whole(iema: cadkg.KnowledgeGraph) -> None:
    wanted = [g for g in iema.named_graphs() if g.endswith(("ids.wri", "/derived"))]
    assert len(wanted) == 2
    quads = list(ox.parse(iema.serialize("nq", graphs=wanted), format=ox.RdfFormat.N_QUADS))
    assert {q.graph_name.value for q in quads} == set(wanted)
    assert len(quads) == sum(len(list(iema.graph_quads(g))) for g in wanted)
    merged = list(ox.parse(iema.serialize("nt", graphs=wanted[:1]), format=ox.RdfFormat.N_TRIPLES))
    assert len(merged) == len(list(iema.graph_quads(wanted[0])))


@pytest.mark.parametrize("fmt", ["ttl", "nt", "nq", "trig", "jsonld"])
def test_exports_round_trip(iema: cadkg.KnowledgeGraph, fmt: str) -> None:
    data = iema.serialize(fmt)
    rdf_format = {
        "ttl": ox.RdfFormat.TURTLE,
        "nt": ox.RdfFormat.N_TRIPLES,
        "nq": ox.RdfFormat.N_QUADS,
        "trig": ox.RdfFormat.TRIG,
        "jsonld": ox.RdfFormat.JSON_LD,
    }[fmt]
    store = ox.Store()
    store.load(data, rdf_format)
    ontology_triples = sum(1 for q in iema.quads() if q.graph_name == ox.NamedNode("https://w3id.org/cadkg"))
    if fmt in ("nq", "trig", "jsonld"):
        assert len(store) == len(iema) - ontology_triples
        assert {g.value for g in store.named_graphs()} == set(iema.named_graphs()) - {
            "https://w3id.org/cadkg"
        }
    else:
        merged = {
            (q.subject, q.predicate, q.object)
            for q in iema.quads()
            if q.graph_name != ox.NamedNode("https://w3id.org/cadkg")
        }
        assert len(store) == len(merged)
    if fmt == "jsonld":
        assert isinstance(json.loads(data), list | dict)


def test_build_into_directory_and_reopen(tmp_path: Path) -> None:
    kg = cadkg.build(IEMA, tmp_path / "store")
    count = len(kg)
    kg.close()
    reopened = cadkg.open(tmp_path / "store")
    assert len(reopened) == count
    assert reopened.named_query("wire-endpoints", wireNumber="1500.51").rows[0]["component"] == "F1500.1"
    reopened.close()


def test_failed_build_leaves_the_previous_store_unchanged(tmp_path: Path) -> None:
    manifest = copy_example(tmp_path)
    store = tmp_path / "store"
    cadkg.build(manifest, store).close()
    before = sorted(p.name for p in store.iterdir())
    with cadkg.open(store) as kg:
        count = len(kg)
    csv = manifest.parent / "lista-cablaggio.csv"
    lines = csv.read_text(encoding="utf-8").splitlines(keepends=True)
    lines[20] = lines[20].replace("=-", "", 1).replace(":", "-", 1)  # a pin without its colon
    csv.write_text("".join(lines), encoding="utf-8")
    with pytest.raises(IngestError) as err:
        cadkg.build(manifest, store)
    assert err.value.line == 21
    assert sorted(p.name for p in store.iterdir()) == before
    with cadkg.open(store) as kg:
        assert len(kg) == count


@pytest.mark.slow
def test_failed_first_build_leaves_nothing_behind(tmp_path: Path) -> None:
    # A failure at the first source, while the new store is still busy in the background:
    # the generation used to come back after its removal, and the retry was refused.
    manifest = copy_example(tmp_path)
    scene = manifest.parent / "scene.x3d"
    good = scene.read_bytes()
    scene.write_bytes(
        good.replace(
            b'DEF="ID000012" translation="0.01 0 0.0075"', b'DEF="ID000012" translation="0.01 nan 0.0075"', 1
        )
    )
    text = manifest.read_text(encoding="utf-8")
    wri, x3d = 'path = "ids.wri"\nkind = "wri"', 'path = "scene.x3d"\nkind = "x3d"\nframe = "cabinet"'
    manifest.write_text(text.replace(x3d, "@").replace(wri, x3d).replace("@", wri), encoding="utf-8")
    store = tmp_path / "store"
    for _ in range(4):
        with pytest.raises(IngestError) as err:
            cadkg.build(manifest, store)
        assert "bad number in 'translation'" in str(err.value)
        del err  # as a command ends: the last references to the failed build go
        gc.collect()
        assert list(store.iterdir()) == []
    scene.write_bytes(good)
    with cadkg.build(manifest, store) as kg:
        assert kg.named_query("wire-endpoints", wireNumber="1500.51").rows[0]["component"] == "F1500.1"


def test_builds_into_what_a_killed_build_left(tmp_path: Path) -> None:
    store = tmp_path / "store"
    debris = store / "gen-20260101T000000-0badf00d"
    debris.mkdir(parents=True)
    (debris / "000024.sst").write_bytes(b"half written")
    (store / ".CURRENT.gen-20260101T000000-0badf00d").write_text("gen-20260101T000000-0badf00d\n")
    with cadkg.build(IEMA, store) as kg:
        assert kg.generation != debris.name
        assert kg.named_query("wire-endpoints", wireNumber="1500.51").rows[0]["component"] == "F1500.1"
    (tmp_path / "other").mkdir()
    (tmp_path / "other" / "gen-notes").write_text("mine")  # a file, not a generation
    with pytest.raises(StoreError, match="not a cadkg store"):
        cadkg.build(IEMA, tmp_path / "other")


def test_rebuild_replaces_the_generation(tmp_path: Path) -> None:
    store = tmp_path / "store"
    cadkg.build(IEMA, store).close()
    first = (store / "CURRENT").read_text().strip()
    cadkg.build(IEMA, store).close()
    second = (store / "CURRENT").read_text().strip()
    assert first != second
    # The replaced generation is kept as the previous one (for 'cadkg diff STORE') ...
    assert sorted(p.name for p in store.iterdir()) == sorted(["CURRENT", "PREVIOUS", first, second])
    assert (store / "PREVIOUS").read_text().strip() == first
    cadkg.build(IEMA, store).close()
    third = (store / "CURRENT").read_text().strip()
    # ... until the next build replaces it.
    assert sorted(p.name for p in store.iterdir()) == sorted(["CURRENT", "PREVIOUS", second, third])


def test_refuses_to_build_into_a_foreign_directory(tmp_path: Path) -> None:
    (tmp_path / "notes.txt").write_text("mine")
    with pytest.raises(StoreError, match="not a cadkg store"):
        cadkg.build(IEMA, tmp_path)
    with pytest.raises(StoreError, match="not a cadkg store"):
        cadkg.open(tmp_path)


def test_replacing_one_file_graph_leaves_the_others(tmp_path: Path) -> None:
    manifest = copy_example(tmp_path)
    kg = cadkg.build(manifest, tmp_path / "store")
    wri_graph = graph_iri(BASE, "ids.wri")

    def graph_of(iri: str) -> set[tuple[str, str, str]]:
        return {
            (str(q.subject), str(q.predicate), str(q.object))
            for q in kg.quads()
            if q.graph_name == ox.NamedNode(iri)
        }

    wri_before = graph_of(wri_graph)
    csv = manifest.parent / "lista-cablaggio.csv"
    lines = csv.read_text(encoding="utf-8").splitlines(keepends=True)
    csv.write_text("".join(lines[:-1]), encoding="utf-8")  # drop the last wire
    wires_before = len(kg.named_query("connections-in-order"))
    report = kg.replace_source(csv, "lista-cablaggio.csv", BASE, "connection-list")
    assert report.records == 110  # the info record and 109 connections
    assert len(kg.named_query("connections-in-order")) == wires_before - 1
    assert graph_of(wri_graph) == wri_before

    lines[9] = lines[9].replace(":", "-", 1).replace("=-", "", 1)  # wire 6 (F1500.3:13) without a pin
    csv.write_text("".join(lines), encoding="utf-8")
    with pytest.raises(IngestError):
        kg.replace_source(csv, "lista-cablaggio.csv", BASE, "connection-list")
    assert len(kg.named_query("connections-in-order")) == wires_before - 1
    kg.close()


def test_graph_view_traverses_wires(iema: cadkg.KnowledgeGraph) -> None:
    view = iema.graph_view()
    f1 = BASE + "component/F1500.1"
    assert view.nodes[f1]["type"] == "Component"
    assert view.nodes[f1]["label"] == "F1500.1"
    pin = BASE + "pin/F1500.1/14"
    assert view.has_edge(pin, f1, key="pinOf")
    wire = BASE + "wire/1500.51"
    assert view.has_edge(wire, pin, key="fromPin")
    assert view.nodes[wire]["type"] == "Wire"
    only_pins = iema.graph_view(["pinOf"])
    assert {d["relation"] for _, _, d in only_pins.edges(data=True)} == {"pinOf"}
    with pytest.raises(cadkg.UnknownTermError):
        iema.graph_view(["pinsOf"])


def test_graphml_export_reads_back(iema: cadkg.KnowledgeGraph, tmp_path: Path) -> None:
    import networkx as nx

    path = iema.export(tmp_path / "cell.graphml")
    graph = nx.read_graphml(path)
    view = iema.graph_view()
    assert graph.number_of_nodes() == view.number_of_nodes()
    assert graph.number_of_edges() == view.number_of_edges()
    assert graph.nodes[BASE + "component/X1600"]["label"] == "X1600"


def test_an_update_is_followed_by_the_derivation(tmp_path: Path) -> None:
    mini = ROOT / "tests" / "data" / "cells" / "mini" / "manifest.toml"
    target_z = 'SELECT DISTINCT ?z WHERE { ?c ck:label "K1" ; ck:targetPose/ck:tz ?z }'
    with cadkg.KnowledgeGraph.build(mini, tmp_path / "store") as kg:
        # tests/usecases/iema/test_services.py: K1's target is 0.15 m in front of its front face.
        assert [round(r["z"], 9) for r in kg.query(target_z)] == [0.2175]
        kg.execute(
            """DELETE { GRAPH ?g { ?c ck:approachDistance ?d } }
               INSERT { GRAPH ?g { ?c ck:approachDistance 0.25e0 } }
               WHERE { GRAPH ?g { ?c a ck:Cell ; ck:approachDistance ?d } }""",
            update=True,
        )
        assert [round(r["z"], 9) for r in kg.query(target_z)] == [0.3175]
        assert kg.cell_model().components["K1"].target.position[2] == pytest.approx(0.3175)


def test_a_bad_row_late_in_a_streamed_list_fails_the_memory_build_located(tmp_path: Path) -> None:
    # In memory the connection list is mapped and loaded row by row: rows before the bad
    # one are in the store being built when it raises, and that store is dropped.
    manifest = copy_example(tmp_path)
    csv = manifest.parent / "lista-cablaggio.csv"
    lines = csv.read_text(encoding="utf-8").splitlines(keepends=True)
    last = len(lines) - 1
    cells = lines[last].split("\t")
    cells[2] = "=-X0031"  # the origin pin cell without ':PIN'
    lines[last] = "\t".join(cells)
    csv.write_text("".join(lines), encoding="utf-8")
    with pytest.raises(IngestError) as err:
        cadkg.build(manifest)
    assert err.value.line == last + 1
    assert "lista-cablaggio.csv" in str(err.value)


@pytest.mark.parametrize("enabled", [True, False])
def test_a_build_leaves_the_garbage_collector_as_it_found_it(tmp_path: Path, enabled: bool) -> None:
    import gc

    (gc.enable if enabled else gc.disable)()
    try:
        cadkg.build(IEMA)
        assert gc.isenabled() is enabled
        with pytest.raises(IngestError):
            cadkg.build(ROOT / "examples" / "bad-cell" / "does-not-exist.toml")
        assert gc.isenabled() is enabled
    finally:
        gc.enable()


def test_an_in_memory_build_writes_its_meshes_when_asked_where_they_are(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    import tempfile

    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))
    kg = cadkg.build(IEMA)
    assert not list(tmp_path.iterdir())  # the build itself wrote no file
    uris = sorted({row["u"] for row in kg.query("SELECT ?u WHERE { ?m ck:meshUri ?u }").rows})
    assert len(uris) == 117  # the scene's shapes (seven end stops among them) and the models' meshes
    files = kg.files_dir
    assert files.parent == tmp_path
    written = sorted(str(p.relative_to(files)) for p in files.rglob("*") if p.is_file())
    assert written == uris
    for uri in uris:  # binary STL: 80-byte header, triangle count, 50 bytes a triangle
        stl = (files / uri).read_bytes()
        assert len(stl) == 84 + 50 * int.from_bytes(stl[80:84], "little") > 84
    assert kg.files_dir == files  # written once, in one place
