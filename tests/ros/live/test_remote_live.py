"""The node serving a cell from an external SPARQL store (Virtuoso), as it serves an embedded one.

scripts/virtuoso.sh starts a private Virtuoso on loopback (tests/remote installs it); the IEMA
example is built, pushed through the Graph Store Protocol, and the node is started on the
endpoint URL, with the credentials in CADKG_STORE_AUTH_DIGEST.
"""

from __future__ import annotations

import math
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from cadkg_interfaces import srv

from tests.remote.virtuoso import running_virtuoso
from tests.ros.live.conftest import ROOT, Server, wait_for

NAMESPACE = "/remote_iema"


@pytest.fixture(scope="module")
def remote_server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Server, Any]]:
    directory = tmp_path_factory.mktemp("virtuoso")
    with running_virtuoso(directory) as env:
        yield from _serve_pushed_store(tmp_path_factory, directory, env)


def _serve_pushed_store(
    tmp_path_factory: pytest.TempPathFactory, directory: Path, env: dict[str, str]
) -> Iterator[tuple[Server, Any]]:
    from cadkg.graph import KnowledgeGraph
    from cadkg.services.session import Session
    from cadkg.services.table import call

    credentials = f"{env['VIRTUOSO_USER']}:{env['VIRTUOSO_PASSWORD']}"
    store = tmp_path_factory.mktemp("iema") / "store"
    manifest = ROOT / "examples" / "iema-switchgear" / "manifest.toml"
    with KnowledgeGraph.build(manifest, store) as kg:
        expected = call(Session(kg.cell_model(), kg=kg), "cad_service", {"label": "F1500.1"})
    cli = Path(sys.prefix) / "bin" / "cadkg"
    pushed = subprocess.run(
        [str(cli), "push", str(store), "--endpoint", env["VIRTUOSO_SPARQL_AUTH"],
         "--graph-store", env["VIRTUOSO_GRAPH_STORE"], "--auth-digest", credentials],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert pushed.returncode == 0, pushed.stderr
    server = Server(
        env["VIRTUOSO_SPARQL_AUTH"],
        directory / "node.log",
        node_name="cadkg_remote",
        extra=["--namespace", NAMESPACE],
        env={"CADKG_STORE_AUTH_DIGEST": credentials},
    )
    try:
        yield server, expected
    finally:
        server.stop()


def test_cad_service_from_the_remote_store_equals_the_embedded_answer(
    ros: Any, remote_server: tuple[Server, Any]
) -> None:
    server, expected = remote_server
    client = ros.create_client(srv.CadService, f"{NAMESPACE}/cad_service")
    try:
        wait_for(ros, client.service_is_ready, 120.0, server)
        future = client.call_async(srv.CadService.Request(label="F1500.1"))
        wait_for(ros, future.done, 60.0, server)
    finally:
        ros.destroy_client(client)
    answer = future.result()
    assert answer.success
    for field in ("target_pose", "corner_pose", "original_pose"):
        got, want = getattr(answer, field), getattr(expected, field)
        position = (got.position.x, got.position.y, got.position.z)
        orientation = (got.orientation.x, got.orientation.y, got.orientation.z, got.orientation.w)
        actual, wanted = (*position, *orientation), (*want.position, *want.orientation)
        assert all(math.isclose(a, b, abs_tol=1e-12) for a, b in zip(actual, wanted, strict=True)), field
    assert sorted(p.pin for p in answer.pins) == sorted(p.pin for p in expected.pins)
