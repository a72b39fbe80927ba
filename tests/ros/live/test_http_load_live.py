"""The ROS node keeps serving while ``cadkg serve`` on the same store is under load: hundreds of
half-sent and idle connections (generated as the endpoint's own slow-client tests make them,
under a limit of 1,024 open files) and clients asking queries that run to the server's time
limit on every worker. Every ROS call is answered, with the answer it gave before the load."""

from __future__ import annotations

import json
import random
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Any

import httpx
from cadkg_interfaces import srv

from tests.ros.live.conftest import MINI, Server, answer
from tests.server.serving import cadkg_serve_process
from tests.server.slow_clients import DESCRIPTORS, answer_within, connect, follow, generated, own_descriptors

SLOW_CLIENTS = 700


def xyz(point: Any) -> tuple[float, float, float]:
    return (point.x, point.y, point.z)


# Runs until the server's time limit stops it: the mini cell's triples, three times over.
RUNAWAY = "SELECT (COUNT(*) AS ?n) WHERE { ?a ?b ?c . ?d ?e ?f . ?g ?h ?i }"
CALLS = 40
# How long the node is asked while the server is loaded: several of the runaways' time limits.
LOADED_SECONDS = 12.0
# Each call has this long (a loaded 2-core machine; a call takes milliseconds when idle).
CALL_SECONDS = 20.0


def _runaways(base: str, stop: threading.Event, statuses: list[int]) -> None:
    while not stop.is_set():
        try:
            response = httpx.get(f"{base}/sparql", params={"query": RUNAWAY}, timeout=30)
            statuses.append(response.status_code)
        except httpx.TransportError:
            statuses.append(0)


def _answer(response: Any) -> tuple[Any, ...]:
    """What a cad_service answer says: its outcome, the target position and the pins' screws."""
    target = response.target_pose.position
    screws = sorted(
        (p.pin, p.screw.position.x, p.screw.position.y, p.screw.position.z) for p in response.pins
    )
    return (response.success, response.message, target.x, target.y, target.z, tuple(screws))


def test_the_node_answers_while_http_is_under_load(tmp_path: Path, ros: Any) -> None:
    own_descriptors()
    store = tmp_path / "store"
    subprocess.run(
        [sys.executable, "-m", "cadkg.cli", "build", str(MINI / "manifest.toml"), "--store", str(store)],
        check=True,
        capture_output=True,
        timeout=300,
    )
    node = Server(
        store, tmp_path / "node.log", node_name="cadkg_under_load", extra=["--namespace", "/loaded"]
    )
    log = tmp_path / "serve.log"
    args = (str(store), "--workers", "2", "--timeout", "3", "--header-timeout", "4")
    try:
        client = ros.create_client(srv.CadService, "/loaded/cad_service")
        request = srv.CadService.Request(label="K1")
        before = _answer(answer(ros, client, request, 120.0, node))
        assert before[0] and len(before[5]) == 3, before
        with cadkg_serve_process(*args, descriptors=DESCRIPTORS, log=log) as (base, _):
            port = int(base.rsplit(":", 1)[1])
            slow = generated(random.Random(43), SLOW_CLIENTS)
            connect(port, slow)
            stop, statuses = threading.Event(), []
            loaders = [threading.Thread(target=_runaways, args=(base, stop, statuses)) for _ in range(3)]
            for thread in loaders:
                thread.start()
            following = threading.Thread(target=follow, args=(slow, time.monotonic() + 60))
            following.start()
            try:
                waits: list[float] = []
                until = time.monotonic() + LOADED_SECONDS
                while len(waits) < CALLS or time.monotonic() < until:
                    start = time.monotonic()
                    got = _answer(answer(ros, client, request, CALL_SECONDS, node, fresh=False))
                    waits.append(time.monotonic() - start)
                    assert got == before
                sparql = ros.create_client(srv.Sparql, "/loaded/sparql")
                ask = srv.Sparql.Request(query="ASK { ?w a ck:Wire }", format="json")
                counted = answer(ros, sparql, ask, 60.0, node)
                assert counted.success and json.loads(counted.result)["boolean"] is True, counted
            finally:
                stop.set()
                for thread in loaders:
                    thread.join(60)
                following.join(90)
                for one in slow:
                    if one.sock is not None and one.closed_after is None:
                        one.sock.close()
            # The HTTP side was loaded for real: its runaways ran to their limit, and it answers.
            assert statuses and set(statuses) <= {503, 200, 0} and statuses.count(503) >= 3, statuses[:20]
            assert answer_within(base, 30) < 30
        assert max(waits) < CALL_SECONDS
        assert all(one.closed_after is not None for one in slow), "the server left slow clients open"
        text = log.read_text()
        assert "Too many open files" not in text and "Traceback" not in text, text[-3000:]
    finally:
        node.stop()
