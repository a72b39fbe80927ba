"""The routes behind the page's workbench, over a real server: completion terms, named queries
bound as shown, ``SELECT *`` columns, the favicon, the page without its bundle, the 3D scene of
every example (and of a remote store), the mesh files, and the token a writing service needs.

Expected values come from the examples' files: IEMA's ``ids.wri`` places 110 items with a mesh
(55 distinct boxes) and ``lista-cablaggio.csv`` has 110 wires; ``F1500.1`` has 8 wire ends;
ELVEZ's jigs and combs have 7 guides (``ELVEZ_GUIDES``) with a key and a key corner each,
and its sequence tapes at J1.1, J2.1 (operation 5) and J3.1 (operation 9); ELIMCO's
``pin_info.xml`` has 6 pins, one double, and ``path_info.xml`` 3 routes; the KBL has 31 nodes
and 30 segments.
"""

from __future__ import annotations

import struct
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

import cadkg
from cadkg.remote import RemoteGraph
from cadkg.server.columns import star_order
from cadkg.server.workbench import page
from cadkg.server.workbench.harness_layout import layout
from cadkg.services.session import Session
from cadkg.services.table import call
from tests.conftest import EXAMPLES
from tests.server.serving import serving

SRJ = "application/sparql-results+json"
ELVEZ_GUIDES = [("C1", 1), ("C2", 1), ("J1", 1), ("J2", 1), ("J3", 1), ("J3", 2), ("J4", 1)]
BASE = "https://example.org/cell/iema-qe01/"


@pytest.fixture(scope="module")
def scene(url: str) -> dict:
    response = httpx.get(f"{url}/api/scene", timeout=60)
    assert response.status_code == 200, response.text
    return response.json()


def test_completion_terms(url: str) -> None:
    terms = httpx.get(f"{url}/api/terms").json()
    assert terms["prefixes"]["cell"] == BASE == terms["base"]
    assert terms["prefixes"]["ck"] == "https://w3id.org/cadkg#"
    assert {"skos", "dcterms", "prov", "sh", "vec"} <= set(terms["prefixes"])
    classes = {t["iri"]: t for t in terms["classes"]}
    assert classes["https://w3id.org/cadkg#Wire"]["label"] == "wire"
    properties = {t["iri"]: t for t in terms["properties"]}
    assert properties["https://w3id.org/cadkg#wireNumber"]["kind"] == "datatype"
    assert properties["https://w3id.org/cadkg#fromPin"]["kind"] == "object"
    assert len(terms["components"]) == 63 and "F1500.1" in terms["components"]  # with the root `1`
    assert terms["components"] == sorted(terms["components"])


def test_a_named_query_keeps_its_parameter_when_its_text_is_edited(url: str) -> None:
    bound = httpx.get(f"{url}/api/queries/wires-of-component/bound", params={"label": "F1500.1"}).json()
    assert bound["values"] == 'VALUES (?label) { ("F1500.1") }'
    assert bound["values"] in bound["text"]
    named = httpx.get(f"{url}/api/queries/wires-of-component", params={"label": "F1500.1"}).json()
    edited = bound["text"].replace("SELECT DISTINCT", "SELECT  DISTINCT")  # a space added
    rows = httpx.post(f"{url}/sparql", data={"query": edited}, headers={"Accept": SRJ}).json()
    assert len(rows["results"]["bindings"]) == 8
    assert rows == named
    # The text alone, as a page without the VALUES block sent it, matches every component.
    text = httpx.get(f"{url}/api/queries").json()
    plain = next(q["text"] for q in text if q["name"] == "wires-of-component")
    unbound = httpx.post(f"{url}/sparql", data={"query": plain}, headers={"Accept": SRJ}).json()
    assert len(unbound["results"]["bindings"]) == 220
    assert httpx.get(f"{url}/api/queries/nothing/bound").status_code == 404
    assert httpx.get(f"{url}/api/queries/wires-of-component/bound").status_code == 400


def test_select_star_columns_come_in_the_order_of_the_query(url: str) -> None:
    query = "SELECT * WHERE { ?s ck:wireNumber ?number . ?s a ?class } LIMIT 2"
    data = httpx.get(f"{url}/sparql", params={"query": query}, headers={"Accept": SRJ}).json()
    assert data["head"]["vars"] == ["s", "number", "class"]
    assert set(data["results"]["bindings"][0]) == {"s", "number", "class"}
    csv = httpx.get(f"{url}/sparql", params={"query": query, "format": "csv"}).text
    assert csv.splitlines()[0] == "s,number,class"
    assert star_order("PREFIX a: <x:> SELECT DISTINCT * { ?z ?y ?x }") == ["z", "y", "x"]
    assert star_order("SELECT ?x (COUNT(*) AS ?n) WHERE { ?x ?p ?o } GROUP BY ?x") is None
    assert star_order('# SELECT * \nASK { ?a ?b "?c" }') is None
    assert star_order('SELECT * WHERE { ?b ?a "?c" . # ?d\n ?e ?a ?b }') == ["b", "a", "e"]


def test_favicon(url: str) -> None:
    icon = httpx.get(f"{url}/favicon.ico")
    assert icon.status_code == 200 and icon.headers["content-type"] == "image/x-icon"
    assert icon.content[:4] == b"\x00\x00\x01\x00"  # an ICO header


def test_a_page_without_its_bundle_says_how_to_build_it(
    url: str, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setattr(page, "DIST", tmp_path)
    response = httpx.get(f"{url}/")
    assert response.status_code == 503
    assert "bash scripts/setup.sh" in response.text and str(tmp_path) in response.text
    assert page.bundle_missing() is not None
    assert httpx.get(f"{url}/sparql", params={"query": "ASK {}"}).status_code == 200


def test_iema_scene(scene: dict) -> None:
    assert scene["profile"] == "iema" and scene["problems"] == []
    frames = {f["name"]: f for f in scene["frames"]}
    assert frames["cabinet"]["parent"] == "world"
    assert len(scene["objects"]) == 117 and len(scene["meshes"]) == 56
    assert all(o["frame"] in frames and o["mesh"] is not None for o in scene["objects"])
    components = {c["label"]: c for c in scene["components"]}
    fuse = components["F1500.1"]
    assert fuse["iri"] == f"{BASE}component/F1500.1" and fuse["frame"] == "cabinet"
    items = {scene["objects"][i]["iri"] for i in fuse["objects"]}
    assert items == {f"{BASE}item/ID000045", f"{BASE}item/ID000046"}
    routes = {r["iri"]: r for r in scene["routes"]}
    assert len(routes) == len(scene["routes"]) == 110  # three wires numbered 0V, one IRI each
    first = routes[f"{BASE}wire/1500.51"]
    assert first["label"] == "1500.51" and first["frame"] == "cabinet"
    # group_connection_provider's keypoints of the same wire: hole, duct CN2 twice, hole.
    keypoints = [0.1195, 0.565, 0.0595, 0.1195, 0.73, 0.03, 0.283, 0.73, 0.03, 0.283, 0.605, 0.0545]
    assert first["points"] == keypoints


def test_meshes_stream_as_binary_stl(url: str, scene: dict) -> None:
    entry = scene["meshes"][0]
    response = httpx.get(f"{url}/api/mesh/{entry['path']}")
    assert response.status_code == 200 and response.headers["content-type"] == "model/stl"
    (triangles,) = struct.unpack_from("<I", response.content, 80)
    assert len(response.content) == entry["bytes"] == 84 + 50 * triangles and triangles == 12
    assert "immutable" in response.headers["cache-control"]
    for bad in (
        "../manifest.toml",
        "meshes/../../x.stl",
        "meshes/ID000012.stl.txt",
        "nothing.stl",
        "%2F..%2Fx.stl",
    ):
        assert httpx.get(f"{url}/api/mesh/{bad}").status_code == 404, bad


def test_a_writing_service_needs_the_token(url: str) -> None:
    # Never by GET, which a page elsewhere can make; on a read-only endpoint not at all.
    assert httpx.get(f"{url}/api/load_files", params={"paths": "/etc/hostname"}).status_code == 405
    response = httpx.post(f"{url}/api/load_files", data={"paths": "/etc/hostname"})
    assert response.status_code == 403
    assert "read-only" in response.json()["error"]


def test_elvez_scene(elvez: cadkg.KnowledgeGraph) -> None:
    with serving(elvez) as base:
        scene = httpx.get(f"{base}/api/scene", timeout=60).json()
    assert scene["profile"] == "elvez" and scene["problems"] == []
    frames = {f["name"] for f in scene["frames"]}
    assert all(point["frame"] in frames for point in scene["points"])
    # The real ELVEZ files' elements, each at its platform's frame with its mesh.
    labels = [o["label"] for o in scene["objects"]]
    assert {"J1", "J2", "J3", "J4", "C1", "C2", "B1", "T1", "T2", "Agun", "Agripper"} <= set(labels)
    assert all(o["frame"] in frames for o in scene["objects"])
    assert len(scene["meshes"]) == 11
    # Every guide's key centre and key corner, where jig_info puts them (in robot_base).
    points = {(p["kind"], p["label"]): p for p in scene["points"]}
    keys = sorted(label for kind, label in points if kind == "key")
    assert keys == [f"{g} guide {n}" for g, n in ELVEZ_GUIDES]
    assert len([kind for kind, _ in points if kind == "key-corner"]) == len(ELVEZ_GUIDES)
    jig = call(Session(elvez.cell_model(), kg=elvez), "CAD_platform.jig_info", {"jig": "J3"})
    key = jig.guides[1].key_center_frame.position  # (x, y, z)
    at = points[("key", "J3 guide 2")]
    assert at["frame"] == "robot_base" and at["position"] == pytest.approx(list(key), abs=1e-9)
    # Taped at J1.1 and J2.1 (operation 5: no taping spot there, so at the guide's key) and at
    # J3.1 (operation 9: J3's taping spot 1, whose centre is not a key).
    spots = {label: p for (kind, label), p in points.items() if kind == "tape-spot"}
    assert sorted(spots) == [
        "J1.1: taping (operation 5)",
        "J2.1: taping (operation 5)",
        "J3.1: taping (operation 9)",
    ]
    assert spots["J1.1: taping (operation 5)"]["position"] == points[("key", "J1 guide 1")]["position"]
    centre = jig.taping_spots[0].center_frame.position
    assert spots["J3.1: taping (operation 9)"]["position"] == pytest.approx(list(centre), abs=1e-9)
    assert all(
        p["position"] not in [k["position"] for k in points.values() if k["kind"] == "key"]
        for label, p in spots.items()
        if label.startswith("J3")
    )
    # Each cable of wh_routes through the keys of its guides: CA1 over J1.1, J2.1, J3.1.
    routes = {r["label"]: r for r in scene["routes"]}
    assert sorted(routes) == [f"CA{n}" for n in range(1, 8)]
    via = [points[("key", f"{g} guide 1")]["position"] for g in ("J1", "J2", "J3")]
    assert routes["CA1"]["frame"] == "robot_base" and routes["CA1"]["points"] == [v for p in via for v in p]


def test_a_harness_is_drawn_at_the_coordinates_the_graph_gives() -> None:
    vw = cadkg.build(EXAMPLES / "vw-harness" / "manifest.toml")
    # Node positions as the graph would state them: a pose per node (an update's WHERE reads the
    # store's default graph, not the union, hence GRAPH ?g).
    vw.execute(
        """INSERT { GRAPH <urn:test:coordinates> {
             ?node ck:hasPose ?pose . ?pose a ck:Pose ; ck:tx ?x ; ck:ty 0.5 ; ck:tz 0.25 ;
               ck:qx 0.0 ; ck:qy 0.0 ; ck:qz 0.0 ; ck:qw 1.0 } }
           WHERE { GRAPH ?g { ?node a ck:HarnessNode }
             BIND(IRI(CONCAT(STR(?node), "/pose")) AS ?pose) BIND(STRLEN(STR(?node)) / 100.0 AS ?x) }""",
        update=True,
    )
    with serving(vw) as base:
        scene = httpx.get(f"{base}/api/scene", timeout=60).json()
    for harness in scene["harnesses"]:
        assert harness["coordinates"] == "graph"
        for node in harness["nodes"]:
            assert node["position"] == [round(len(node["iri"]) / 100, 6), 0.5, 0.25]


def test_harness_layout_keeps_segment_lengths_of_a_tree() -> None:
    # A Y: a trunk of 1 m, two branches of 0.5 m.
    points = layout(4, [(0, 1, 1.0), (1, 2, 0.5), (1, 3, 0.5)])
    assert points == layout(4, [(0, 1, 1.0), (1, 2, 0.5), (1, 3, 0.5)])

    def distance(a: int, b: int) -> float:
        return float(((points[a][0] - points[b][0]) ** 2 + (points[a][1] - points[b][1]) ** 2) ** 0.5)

    assert distance(0, 1) == pytest.approx(1.0, abs=0.15)
    assert distance(1, 2) == pytest.approx(0.5, abs=0.15)
    assert distance(2, 3) > 0.5
    apart = layout(3, [(0, 1, 1.0)])  # node 2 alone: beside the rest, not on it
    assert min(abs(apart[2][0] - p[0]) for p in apart[:2]) > 0.1


@pytest.fixture(scope="module")
def remote(iema: cadkg.KnowledgeGraph) -> Iterator[tuple[str, str]]:
    with serving(iema) as upstream, serving(lambda: RemoteGraph(f"{upstream}/sparql")) as base:
        yield upstream, base


def test_the_workbench_routes_on_a_remote_store(remote: tuple[str, str], scene: dict) -> None:
    upstream, base = remote
    here = httpx.get(f"{base}/api/terms", timeout=60).json()
    assert here == httpx.get(f"{upstream}/api/terms", timeout=60).json()
    far = httpx.get(f"{base}/api/scene", timeout=120).json()
    # The same cell, frames, routes and components; no mesh files, so every item is a box.
    assert far["frames"] == scene["frames"] and far["routes"] == scene["routes"]
    assert far["components"] == scene["components"]
    assert far["meshes"] == [] and len(far["objects"]) == 117
    assert all(o["box"] and o["mesh"] is None for o in far["objects"])
    assert "drawn as boxes" in far["problems"][0]
    assert httpx.get(f"{base}/api/mesh/meshes/ID000012.stl").status_code == 404


def test_the_cell_and_whose_queries(url: str) -> None:
    cell = httpx.get(f"{url}/api/cell").json()
    assert cell["name"] == "IEMA switchgear QE01" and cell["profile"] == "iema"
    assert cell["title"].startswith("switchgear cabinet wiring")
    queries = cell["queries"]
    assert queries["connections-in-order"] == "iema" and queries["elvez-plan"] == "elvez"
    assert queries["wires-of-component"] == "" and queries["harness-segment-lengths"] == "vw"
    assert set(queries) == {q["name"] for q in httpx.get(f"{url}/api/queries").json()}


def test_wires_carry_their_colour(scene: dict) -> None:
    # lista-cablaggio.csv: every wire has a colour code, seven of them in all.
    colours = [route.get("colour") for route in scene["routes"]]
    assert None not in colours and set(colours) == {"BK", "BN", "BU", "GNYE", "GY", "RD", "WH"}
    first = next(r for r in scene["routes"] if r["label"] == "1500.51")
    assert first["colour"] == "BU"
