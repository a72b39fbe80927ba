"""``cadkg serve`` from the command line: what it refuses, and a real client against it."""

from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import httpx
import pytest

from tests.cli import run
from tests.conftest import IEMA
from tests.server.listener import Listener
from tests.server.serving import cadkg_serve, cadkg_serve_process


def test_refuses_a_non_loopback_host_unless_allowed() -> None:
    result = run("serve", IEMA, "--host", "0.0.0.0")
    assert result.returncode == 2
    assert "refusing to listen on 0.0.0.0" in result.stderr
    assert "--allow-non-loopback" in result.stderr
    assert "Traceback" not in result.stderr


def test_allow_update_needs_a_token() -> None:
    result = run("serve", IEMA, "--allow-update")
    assert result.returncode == 2
    assert "--allow-update needs --token" in result.stderr


@pytest.mark.skipif(shutil.which("curl") is None, reason="curl is not installed")
def test_serve_answers_curl() -> None:
    query = "query=SELECT DISTINCT ?n WHERE { ?w ck:wireNumber ?n } ORDER BY ?n"
    with cadkg_serve(str(IEMA), "--max-rows", "3") as base:
        command = ["curl", "-sS", "-D", "-", "-H", "Accept: application/sparql-results+json",
                   "--data-urlencode", query, f"{base}/sparql"]  # fmt: skip
        result = subprocess.run(command, capture_output=True, text=True, timeout=60, check=False)
    assert result.returncode == 0, result.stderr
    head, _, body = result.stdout.partition("\n\n")  # text mode: CRLF read as LF
    assert "x-cadkg-truncated: 3" in head.lower()
    numbers = [row["n"]["value"] for row in json.loads(body)["results"]["bindings"]]
    assert numbers == ["0010.01", "0010.02", "0010.03"]


def test_a_cors_origin_is_an_origin() -> None:
    result = run("serve", IEMA, "--cors", "https://yasgui.example/sparql")
    assert result.returncode == 2
    assert "is not a web origin" in result.stderr


def test_the_flags_that_open_the_endpoint_reach_it(tmp_path: Path) -> None:
    with Listener() as listener, cadkg_serve_process(
        str(IEMA), "--cors", "https://yasgui.example", "--allow-service", listener.url,
        "--files-root", str(tmp_path),
    ) as (base, _):  # fmt: skip
        query = {"query": f"SELECT ?s WHERE {{ SERVICE <{listener.url}> {{ ?s ?p ?o }} }}"}
        answered = httpx.get(f"{base}/sparql", params=query, headers={"Origin": "https://yasgui.example"})
        assert answered.status_code == 200, answered.text
        assert answered.headers["access-control-allow-origin"] == "https://yasgui.example"
        assert answered.json()["results"]["bindings"][0]["s"]["value"] == "urn:remote:1"
        # --files-root alone opens nothing: load_files still needs --allow-update and the token.
        assert httpx.post(f"{base}/api/load_files", data={"paths": "x.xml"}).status_code == 403
