"""``serve`` on a remote store: the served graph is a RemoteGraph reading another endpoint over
the SPARQL 1.1 Protocol (here a second cadkg endpoint serving the IEMA example)."""

from __future__ import annotations

import httpx
import pytest

import cadkg
from cadkg.remote import RemoteGraph
from tests.server.serving import serving

SRJ = "application/sparql-results+json"
WIRES = "SELECT (COUNT(DISTINCT ?w) AS ?n) WHERE { ?w a ck:Wire }"


@pytest.mark.slow
def test_serving_a_remote_store(iema: cadkg.KnowledgeGraph) -> None:
    with serving(iema) as upstream, serving(lambda: RemoteGraph(f"{upstream}/sparql")) as base:
        count = httpx.get(f"{base}/sparql", params={"query": WIRES}, headers={"Accept": SRJ}, timeout=60)
        assert count.status_code == 200, count.text
        assert count.json()["results"]["bindings"][0]["n"]["value"] == "110"
        near = f"{base}/api/queries/wires-of-component"
        here = httpx.get(near, params={"label": "F1500.1"}, timeout=60).json()["results"]["bindings"]
        there = httpx.get(
            f"{upstream}/api/queries/wires-of-component", params={"label": "F1500.1"}, timeout=60
        ).json()["results"]["bindings"]
        assert here == there and len(here) == 8
        dataset = httpx.get(
            f"{base}/sparql", params={"query": WIRES, "default-graph-uri": "urn:x"}, timeout=60
        )
        assert dataset.status_code == 400
        assert "not supported on a remote store" in dataset.text
        bad = httpx.get(f"{base}/sparql", params={"query": "SELECT ?x WHERE { ?x }"}, timeout=60)
        assert bad.status_code in (400, 502)
        assert httpx.post(f"{base}/sparql", data={"update": "CLEAR ALL"}).status_code == 403
        graph = httpx.get(f"{base}/api/graph", params={"component": "F1500.1"}, timeout=60).json()
        assert {n["label"] for n in graph["nodes"] if n["kind"] == "component"} == {
            "F1500.1", "Q1500.1", "X1600", "Q0010",
        }  # fmt: skip
