"""What keeps a served cell answering under slow and many clients: a time for each request head,
a body that must keep coming, a bound on open connections below the descriptor limit.

uvicorn's HTTP/1.1 protocol (h11) closes a connection left idle after an answer
(``timeout_keep_alive``) but waits forever for a request head or body that stops half-way, and
accepts connections until the process runs out of descriptors (then it answers nobody). The
protocol class here adds the missing timers and the bound; uvicorn takes it as ``http=``.
"""

from __future__ import annotations

import asyncio
import resource
from collections.abc import Callable
from dataclasses import dataclass

import h11
from uvicorn.protocols.http.h11_impl import H11Protocol

from cadkg.errors import StoreError

__all__ = ["ACCEPT_BURST", "RESERVE", "ConnectionBound", "bounded_protocol", "connection_bound"]

# Descriptors a served cell needs besides its connections: the store's files (RocksDB keeps its
# tables open), the pipes to the query workers, meshes and bundle files being sent, the log; and
# the connections accepted before their protocol could refuse them (below).
RESERVE = 256
# asyncio accepts up to its server's backlog of connections at each turn of the loop before any
# of their protocols runs, and a few turns may pass before the refused ones are closed: with the
# default of 2,048 a burst of clients runs the process out of descriptors whatever the bound.
# Kept this small, at most a few bursts (under RESERVE) are open past the bound; clients past the
# kernel's queue of as many wait in their connect(), holding nothing of the server's.
ACCEPT_BURST = 64


@dataclass(frozen=True)
class ConnectionBound:
    """How many connections the server keeps open, and the descriptor limit it was sized under."""

    connections: int
    descriptors: int

    def describe(self) -> str:
        return (
            f"at most {self.connections} connections open (of {self.descriptors} descriptors, "
            f"the rest kept for the store, workers and files)"
        )


def connection_bound(requested: int = 0) -> ConnectionBound:
    """Raise this process's soft descriptor limit to its hard limit where allowed, and size the
    connection bound under it: ``requested``, or (0) the limit less :data:`RESERVE`, at least 16.

    Raises
    ------
    StoreError
        When ``requested`` leaves fewer than :data:`RESERVE` descriptors for the rest.
    """
    soft, hard = resource.getrlimit(resource.RLIMIT_NOFILE)
    if hard != resource.RLIM_INFINITY and soft != hard:
        try:
            resource.setrlimit(resource.RLIMIT_NOFILE, (hard, hard))
            soft = hard
        except (ValueError, OSError):  # a sandbox may refuse: serve under the soft limit
            pass
    descriptors = soft if soft != resource.RLIM_INFINITY else 1 << 20
    if requested == 0:
        return ConnectionBound(max(descriptors - RESERVE, 16), descriptors)
    if requested > descriptors - RESERVE:
        raise StoreError(
            f"{requested} connections leave fewer than {RESERVE} of the {descriptors} descriptors "
            "this process may open for the store, workers and files"
        )
    return ConnectionBound(requested, descriptors)


def _plain_answer(status: int, reason: str, text: str, *headers: str) -> bytes:
    """A whole answer that closes the connection, written before (or instead of) a request."""
    body = text.encode()
    head = [f"HTTP/1.1 {status} {reason}", "content-type: text/plain; charset=utf-8", "connection: close"]
    head += [*headers, f"content-length: {len(body)}"]
    return ("\r\n".join(head) + "\r\n\r\n").encode() + body


class _BoundedH11Protocol(H11Protocol):
    """h11 with a time for the request head, a time between body chunks, and a connection bound."""

    header_timeout: float
    max_connections: int

    _timer: asyncio.TimerHandle | None = None
    _head_started = False  # the timer running is the head's, not a body's

    def connection_made(self, transport: asyncio.Transport) -> None:  # type: ignore[override]
        full = len(self.connections) >= self.max_connections
        super().connection_made(transport)
        if full:
            # Answered and closed at once, before it is read: a refused connection must not hold
            # its descriptor for as long as an accepted one may.
            refusal = _plain_answer(503, "Service Unavailable", "too many connections", "retry-after: 1")
            transport.write(refusal)
            transport.close()
            return
        self._arm_head()

    def data_received(self, data: bytes) -> None:
        super().data_received(data)
        self._follow()

    def on_response_complete(self) -> None:
        super().on_response_complete()
        # A kept-alive connection waits under timeout_keep_alive until its next request starts;
        # a pipelined request already started has its head's time.
        if self.conn.their_state is h11.IDLE and self.conn.trailing_data[0]:
            self._arm_head()

    def connection_lost(self, exc: Exception | None) -> None:
        self._disarm()
        super().connection_lost(exc)

    def _follow(self) -> None:
        """After data: the head's timer runs on until the head is whole (a client sending a byte
        a second must not keep it open), then each body chunk gives the next its time."""
        state = self.conn.their_state
        if state is h11.IDLE:
            if not self._head_started:
                self._arm_head()  # a kept-alive connection's next head began
        elif state is h11.SEND_BODY:
            self._arm(self._body_stalled)
        else:
            self._disarm()

    def _arm_head(self) -> None:
        self._arm(self._head_late)
        self._head_started = True

    def _arm(self, handler: Callable[[], None]) -> None:
        self._disarm()
        self._timer = self.loop.call_later(self.header_timeout, handler)

    def _disarm(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None
        self._head_started = False

    def _head_late(self) -> None:
        self._close(f"no whole request head within {self.header_timeout:g} s")

    def _body_stalled(self) -> None:
        if self.flow.read_paused:  # the app has not read what came: not the client's stall
            self._arm(self._body_stalled)
            return
        self._close(f"the request body stalled for {self.header_timeout:g} s")

    def _close(self, why: str) -> None:
        self._timer = None
        self._head_started = False
        if self.transport.is_closing():
            return
        # No request read yet on this turn (the cycle, if any, is the last request's, answered).
        if self.conn.their_state is h11.IDLE or self.cycle is None or not self.cycle.response_started:
            self.transport.write(_plain_answer(408, "Request Timeout", why))
        self.transport.close()


def bounded_protocol(header_timeout: float, bound: ConnectionBound) -> type[H11Protocol]:
    """The protocol class for uvicorn's ``http=``, closing a connection whose request head is not
    whole within ``header_timeout`` seconds, or whose body sends nothing for as long, and answering
    503 to (and closing) a connection past ``bound``."""
    return type(
        "BoundedH11Protocol",
        (_BoundedH11Protocol,),
        {"header_timeout": header_timeout, "max_connections": bound.connections},
    )
