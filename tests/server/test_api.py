"""The JSON API: services as ``cadkg call`` answers them, named queries, the graph view, info."""

from __future__ import annotations

import json

import httpx

import cadkg
from cadkg.server import Settings
from tests.cli import run
from tests.conftest import IEMA
from tests.server.serving import serving

BASE = "https://example.org/cell/iema-qe01/"


def test_api_lists_services_and_queries(url: str) -> None:
    data = httpx.get(f"{url}/api").json()
    services = {s["name"]: s for s in data["services"]}
    assert services["cad_service"]["params"] == {"label": "str"}
    assert services["reset_to_connection_list"]["optional"] == ["connection_list", "source"]
    assert "wires-of-component" in data["queries"]
    endpoints = data["endpoints"]
    assert {"/api/cell", "/api/changes", "/api/info", "/api/plan"} <= set(endpoints.values())
    cell = httpx.get(f"{url}{endpoints['cell']}").json()
    assert cell["profile"] == "iema" and cell["name"] == "IEMA switchgear QE01"


def test_service_answers_as_cadkg_call(url: str) -> None:
    cli = run("call", IEMA, "cad_service", "label=F1500.1")
    assert cli.returncode == 0, cli.stderr
    response = httpx.get(f"{url}/api/cad_service", params={"label": "F1500.1"})
    assert response.status_code == 200
    assert response.headers["content-type"] == "application/json"
    assert response.json() == json.loads(cli.stdout)
    assert response.json()["success"] is True
    by_post = httpx.post(f"{url}/api/cad_service", json={"label": "F1500.1"})
    assert by_post.json() == response.json()


def test_service_errors(url: str) -> None:
    unknown = httpx.get(f"{url}/api/no_such_service")
    assert unknown.status_code == 404
    assert "cad_service" in unknown.json()["error"]
    missing = httpx.get(f"{url}/api/cad_service")
    assert missing.status_code == 400
    assert missing.json() == {"error": "cad_service: missing parameter label"}
    bad = httpx.get(f"{url}/api/get_item_screw_service", params={"label": "F1500.1", "detected_pose": "1,2"})
    assert bad.status_code == 400 and "not a pose" in bad.json()["error"]
    no_component = httpx.get(f"{url}/api/cad_service", params={"label": "NOPE"})
    assert no_component.status_code == 200
    assert no_component.json()["success"] is False


def test_cursors_are_kept_per_client(iema: cadkg.KnowledgeGraph) -> None:
    auth = {"Authorization": "Bearer t0ken"}
    with serving(iema, Settings(token="t0ken", watch_seconds=0)) as url:

        def next_wire(client: str) -> str:
            params = {"client": client}
            response = httpx.post(f"{url}/api/group_connection_provider", params=params, headers=auth)
            return str(response.json()["wire"])

        httpx.post(f"{url}/api/reset_connection_list", params={"client": "a"}, headers=auth)
        httpx.post(f"{url}/api/reset_connection_list", headers={**auth, "X-Cadkg-Client": "b"})
        first, second = next_wire("a"), next_wire("a")
        assert first != second
        assert next_wire("b") == first


def test_named_queries_listed_and_run(url: str) -> None:
    listed = {q["name"]: q for q in httpx.get(f"{url}/api/queries").json()}
    assert listed["wires-of-component"]["params"][0]["name"] == "label"
    assert listed["wires-of-component"]["text"].startswith("# wires-of-component:")
    response = httpx.get(f"{url}/api/queries/wires-of-component", params={"label": "F1500.1"})
    assert response.status_code == 200
    rows = response.json()["results"]["bindings"]
    # The wires of F1500.1 in lista-cablaggio.csv, in list order (rows 1, 4, 19-21, 44-46).
    assert [r["wireNumber"]["value"] for r in rows] == [
        "1500.51", "1500.50", "1500.01", "1500.02", "1500.03", "0010.03", "0010.04", "0010.05",
    ]  # fmt: skip
    assert rows[0]["otherEnd"]["value"] == "Q1500.1:A1"
    as_csv = httpx.get(f"{url}/api/queries/wire-endpoints", params={"wireNumber": "1500.51", "format": "csv"})
    assert as_csv.text.splitlines()[0] == "wireNumber,end,component,pinName,level,termination,wire"
    assert httpx.get(f"{url}/api/queries/wires-of-component").status_code == 400
    assert httpx.get(f"{url}/api/queries/nothing").status_code == 404


def test_graph_view_of_a_component(url: str) -> None:
    data = httpx.get(f"{url}/api/graph", params={"component": "F1500.1"}).json()
    assert data["center"] == f"{BASE}component/F1500.1"
    labels = {n["label"] for n in data["nodes"] if n["kind"] == "component"}
    assert labels == {"F1500.1", "Q1500.1", "X1600", "Q0010"}
    pins = {n["label"] for n in data["nodes"] if n["kind"] == "pin"}
    assert {"1", "2", "3", "4", "5", "6", "13", "14"} <= pins
    wires = {e["label"] for e in data["edges"] if e["kind"] == "wire"}
    assert "1500.51 → A1" in wires and "1500.50 → 2" in wires
    assert len(wires) == 8
    ids = {n["id"] for n in data["nodes"]}
    assert all(e["source"] in ids and e["target"] in ids for e in data["edges"])
    missing = httpx.get(f"{url}/api/graph", params={"component": "NOPE"})
    assert missing.status_code == 404


def test_graph_view_of_any_node(url: str) -> None:
    wire = f"{BASE}wire/1500.51"
    data = httpx.get(f"{url}/api/graph", params={"node": wire}).json()
    edges = {(e["source"], e["label"], e["target"]) for e in data["edges"]}
    assert (wire, "fromPin", f"{BASE}pin/F1500.1/14") in edges
    assert (wire, "toPin", f"{BASE}pin/Q1500.1/A1") in edges
    properties = {p["property"]: p["value"] for p in data["properties"]}
    assert properties["colour"] == "BU"
    assert properties["lengthM"] == "0.746"
    assert httpx.get(f"{url}/api/graph").status_code == 400


def test_info(url: str) -> None:
    data = httpx.get(f"{url}/api/info").json()
    assert f"{BASE}graph/lista-cablaggio.csv" in data["named_graphs"]
    assert data["update"] is False and data["token"] is False
    assert data["limits"]["max_rows"] == 10_000
    assert data["generation"].startswith("memory-")
    assert data["changes"] is False  # an in-memory graph without the token cannot change
