from __future__ import annotations

import csv
import io
import json
import shutil
from pathlib import Path

import networkx as nx
import pytest

from tests.cli import run
from tests.conftest import BAD, IEMA


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    target = tmp_path_factory.mktemp("cli") / "store"
    result = run("build", IEMA, "--store", target)
    assert result.returncode == 0, result.stderr
    assert "lista-cablaggio.csv" in result.stdout
    assert "connection-list" in result.stdout
    return target


def test_query_named_with_parameter_as_json(store: Path) -> None:
    result = run("query", store, "wire-endpoints", "wireNumber=1500.51", "--format", "rows-json")
    assert result.returncode == 0, result.stderr
    rows = json.loads(result.stdout)["rows"]
    assert [(r["end"], r["component"], r["pinName"]) for r in rows] == [
        ("origin", "F1500.1", "14"),
        ("destination", "Q1500.1", "A1"),
    ]


def test_query_sparql_text_as_csv(store: Path) -> None:
    result = run(
        "query", store, "SELECT (COUNT(DISTINCT ?w) AS ?n) WHERE { ?w a ck:Wire }", "--format", "csv"
    )
    assert result.returncode == 0, result.stderr
    assert list(csv.reader(io.StringIO(result.stdout))) == [["n"], ["110"]]


def test_query_a_manifest_directly_and_a_rq_file(tmp_path: Path) -> None:
    rq = tmp_path / "q.rq"
    rq.write_text("SELECT ?label WHERE { ?c a ck:Component ; ck:label ?label } ORDER BY ?label LIMIT 1")
    result = run("query", IEMA, rq, "--format", "csv")
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[1] == "1"  # the cabinet's root item (ids.wri line 1, =-1)


def test_table_output(store: Path) -> None:
    result = run("query", store, "pins-of-component", "label=X1600")
    assert result.returncode == 0
    assert "pinName" in result.stdout


def test_validate_exit_codes() -> None:
    good = run("validate", IEMA)
    assert good.returncode == 0, good.stdout + good.stderr
    bad = run("validate", BAD)
    assert bad.returncode == 1
    assert "connections.tsv:6: error" in bad.stdout
    assert "connections.tsv:9: error" in bad.stdout


def test_export_graphml_opens_with_networkx(store: Path, tmp_path: Path) -> None:
    out = tmp_path / "cell.graphml"
    result = run("export", store, "--format", "graphml", "-o", out)
    assert result.returncode == 0, result.stderr
    graph = nx.read_graphml(out)
    assert graph.nodes["https://example.org/cell/iema-qe01/component/F1500.1"]["type"] == "Component"


def test_export_turtle_by_suffix(store: Path, tmp_path: Path) -> None:
    out = tmp_path / "cell.ttl"
    assert run("export", store, "-o", out).returncode == 0
    assert "ck:wireNumber" in out.read_text()


def test_kinds_and_queries_list() -> None:
    kinds = run("kinds")
    assert "connection-list" in kinds.stdout and "wri" in kinds.stdout
    queries = run("queries")
    assert "wires-of-component" in queries.stdout


def test_input_error_is_one_line_without_traceback(tmp_path: Path) -> None:
    cell = tmp_path / "cell"
    shutil.copytree(IEMA.parent, cell)
    wri = cell / "ids.wri"
    wri.write_bytes(wri.read_bytes().replace(b"ID000041", b"41", 1))
    result = run("build", cell / "manifest.toml", "--store", tmp_path / "store")
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    lines = [line for line in result.stderr.splitlines() if line.strip()]
    assert len(lines) == 1
    assert "ids.wri:23: malformed CAD item ID (found '41'" in lines[0]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (("query", "nowhere", "components"), "neither a store directory nor a manifest"),
        (("query", str(IEMA), "wires-of-component"), "needs label"),
        (("query", str(IEMA), "SELECT ?x WHERE {"), "SPARQL syntax error"),
        (("query", str(IEMA), "not-a-query"), "not a named query"),
        (("query", str(IEMA), "components", "label"), "key=value"),
        (
            ("export", str(IEMA), "-o", "/nowhere/g.ttl"),
            "cadkg: error: /nowhere/g.ttl: No such file or directory",
        ),
    ],
)
def test_usage_errors_exit_2(args: tuple[str, ...], message: str) -> None:
    result = run(*args)
    assert result.returncode == 2
    assert message in result.stderr
    assert "Traceback" not in result.stderr


def test_unknown_manifest_key_names_key_and_line(tmp_path: Path) -> None:
    manifest = tmp_path / "m.toml"
    manifest.write_text('[cell]\nname = "x"\nprofile = "iema"\nbase_iri = "https://e.org/x/"\nkinds = 1\n')
    result = run("build", manifest, "--store", tmp_path / "s")
    assert result.returncode == 2
    assert "m.toml:5: unknown key 'kinds' in [cell]" in result.stderr
