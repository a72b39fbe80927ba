"""Slow and many clients of a served cell, generated: half-sent request heads, bodies that
stall, idle connections, tricklers; shared by the endpoint's tests and the ROS node's test under
HTTP load."""

from __future__ import annotations

import contextlib
import random
import resource
import selectors
import socket
import time
from dataclasses import dataclass, field

import httpx
import pytest

DESCRIPTORS = 1024


def own_descriptors(needed: int = 4096) -> None:
    """Raise this process's soft limit of open files to ``needed`` (its end of the connections
    needs descriptors too); skip when the hard limit does not allow it."""
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if hard != resource.RLIM_INFINITY and hard < needed:
        pytest.skip(f"the test opens over 1,500 sockets; the hard limit of open files is {hard}")
    if soft != resource.RLIM_INFINITY and soft < needed:
        resource.setrlimit(resource.RLIMIT_NOFILE, (min(hard, 2 * needed), hard))


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
