from __future__ import annotations

from pathlib import Path

import pytest

import cadkg
from cadkg.query.validate import validate
from tests.conftest import BAD, ROOT


def test_the_good_examples_have_no_findings(iema: cadkg.KnowledgeGraph, fig3: cadkg.KnowledgeGraph) -> None:
    assert validate(iema) == []
    assert validate(fig3) == []


def test_planted_errors_are_found_at_their_lines() -> None:
    findings = validate(cadkg.build(BAD))
    assert [(f.location, f.severity, f.check) for f in findings] == [
        ("connections.tsv:6", "error", "unknown-label"),
        ("connections.tsv:9", "error", "duplicate-wire-number"),
    ]
    assert "K9999" in findings[0].message
    assert "connections.tsv:5" in findings[1].message


def test_shacl_findings_are_located(tmp_path: Path) -> None:
    # Two lists claiming the same wire number give that wire two from-pins: a shape violation
    # located in the file that stated it.
    (tmp_path / "ids.wri").write_text("ID000001\tF1\t\r\nID000002\tQ1\t\r\nID000003\tQ2\t\r\n")
    header = (
        "N. Pagina\tZona\tComponente:pin\tN. Pagina\tZona\tComponente:pin\tNumero filo\tSezione\tColore\n"
    )
    (tmp_path / "a.tsv").write_text(header + "+1\tQ\t-F1:1\t+1\tQ\t-Q1:1\tW7\t1,5\tBK\n")
    (tmp_path / "b.tsv").write_text(header + "+1\tQ\t-F1:2\t+1\tQ\t-Q2:1\tW7\t1,5\tBK\n")
    (tmp_path / "m.toml").write_text(
        '[cell]\nname = "t"\nprofile = "iema"\nbase_iri = "https://example.org/t/"\n'
        '[[source]]\npath = "ids.wri"\n[[source]]\npath = "a.tsv"\n[[source]]\npath = "b.tsv"\n'
    )
    findings = validate(cadkg.build(tmp_path / "m.toml"))
    shacl = [f for f in findings if f.check == "shacl"]
    assert {f.location for f in shacl} <= {"a.tsv:2", "b.tsv:2"}
    assert any("fromPin" in f.message for f in shacl)
    assert any("toPin" in f.message for f in shacl)


def test_a_wire_from_a_pin_to_itself_is_found_at_its_line(tmp_path: Path) -> None:
    (tmp_path / "ids.wri").write_text("ID000001\tF1\t\r\nID000002\tQ1\t\r\n")
    header = (
        "N. Pagina\tZona\tComponente:pin\tN. Pagina\tZona\tComponente:pin\tNumero filo\tSezione\tColore\n"
    )
    rows = "+1\tQ\t-F1:1\t+1\tQ\t-Q1:1\tW1\t1,5\tBK\n+1\tQ\t-F1:2\t+1\tQ\t=-F1:2\tW2\t1,5\tBK\n"
    (tmp_path / "a.tsv").write_text(header + rows)
    (tmp_path / "m.toml").write_text(
        '[cell]\nname = "t"\nprofile = "iema"\nbase_iri = "https://example.org/t/"\n'
        '[[source]]\npath = "ids.wri"\n[[source]]\npath = "a.tsv"\n'
    )
    findings = validate(cadkg.build(tmp_path / "m.toml"))
    assert [(f.location, f.severity, f.check) for f in findings] == [("a.tsv:3", "error", "shacl")]
    assert "must not start and end on the same pin" in findings[0].message
    assert findings[0].message.startswith("<https://example.org/t/wire/W2>")


def test_wire_ends_without_model_data_are_found() -> None:
    from tests.usecases.iema.test_services import MINI

    findings = [f for f in validate(cadkg.build(MINI), shacl=False) if f.check == "pin-without-data"]
    assert [(f.location, f.severity) for f in findings] == [("connections.tsv:5", "error")]
    assert "K9:1" in findings[0].message


@pytest.mark.parametrize("example", ["elvez-cell", "elimco-bench", "enki-hose", "vw-harness"])
def test_the_other_use_cases_validate_clean(example: str) -> None:
    kg = cadkg.build(ROOT / "examples" / example / "manifest.toml")
    assert [f for f in validate(kg) if f.severity == "error"] == []
    # Harness cables end at connector cavities: the cabinet derivation leaves them alone.
    assert not kg.ask("ASK { ?pin ck:missingPinData true }")


def test_wire_numbers_repeat_freely_across_harnesses(tmp_path: Path) -> None:
    def harness(name: str) -> str:
        return (
            f"harness {name}\nconnector X1 cavities=1-2\nconnector X2 cavities=1-2\n"
            "segment S1 X1 X2 length=100mm diameter=5mm\n"
            "wire 1 X1:1 X2:1 section=0.35 colour=RD length=0.2m\n"
        )

    (tmp_path / "a.harness").write_text(harness("A"))
    (tmp_path / "b.harness").write_text(harness("B"))
    (tmp_path / "m.toml").write_text(
        '[cell]\nname = "t"\nprofile = "vw"\nbase_iri = "https://example.org/t/"\n'
        '[[source]]\npath = "a.harness"\n[[source]]\npath = "b.harness"\n'
    )
    kg = cadkg.build(tmp_path / "m.toml")
    assert len(kg.query("SELECT ?w WHERE { ?w a ck:Wire ; ck:wireNumber '1' }")) == 2
    assert validate(kg) == []


CK = "https://w3id.org/cadkg#"


def _shapes_conform(data: bytes) -> tuple[bool, str]:
    import pyshacl
    import rdflib

    from cadkg.ontology.terms import ontology_path

    conforms, _, text = pyshacl.validate(
        rdflib.Graph().parse(data=data, format="nt"),
        shacl_graph=rdflib.Graph().parse(ontology_path("shapes.ttl"), format="turtle"),
        ont_graph=rdflib.Graph().parse(ontology_path("cadkg.ttl"), format="turtle"),
        inference="none",
        advanced=True,
    )
    return bool(conforms), str(text)


def test_the_derived_graph_conforms_to_the_shapes(iema: cadkg.KnowledgeGraph) -> None:
    # cadkg validate leaves the derived graph out; its poses, pins, clusters and routes are
    # checked here, together with the frames and pins of the graphs they refer to.
    derived = "https://example.org/cell/iema-qe01/derived"
    assert derived in iema.named_graphs()
    assert iema.construct(f"CONSTRUCT {{ ?s ?p ?o }} WHERE {{ GRAPH <{derived}> {{ ?s ?p ?o }} }}")
    conforms, text = _shapes_conform(iema.serialize("nt"))
    assert conforms, text


def test_validate_checks_what_the_files_say_not_the_derived_graph() -> None:
    kg = cadkg.build(ROOT / "examples" / "iema-switchgear" / "manifest.toml")
    base = "https://example.org/cell/iema-qe01/"
    # A pose with a second x, once in the derived graph and once in the scene's graph.
    pose = kg.query(
        f"SELECT ?pose WHERE {{ GRAPH <{base}derived> {{ ?pin ck:screwPose ?pose }} }} LIMIT 1"
    ).rows[0]["pose"]
    scene_pose = kg.query(
        f"SELECT ?pose WHERE {{ GRAPH <{base}graph/scene.x3d> {{ ?frame ck:hasPose ?pose }} }} LIMIT 1"
    ).rows[0]["pose"]
    bad = '"9.5"^^<http://www.w3.org/2001/XMLSchema#double>'
    # Straight into the store: an update through the graph would derive the graph again.
    kg._store.update(f"INSERT DATA {{ GRAPH <{base}derived> {{ <{pose}> <{CK}tx> {bad} }} }}")
    assert [f for f in validate(kg) if f.check == "shacl"] == []
    kg._store.update(f"INSERT DATA {{ GRAPH <{base}graph/scene.x3d> {{ <{scene_pose}> <{CK}tx> {bad} }} }}")
    shacl = [f for f in validate(kg) if f.check == "shacl"]
    assert [f.message.split(">")[0].lstrip("<") for f in shacl] == [scene_pose]
    assert "exactly one ck:tx" in shacl[0].message
