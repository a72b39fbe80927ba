"""Slow and many clients against ``cadkg serve`` under a limit of 1,024 open files: half-sent
request heads, bodies that stall, idle connections, more connections than the bound. The served
cell keeps answering, no descriptor runs out, and the server closes what stalls."""

from __future__ import annotations

import contextlib
import random
import resource
import selectors
import socket
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path

import httpx
import pytest

from cadkg.errors import StoreError
from cadkg.server.connections import RESERVE, connection_bound
from tests.conftest import IEMA
from tests.server.serving import cadkg_serve_process

DESCRIPTORS = 1024
WIRES = "SELECT (COUNT(DISTINCT ?w) AS ?n) WHERE { ?w a ck:Wire }"
HEAD = (
    "GET /sparql?query=ASK%7B%7D HTTP/1.1\r\nHost: 127.0.0.1\r\nAccept: application/sparql-results+json\r\n"
    "User-Agent: slow-client\r\n\r\n"
)
QUERY = "ASK {}"
POST = (
    "POST /sparql HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/sparql-query\r\n"
    "Content-Length: {length}\r\n\r\n"
)


@pytest.fixture(autouse=True)
def _client_descriptors() -> None:
    """The test's own end of the connections needs descriptors too."""
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if hard != resource.RLIM_INFINITY and hard < 4096:
        pytest.skip(f"the test opens over 1,500 sockets; the hard limit of open files is {hard}")
    if soft != resource.RLIM_INFINITY and soft < 4096:
        resource.setrlimit(resource.RLIMIT_NOFILE, (min(hard, 8192), hard))


@dataclass
class Client:
    """One slow client: what it sends at once, what it trickles later, what it got back."""

    kind: str
    sent: bytes
    trickle: bytes = b""
    sock: socket.socket | None = None
    received: bytes = b""
    closed_after: float | None = None
    opened: float = field(default_factory=time.monotonic)


def generated(rng: random.Random, count: int) -> list[Client]:
    """``count`` slow clients, a mix of kinds, each cut at a generated place."""
    clients = []
    for n in range(count):
        kind = ("idle", "line", "headers", "body", "trickle", "pipelined")[n % 6]
        line_end = HEAD.index("\r\n")
        if kind == "idle":
            sent = ""
            trickle = ""
        elif kind == "line":  # part of the request line
            sent, trickle = HEAD[: rng.randrange(1, line_end)], ""
        elif kind == "headers":  # the request line and part of the headers, never the blank line
            sent, trickle = HEAD[: rng.randrange(line_end + 2, len(HEAD) - 2)], ""
        elif kind == "body":  # a whole head, a body that stops short of its Content-Length
            length = rng.randrange(len(QUERY) + 1, 4096)
            sent, trickle = POST.format(length=length) + QUERY[: rng.randrange(0, len(QUERY))], ""
        elif kind == "trickle":  # a head sent a byte at a time, never ending
            sent, trickle = HEAD[:1], HEAD[1:-2] + "x" * 200
        else:  # a whole request answered, then half of the next on the kept-alive connection
            sent, trickle = HEAD + HEAD[: rng.randrange(1, len(HEAD) - 2)], ""
        clients.append(Client(kind, sent.encode(), trickle.encode()))
    return clients


def connect(port: int, clients: list[Client]) -> None:
    for client in clients:
        sock = socket.create_connection(("127.0.0.1", port), timeout=10)
        sock.setblocking(False)
        client.sock, client.opened = sock, time.monotonic()
        if client.sent:
            with contextlib.suppress(OSError):  # refused and reset already
                sock.send(client.sent)


def follow(clients: list[Client], until: float) -> None:
    """Read every client's answers until the server closed them all (or ``until``), a trickling
    client sending a byte every 0.2 s meanwhile; a client the server closed is closed."""
    selector = selectors.DefaultSelector()
    open_ = {}
    for client in clients:
        assert client.sock is not None
        selector.register(client.sock, selectors.EVENT_READ, client)
        open_[client.sock.fileno()] = client
    next_trickle = time.monotonic()
    while open_ and time.monotonic() < until:
        for key, _ in selector.select(timeout=0.1):
            client = key.data
            try:
                chunk = client.sock.recv(65536)
            except (BlockingIOError, InterruptedError):
                continue
            except ConnectionResetError:
                chunk = b""
            if chunk:
                client.received += chunk
                continue
            client.closed_after = time.monotonic() - client.opened
            selector.unregister(client.sock)
            del open_[client.sock.fileno()]
            client.sock.close()
        if time.monotonic() >= next_trickle:
            next_trickle += 0.2
            for client in open_.values():
                if client.trickle:
                    try:
                        client.sock.send(client.trickle[:1])
                        client.trickle = client.trickle[1:]
                    except OSError:
                        client.trickle = b""
    selector.close()


def answer_within(base: str, seconds: float) -> float:
    """Seconds until a normal SPARQL query got 200 (asked again on a 503 or a refused connection)."""
    start = time.monotonic()
    while True:
        try:
            response = httpx.get(f"{base}/sparql", params={"query": WIRES}, timeout=10)
            if response.status_code == 200:
                return time.monotonic() - start
            assert response.status_code == 503, response.text
        except httpx.TransportError:
            pass
        assert time.monotonic() - start < seconds, f"no answer within {seconds} s"
        time.sleep(0.2)


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
