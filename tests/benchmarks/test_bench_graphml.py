"""The synthetic harness generator and benchmarks/bench_graphml.py, end to end at small sizes."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import networkx as nx
import pytest

import cadkg
from cadkg.usecases.vw.graphml import harness_graph, write_harness_graphml
from tests.conftest import ROOT

sys.path.insert(0, str(ROOT / "benchmarks"))
import synthetic_harness

# A benchmark's smoke run: the script itself, at a size, in a new interpreter.
pytestmark = pytest.mark.slow


def test_synthetic_harness_builds_into_both_views(tmp_path: Path) -> None:
    written = synthetic_harness.write_harness(tmp_path, 400, seed=1)
    kg = cadkg.build(written.manifest)
    topology = harness_graph(kg, "topology")
    assert (topology.number_of_nodes(), topology.number_of_edges()) == (written.nodes, written.segments)
    assert nx.is_tree(nx.Graph(topology))
    assert sum(d["kind"] == "connector" for _, d in topology.nodes(data=True)) == written.connectors
    assert all({"x", "y", "z"} <= set(d) for _, d in topology.nodes(data=True))
    wires = harness_graph(kg, "wires")
    assert wires.number_of_edges() == written.wires == 400
    assert sum(1 for _, _, d in wires.edges(data=True) if "cable" in d) == 2 * written.cables
    # What the streaming writer wrote is what networkx reads back.
    for view, graph in (("topology", topology), ("wires", wires)):
        path = write_harness_graphml(kg, tmp_path / f"{view}.graphml", view)
        read = nx.read_graphml(tmp_path / f"{view}.graphml", force_multigraph=True)
        assert path.nodes and dict(read.nodes(data=True)) == dict(graph.nodes(data=True))
        assert sorted(read.edges(keys=True, data=True)) == sorted(
            (min(u, v), max(u, v), k, d) for u, v, k, d in graph.edges(keys=True, data=True)
        )
    again = tmp_path / "again"
    synthetic_harness.write_harness(again, 400, seed=1)
    assert (again / "harness.harness").read_bytes() == (tmp_path / "harness.harness").read_bytes()


def test_bench_graphml_prints_both_views_and_the_baseline() -> None:
    result = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "bench_graphml.py"), "--quick"],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert result.returncode == 0, result.stderr
    rows = [line.split() for line in result.stdout.splitlines() if line.lstrip().startswith("2,000")]
    assert [row[1] for row in rows] == ["topology", "wires", "both"]
    for row in rows:
        ratio = next(i for i, token in enumerate(row) if token.endswith("x"))  # networkx / cadkg
        assert float(row[ratio][:-1]) > 0 and float(row[ratio + 1]) > 0  # export / build
