"""The endpoint as an attacker on loopback tries it: outbound requests through ``SERVICE`` and
``LOAD``, state changes without the token, web pages of other origins. Runaway queries are in
``test_runaway.py``."""

from __future__ import annotations

import re
import time
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest

import cadkg
from cadkg.server import Settings, create_app
from cadkg.services.service import Effect
from cadkg.services.table import SERVICES
from tests.conftest import EXAMPLES, ROOT
from tests.server.listener import Listener
from tests.server.serving import serving, serving_app

SRJ = "application/sparql-results+json"
TOKEN = "t0ken"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
ELIMCO = EXAMPLES / "elimco-bench" / "manifest.toml"


@pytest.fixture
def listener() -> Iterator[Listener]:
    with Listener() as listening:
        yield listening


def _federated(url: str) -> list[str]:
    """``SERVICE`` to ``url`` written every way pyoxigraph reads it."""
    base, _, tail = url.rpartition("/")
    host = base.removeprefix("http://")
    escaped = url.replace(":", "\\u003A", 2).replace("\\u003A", ":", 1)
    return [
        f"SELECT * WHERE {{ SERVICE <{url}> {{ ?s ?p ?o }} }}",
        f"select * where {{ service <{url}> {{ ?s ?p ?o }} }}",
        f"SELECT * WHERE {{ Service Silent <{url}> {{ ?s ?p ?o }} }}",
        "SELECT * WHERE { SERVICE SILENT ?e { ?s ?p ?o } }",
        f"SELECT * WHERE {{ VALUES ?e {{ <{url}> }} SERVICE ?e {{ ?s ?p ?o }} }}",
        f"PREFIX e: <http://{host}/> SELECT * WHERE {{ SERVICE e:{tail} {{ ?s ?p ?o }} }}",
        f"BASE <http://{host}/> SELECT * WHERE {{ SERVICE <{tail}> {{ ?s ?p ?o }} }}",
        f"SELECT * WHERE {{ SERVICE <{escaped}> {{ ?s ?p ?o }} }}",
        f"SELECT * WHERE {{ OPTIONAL {{ {{ SELECT * WHERE {{ SERVICE <{url}> {{ ?s ?p ?o }} }} }} }} }}",
        f"ASK {{ FILTER EXISTS {{ SERVICE <{url}> {{ ?s ?p ?o }} }} }}",
        f"SELECT * WHERE {{ # a comment\n SERVICE\t<{url}>{{?s ?p ?o}} }}",
    ]


def _one_line(text: str) -> str:
    lines = text.strip().splitlines()
    assert len(lines) == 1, text
    assert "Traceback" not in text
    return lines[0]


def test_service_is_refused_and_nothing_is_contacted(url: str, listener: Listener) -> None:
    for query in _federated(listener.url):
        for response in (
            httpx.get(f"{url}/sparql", params={"query": query}, headers={"Accept": SRJ}),
            httpx.post(f"{url}/sparql", data={"query": query}),
            httpx.post(f"{url}/sparql", content=query, headers={"Content-Type": "application/sparql-query"}),
        ):
            assert response.status_code == 400, (query, response.text)
            line = _one_line(response.text)
            assert "is refused: cadkg makes no outbound requests" in line, line
            assert "--allow-service" in line
    time.sleep(0.5)
    assert listener.connections == 0


def test_the_word_service_elsewhere_is_no_service(url: str) -> None:
    for query in (
        "SELECT ?n WHERE { ?w ck:wireNumber ?n FILTER(?n != 'SERVICE <http://127.0.0.1:1/>') } LIMIT 1",
        "SELECT ?n WHERE { # SERVICE <http://127.0.0.1:1/> { }\n ?w ck:wireNumber ?n } LIMIT 1",
        "PREFIX service: <urn:x:> SELECT ?service WHERE { ?service ck:wireNumber ?n } LIMIT 1",
    ):
        response = httpx.get(f"{url}/sparql", params={"query": query}, headers={"Accept": SRJ})
        assert response.status_code == 200, (query, response.text)


def test_load_is_refused_in_an_update(listener: Listener) -> None:
    kg = cadkg.KnowledgeGraph.memory()
    with serving(kg, Settings(allow_update=True, token=TOKEN, watch_seconds=0)) as base:
        for update in (f"LOAD <{listener.url}>", f"load silent <{listener.url}> INTO GRAPH <urn:g>"):
            response = httpx.post(f"{base}/sparql", data={"update": update}, headers=AUTH)
            assert response.status_code == 400
            assert "LOAD" in _one_line(response.text)
        where = f"SERVICE <{listener.url}> {{ ?s ?p ?o }}"
        insert = f"INSERT {{ GRAPH <urn:g> {{ ?s ?p ?o }} }} WHERE {{ {where} }}"
        assert httpx.post(f"{base}/sparql", data={"update": insert}, headers=AUTH).status_code == 400
    time.sleep(0.5)
    assert listener.connections == 0


def test_an_allowed_service_is_reached_and_only_it(iema: cadkg.KnowledgeGraph, listener: Listener) -> None:
    settings = Settings(allowed_services=(listener.url,), watch_seconds=0)
    with serving(iema, settings) as base:
        allowed = f"SELECT ?s WHERE {{ SERVICE <{listener.url}> {{ ?s ?p ?o }} }}"
        response = httpx.get(f"{base}/sparql", params={"query": allowed}, headers={"Accept": SRJ})
        assert response.status_code == 200, response.text
        assert response.json()["results"]["bindings"] == [{"s": {"type": "uri", "value": "urn:remote:1"}}]
        assert listener.connections == 1
        other = listener.url.replace("/sparql", "/other")
        for refused in (
            f"SELECT ?s WHERE {{ SERVICE <{other}> {{ ?s ?p ?o }} }}",
            "SELECT ?s WHERE { SERVICE ?e { ?s ?p ?o } }",
        ):
            response = httpx.get(f"{base}/sparql", params={"query": refused})
            assert response.status_code == 400
            assert "refused" in _one_line(response.text)
        time.sleep(0.5)
        assert listener.connections == 1


def test_a_failing_allowed_service_is_one_clean_line(iema: cadkg.KnowledgeGraph) -> None:
    with Listener(fail=True) as failing:
        with serving(iema, Settings(allowed_services=(failing.url,), watch_seconds=0)) as base:
            query = f"SELECT ?s WHERE {{ SERVICE <{failing.url}> {{ ?s ?p ?o }} }}"
            response = httpx.get(f"{base}/sparql", params={"query": query})
        assert failing.connections >= 1
    assert response.status_code == 502
    assert _one_line(response.text).startswith("the query failed: ")


# -- state changes ------------------------------------------------------------------------------


def _centroid(base: str) -> tuple[float, float, float]:
    data = httpx.get(f"{base}/api/get_pin_positions", params={"use_centroid": "true"}).json()
    position = data["centroid"]["position"]
    return position["x"], position["y"], position["z"]


def _moved_pins(directory: Path) -> Path:
    directory.mkdir(parents=True, exist_ok=True)
    text = (EXAMPLES / "elimco-bench" / "pin_info.xml").read_text(encoding="utf-8")
    moved = directory / "pin_info.xml"
    moved.write_text(text.replace('x="11680" y="3960"', 'x="99000" y="3960"'), encoding="utf-8")
    return moved


def test_load_files_on_a_read_only_endpoint_changes_nothing(tmp_path: Path) -> None:
    moved = _moved_pins(tmp_path)
    with serving(lambda: cadkg.build(ELIMCO), Settings(watch_seconds=0)) as base:
        before = _centroid(base)
        by_get = httpx.get(f"{base}/api/load_files", params={"paths": str(moved)})
        assert by_get.status_code == 405
        assert by_get.headers["allow"] == "POST"
        by_post = httpx.post(f"{base}/api/load_files", data={"paths": str(moved)})
        assert by_post.status_code == 403
        with_a_token = httpx.post(f"{base}/api/load_files", data={"paths": str(moved)}, headers=AUTH)
        assert with_a_token.status_code == 403
        assert "read-only" in with_a_token.json()["error"]
        assert _centroid(base) == before


def test_load_files_needs_the_token_and_reads_only_under_the_files_root(tmp_path: Path) -> None:
    root = tmp_path / "root"
    _moved_pins(root / "bench")
    (root / "outside").symlink_to(ROOT / "examples")
    outside = EXAMPLES / "elimco-bench" / "pin_info.xml"
    settings = Settings(allow_update=True, token=TOKEN, files_root=root, watch_seconds=0)

    def load(paths: str, headers: dict[str, str] = AUTH) -> httpx.Response:
        return httpx.post(f"{base}/api/load_files", json={"paths": paths}, headers=headers)

    with serving(lambda: cadkg.build(ELIMCO), settings) as base:
        before = _centroid(base)
        assert load("bench/pin_info.xml", {}).status_code == 401
        assert load("bench/pin_info.xml", {"Authorization": "Bearer nope"}).status_code == 401
        # Outside the root, a file that exists and one that does not get the same answer.
        refusals = {}
        for given in (
            str(outside),
            str(outside.with_name("no_such_file.xml")),
            "../../../../../../etc/passwd",
            "/etc/no_such_file",
            "outside/elimco-bench/pin_info.xml",
            "bench/pin_info.xml\x00.txt",
            f"bench/pin_info.xml,{outside}",
        ):
            response = load(given)
            assert response.status_code == 403, (given, response.text)
            refused = given.rsplit(",", 1)[-1]
            refusals[given] = response.json()["error"].replace(repr(refused), "PATH")
        assert set(refusals.values()) == {"PATH is not under the files root of this endpoint"}
        assert _centroid(base) == before
        loaded = load("bench/pin_info.xml")
        assert loaded.status_code == 200, loaded.text
        assert loaded.json()["success"] is True, loaded.json()
        after = _centroid(base)
        assert after[0] > before[0] + 10  # one pin 87 m further along x moves the centroid
        # Queries see the new file too: the workers were started again on the changed graph.
        query = "SELECT ?x WHERE { ?pin ck:label 'A918VC1A' ; ck:benchX ?x }"
        rows = httpx.get(f"{base}/sparql", params={"query": query}, headers={"Accept": SRJ}).json()
        assert [float(r["x"]["value"]) for r in rows["results"]["bindings"]] == [99000.0]


def test_without_a_files_root_load_files_is_refused(tmp_path: Path) -> None:
    moved = _moved_pins(tmp_path)
    settings = Settings(allow_update=True, token=TOKEN, watch_seconds=0)
    with serving(lambda: cadkg.build(ELIMCO), settings) as base:
        response = httpx.post(f"{base}/api/load_files", data={"paths": str(moved)}, headers=AUTH)
        assert response.status_code == 403
        assert "--files-root" in response.json()["error"]


def test_the_table_of_services_says_what_each_declares() -> None:
    documented = (ROOT / "docs" / "server.md").read_text(encoding="utf-8")
    effects = "|".join(e.value for e in Effect)
    table = dict(re.findall(rf"^\| `([\w.]+)` \| ({effects}) \|", documented, re.MULTILINE))
    assert table == {name: s.effect.value for name, s in SERVICES.items()}


def test_cursors_over_http_need_post_the_token_and_a_client(iema: cadkg.KnowledgeGraph) -> None:
    reset = "/api/reset_to_connection_list"
    with serving(iema) as base:
        assert httpx.get(f"{base}{reset}", params={"data": "3", "client": "a"}).status_code == 405
        refused = httpx.post(f"{base}{reset}", data={"data": "3", "client": "a"}, headers=AUTH)
        assert refused.status_code == 403
        assert "--token" in refused.json()["error"]
        assert httpx.post(f"{base}/api/group_connection_provider", data={"client": "a"}).status_code == 403
        assert httpx.get(f"{base}/api/cad_service", params={"label": "F1500.1"}).status_code == 200
    app = create_app(iema, Settings(token=TOKEN, watch_seconds=0))
    with serving_app(app) as base:
        assert httpx.post(f"{base}{reset}", data={"data": "3"}, headers=AUTH).status_code == 400
        assert httpx.post(f"{base}{reset}", data={"data": "3"}).status_code == 401
        for client in ("default", "robot"):
            moved = httpx.post(f"{base}{reset}", data={"data": "3", "client": client}, headers=AUTH)
            assert moved.status_code == 200 and moved.json()["success"] is True, moved.text
        # Kept as the HTTP caller's own: never the cursor another transport calls "default".
        cursors = app.app.state.endpoint.holder.current.session().dump()  # type: ignore[attr-defined]
        assert set(cursors["iema"]) == {"http:default", "http:robot"}


# -- other origins ------------------------------------------------------------------------------


def test_a_page_of_another_origin_is_refused(url: str) -> None:
    query = {"query": "ASK { ?s ?p ?o }"}
    evil = {"Origin": "http://evil.example"}
    assert httpx.post(f"{url}/reload", headers={**evil, **AUTH}).status_code == 403
    refused = httpx.get(f"{url}/sparql", params=query, headers=evil)
    assert refused.status_code == 403
    assert "--cors" in refused.text
    assert "access-control-allow-origin" not in refused.headers
    own = httpx.get(f"{url}/sparql", params=query, headers={"Origin": url})
    assert own.status_code == 200
    assert "access-control-allow-origin" not in own.headers
    assert httpx.get(f"{url}/sparql", params=query).headers.get("access-control-allow-origin") is None


def test_cors_opens_the_endpoint_to_a_named_origin(iema: cadkg.KnowledgeGraph) -> None:
    yasgui = "https://yasgui.example"
    with serving(iema, Settings(cors=(yasgui,), watch_seconds=0)) as base:
        query = {"query": "ASK { ?s ?p ?o }"}
        answered = httpx.get(f"{base}/sparql", params=query, headers={"Origin": yasgui, "Accept": SRJ})
        assert answered.status_code == 200
        assert answered.headers["access-control-allow-origin"] == yasgui
        assert "X-Cadkg-Generation" in answered.headers["access-control-expose-headers"]
        preflight = httpx.options(
            f"{base}/sparql",
            headers={
                "Origin": yasgui,
                "Access-Control-Request-Method": "POST",
                "Access-Control-Request-Headers": "content-type",
            },
        )
        assert preflight.status_code == 204
        assert preflight.headers["access-control-allow-origin"] == yasgui
        assert "POST" in preflight.headers["access-control-allow-methods"]
        assert "Content-Type" in preflight.headers["access-control-allow-headers"]
        form = httpx.post(f"{base}/sparql", data=query, headers={"Origin": yasgui, "Accept": SRJ})
        assert form.json()["boolean"] is True
        # Still read-only, and other origins still refused.
        assert httpx.post(f"{base}/reload", headers={"Origin": yasgui}).status_code == 403
        other = httpx.get(f"{base}/sparql", params=query, headers={"Origin": "https://elsewhere.example"})
        assert other.status_code == 403
