"""Slow and many clients against ``cadkg serve`` under a limit of 1,024 open files: half-sent
request heads, bodies that stall, idle connections, more connections than the bound. The served
cell keeps answering, no descriptor runs out, and the server closes what stalls."""

from __future__ import annotations

import random
import resource
import threading
import time
from pathlib import Path

import httpx
import pytest

from cadkg.errors import StoreError
from cadkg.server.connections import RESERVE, connection_bound
from tests.conftest import IEMA
from tests.server.serving import cadkg_serve_process
from tests.server.slow_clients import (
    DESCRIPTORS,
    WIRES,
    Client,
    answer_within,
    connect,
    follow,
    generated,
    own_descriptors,
)


@pytest.fixture(autouse=True)
def _client_descriptors() -> None:
    own_descriptors()


@pytest.mark.slow
def test_slow_clients_are_closed_and_the_cell_answers(tmp_path: Path) -> None:
    log = tmp_path / "serve.log"
    timeout = 4.0
    args = (str(IEMA), "--workers", "1", "--header-timeout", str(timeout))
    with cadkg_serve_process(*args, descriptors=DESCRIPTORS, log=log) as (base, _):
        port = int(base.rsplit(":", 1)[1])
        clients = generated(random.Random(1100), 1300)
        connect(port, clients)
        # A normal query asked meanwhile, while the tricklers trickle.
        waited: list[float] = []
        asking = threading.Thread(target=lambda: waited.append(answer_within(base, timeout + 20)))
        asking.start()
        follow(clients, time.monotonic() + timeout + 40)
        for client in clients:
            if client.closed_after is None and client.sock is not None:
                client.sock.close()
        asking.join(timeout + 30)
        assert waited and waited[0] < timeout + 20, waited
        assert httpx.get(f"{base}/sparql", params={"query": WIRES}, timeout=10).status_code == 200
    text = log.read_text()
    assert "Too many open files" not in text, text[-3000:]
    assert f"at most {DESCRIPTORS - RESERVE} connections open (of {DESCRIPTORS} descriptors" in text
    assert "Traceback" not in text, text[-3000:]

    assert all(client.closed_after is not None for client in clients), "the server left some open"
    refused = [c for c in clients if c.received.startswith(b"HTTP/1.1 503")]
    timed_out = [c for c in clients if c.received.endswith(b"no whole request head within 4 s")]
    stalled = [c for c in clients if c.received.endswith(b"the request body stalled for 4 s")]
    assert len(refused) + len(timed_out) + len(stalled) == len(clients), [
        c for c in clients if c not in refused + timed_out + stalled
    ][:5]
    assert {c.kind for c in stalled} == {"body"}
    assert {c.kind for c in timed_out} == {"idle", "line", "headers", "trickle", "pipelined"}
    # Closed by the timer, not before it: a trickling head's time is not renewed by its bytes.
    # (When it fired after the client's connect() is the kernel's: a burst past the accept queue
    # waits there, unseen by the server, until it is taken.)
    assert all((c.closed_after or 0) >= timeout - 0.5 for c in timed_out + stalled)
    assert all(c.received.startswith(b"HTTP/1.1 408") for c in timed_out + stalled if c.kind != "pipelined")
    assert all(c.received.startswith(b"HTTP/1.1 200") for c in timed_out if c.kind == "pipelined")


@pytest.mark.slow
def test_past_the_bound_a_request_gets_503_and_the_cell_recovers(tmp_path: Path) -> None:
    log = tmp_path / "serve.log"
    bound = DESCRIPTORS - RESERVE
    args = (str(IEMA), "--workers", "1", "--header-timeout", "60")
    with cadkg_serve_process(*args, descriptors=DESCRIPTORS, log=log) as (base, _):
        port = int(base.rsplit(":", 1)[1])
        clients = [Client("idle", b"") for _ in range(bound + 400)]
        connect(port, clients)
        try:
            # The ones past the bound are answered and closed as the server takes them.
            until = time.monotonic() + 40
            refused = [c for c in clients if c.received]
            while len(refused) < 400 and time.monotonic() < until:
                follow([c for c in clients if c.closed_after is None], min(until, time.monotonic() + 1))
                refused = [c for c in clients if c.closed_after is not None]
            assert len(refused) == 400
            assert all(c.received.startswith(b"HTTP/1.1 503") for c in refused)
            for _ in range(10):
                start = time.monotonic()
                response = httpx.get(f"{base}/sparql", params={"query": WIRES}, timeout=10)
                assert time.monotonic() - start < 5
                assert response.status_code == 503, response.text
                assert response.headers["retry-after"] == "1"
                assert response.text == "too many connections"
        finally:
            for client in clients:
                if client.sock is not None:
                    client.sock.close()
        assert answer_within(base, 10) < 10
    text = log.read_text()
    assert "Too many open files" not in text, text[-3000:]
    assert "Traceback" not in text, text[-3000:]


def test_the_bound_leaves_descriptors_for_the_rest() -> None:
    bound = connection_bound()
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    assert soft == hard or hard == resource.RLIM_INFINITY  # raised where allowed
    assert bound.descriptors == soft
    assert bound.connections == bound.descriptors - RESERVE
    assert connection_bound(50).connections == 50
    with pytest.raises(StoreError, match="fewer than 256"):
        connection_bound(bound.descriptors - RESERVE + 1)
