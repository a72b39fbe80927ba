"""Compression and cache headers over a real server: the hashed bundle files kept a year, the
page asked again on every visit, JSON and SPARQL answers tagged and answered ``304`` while the
graph is unchanged, and a new tag once an update changed it."""

from __future__ import annotations

import re

import httpx
import pytest

import cadkg
from cadkg.server import Settings
from cadkg.server.caching import ASSETS_CACHE
from cadkg.server.workbench import page
from tests.conftest import EXAMPLES
from tests.server.serving import serving

TOKEN = "caching-test-token"


def _sent_bytes(url: str) -> int:
    """How many bytes a gzip-accepting client receives for ``url`` (still compressed)."""
    with httpx.stream("GET", url, headers={"accept-encoding": "gzip"}) as response:
        assert response.headers["content-encoding"] == "gzip"
        return sum(len(chunk) for chunk in response.iter_raw())


def _assets(html: str) -> list[str]:
    return re.findall(r'(?:src|href)="(/static/dist/assets/[^"]+)"', html)


@pytest.mark.skipif(page.bundle_missing() is not None, reason="the web page is not built")
def test_the_page_is_revalidated_and_its_hashed_files_kept_a_year(url: str) -> None:
    front = httpx.get(f"{url}/", headers={"accept-encoding": "gzip"})
    assert front.status_code == 200 and front.headers["cache-control"] == "no-cache"
    assets = _assets(front.text)
    assert any(a.endswith(".js") for a in assets) and any(a.endswith(".css") for a in assets)
    for asset in assets:
        plain = httpx.get(f"{url}{asset}", headers={"accept-encoding": "identity"})
        packed = httpx.get(f"{url}{asset}", headers={"accept-encoding": "gzip"})
        assert plain.headers["cache-control"] == ASSETS_CACHE == packed.headers["cache-control"]
        assert "content-encoding" not in plain.headers
        assert packed.headers["content-encoding"] == "gzip"
        assert packed.content == plain.content  # httpx undoes the gzip
        assert _sent_bytes(f"{url}{asset}") < len(plain.content) / 2
    missing = httpx.get(f"{url}/static/dist/assets/no-such-file.js")
    assert missing.status_code == 404 and "immutable" not in missing.headers.get("cache-control", "")


def test_an_unchanged_answer_is_not_sent_again(url: str) -> None:
    for path, params in [
        ("/api/scene", {}),
        ("/api/terms", {}),
        ("/api/queries/wires-of-component", {"label": "F1500.1"}),
        ("/api/graph", {"component": "F1500.1"}),
        ("/sparql", {"query": "SELECT (COUNT(*) AS ?n) WHERE { ?s ?p ?o }"}),
    ]:
        first = httpx.get(f"{url}{path}", params=params, headers={"accept-encoding": "gzip"})
        assert first.status_code == 200, (path, first.text)
        etag = first.headers["etag"]
        assert etag.startswith('W/"') and first.headers["x-cadkg-generation"] in etag
        assert first.headers["cache-control"] == "no-cache"
        again = httpx.get(f"{url}{path}", params=params, headers={"if-none-match": etag})
        assert again.status_code == 304 and again.content == b"", path
        assert again.headers["etag"] == etag
        other = httpx.get(f"{url}{path}", params=params, headers={"if-none-match": 'W/"else"'})
        assert other.status_code == 200 and other.headers["etag"] == etag
        assert other.content == first.content


def test_errors_and_large_json_answers(url: str) -> None:
    wrong = httpx.get(f"{url}/api/graph", params={"component": "no-such-label"})
    assert wrong.status_code == 404 and "etag" not in wrong.headers
    scene = httpx.get(f"{url}/api/scene", headers={"accept-encoding": "identity"})
    assert "content-encoding" not in scene.headers
    assert _sent_bytes(f"{url}/api/scene") < len(scene.content) / 3


def test_an_update_gives_answers_a_new_tag() -> None:
    graph = cadkg.build(EXAMPLES / "elvez-cell" / "manifest.toml")
    settings = Settings(allow_update=True, token=TOKEN, watch_seconds=0)
    count = {"query": "SELECT (COUNT(*) AS ?n) WHERE { ?s ?p ?o }"}
    with serving(graph, settings) as base:
        before = httpx.get(f"{base}/sparql", params=count)
        etag = before.headers["etag"]
        update = httpx.post(
            f"{base}/sparql",
            data={"update": "INSERT DATA { <urn:x:a> <urn:x:b> 1 }"},
            headers={"authorization": f"Bearer {TOKEN}"},
        )
        assert update.status_code in (200, 204), update.text
        after = httpx.get(f"{base}/sparql", params=count, headers={"if-none-match": etag})
        assert after.status_code == 200 and after.headers["etag"] != etag
        assert after.content != before.content
