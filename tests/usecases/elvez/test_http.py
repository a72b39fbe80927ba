"""The ELVEZ services over HTTP: Table 2's and the CAD platform node's names side by side, the
sequence cursor per client, as cadkg call answers them."""

from __future__ import annotations

import json
from collections.abc import Iterator

import httpx
import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.server import Settings
from tests.cli import run
from tests.conftest import ROOT
from tests.server.serving import serving

TOKEN = "t0ken"
AUTH = {"Authorization": f"Bearer {TOKEN}"}

MANIFEST = ROOT / "examples" / "elvez-cell" / "manifest.toml"


@pytest.fixture(scope="module")
def url() -> Iterator[str]:
    kg = KnowledgeGraph.build(MANIFEST)
    # The sequence cursor moves by POST with the token, as every cursor over HTTP.
    with serving(kg, Settings(token=TOKEN, watch_seconds=0)) as base:
        yield base
    kg.close()


def test_both_guide_infos_by_their_names(url: str) -> None:
    names = {s["name"] for s in httpx.get(f"{url}/api").json()["services"]}
    assert {"guide_info", "CAD_platform.guide_info", "CAD_platform.next_operation"} <= names
    table2 = httpx.get(f"{url}/api/guide_info", params={"name": "J1"}).json()
    reference = httpx.get(f"{url}/api/CAD_platform.guide_info", params={"jig": "J1", "guide": "1"}).json()
    assert table2["key_frame"] == reference["data"]["key_center_frame"]
    cli = run("call", MANIFEST, "CAD_platform.guide_info", "jig=J1", "guide=1")
    assert cli.returncode == 0, cli.stderr
    assert json.loads(cli.stdout) == reference


def test_the_sequence_cursor_per_client(url: str) -> None:
    def step(client: str) -> str:
        answer = httpx.post(
            f"{url}/api/CAD_platform.next_operation", data={"client": client}, headers=AUTH
        ).json()
        return str(answer["type"])

    assert [step("left"), step("left"), step("right"), step("left")] == ["EC", "PC", "EC", "RC"]
    # index_operation moves the client's cursor too: by POST with the token only.
    assert httpx.get(f"{url}/api/CAD_platform.index_operation", params={"index": "1"}).status_code == 405
    missing = httpx.post(f"{url}/api/CAD_platform.index_operation", data={"client": "left"}, headers=AUTH)
    assert (missing.status_code, missing.json()) == (
        400,
        {"error": "CAD_platform.index_operation: missing parameter index"},
    )
