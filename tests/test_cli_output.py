"""What the command line and the Python API hand back: exit status of ``cadkg call``, ``-o -``,
SPARQL 1.1 JSON results, numbers without float noise, data frames and notebook displays."""

from __future__ import annotations

import json
import re
from decimal import Decimal
from pathlib import Path

import networkx as nx
import pyoxigraph as ox

import cadkg
from cadkg.services.service import to_jsonable
from tests.cli import run
from tests.conftest import IEMA

WIRES = "SELECT ?n WHERE { ?w a ck:Wire ; ck:wireNumber ?n } ORDER BY ?n LIMIT 3"


def test_call_exits_1_when_the_answer_says_it_failed() -> None:
    failed = run("call", IEMA, "reset_to_connection_list", "data=99999")
    assert failed.returncode == 1
    assert json.loads(failed.stdout)["success"] is False  # the answer is printed all the same
    answered = run("call", IEMA, "reset_to_connection_list", "data=1500.51")
    assert answered.returncode == 0, answered.stderr
    assert json.loads(answered.stdout)["success"] is True


def test_output_dash_is_stdout_for_every_export(tmp_path: Path) -> None:
    turtle = run("export", IEMA, "--format", "ttl", "-o", "-")
    assert turtle.returncode == 0, turtle.stderr
    store = ox.Store()
    store.load(turtle.stdout.encode(), ox.RdfFormat.TURTLE)
    assert len(store) > 10_000
    graphml = run("export", IEMA, "--format", "graphml", "-o", "-")
    assert graphml.returncode == 0, graphml.stderr
    written = tmp_path / "cell.graphml"
    written.write_text(graphml.stdout, encoding="utf-8")
    assert nx.read_graphml(written).number_of_nodes() > 100
    assert not Path("-").exists()
    needs_format = run("export", IEMA, "-o", "-")
    assert needs_format.returncode == 2 and "give --format" in needs_format.stderr


def test_query_json_is_the_sparql_results_format() -> None:
    result = run("query", IEMA, WIRES, "--format", "json")
    assert result.returncode == 0, result.stderr
    answer = json.loads(result.stdout)
    assert answer["head"] == {"vars": ["n"]}
    bindings = answer["results"]["bindings"]
    assert [b["n"]["type"] for b in bindings] == ["literal"] * 3
    # The same rows as the plain shape, which stays available under its own name.
    plain = json.loads(run("query", IEMA, WIRES, "--format", "rows-json").stdout)
    assert [b["n"]["value"] for b in bindings] == [row["n"] for row in plain["rows"]]
    asked = json.loads(run("query", IEMA, "ASK { ?w a ck:Wire }", "--format", "json").stdout)
    assert asked["boolean"] is True


def test_answers_carry_no_float_noise() -> None:
    assert to_jsonable(0.1 + 0.106) == 0.206
    assert to_jsonable((0.1 + 0.2, 1e-14, 2.5), "Vec3") == {"x": 0.3, "y": 0.0, "z": 2.5}
    answer = run("call", IEMA, "cad_service", "label=F1500.1")
    assert answer.returncode == 0, answer.stderr
    assert re.findall(r"\d\.\d{13,}", answer.stdout) == []  # 17 digits before rounding


def test_decimal_columns_are_floats_in_a_data_frame(iema: cadkg.KnowledgeGraph) -> None:
    result = iema.named_query("wires-by-colour-section")
    frame = result.to_dataframe()
    assert frame["section"].dtype.kind == "f" and frame["totalLengthM"].dtype.kind == "f"
    assert "section" in frame.describe().columns
    exact = result.to_dataframe(keep_decimals=True)
    assert all(isinstance(v, Decimal) for v in exact["section"])


def test_results_and_graphs_show_themselves(iema: cadkg.KnowledgeGraph) -> None:
    result = iema.query(WIRES)
    html = result._repr_html_()
    assert html.startswith("<table>") and "<th>n</th>" in html and html.count("<tr>") == 4
    assert repr(result) == "QueryResult(variables=['n'], rows=3)"
    shown = repr(iema)
    assert shown.startswith("<KnowledgeGraph in memory: cell 'IEMA switchgear QE01' (iema), ")
    assert f"{len(iema)} triples" in shown
