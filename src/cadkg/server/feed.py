"""``GET /api/changes``: the change feed of the served graph as Server-Sent Events.

After every rebuild, reload, ``load_files`` or assignment the endpoint compares the things of
the graph it now serves with those of the one before (:class:`cadkg.changes.feed.ChangeFeed`,
in a thread of its own) and sends each client an event ``changes`` whose data is the change
set as ``cadkg diff --format json`` prints it; a client that connects is sent the latest one
first (latched). Read-only: no token.
"""

from __future__ import annotations

import asyncio
import json
import sys
from collections.abc import AsyncIterator
from typing import Any

from starlette.requests import Request
from starlette.responses import Response, StreamingResponse

from cadkg.changes.changeset import ChangeSet
from cadkg.changes.feed import ChangeFeed
from cadkg.served.feed import CellFeed
from cadkg.served.holder import GraphHolder

__all__ = ["Streams", "changes", "server_feed"]

# A comment line this often keeps proxies and clients from closing an idle stream.
KEEPALIVE_SECONDS = 15.0


class Streams:
    """The event streams open on the server's loop; each ends at the ``None`` put in its queue
    (:class:`cadkg.server.closing.ClosingServer` closes them when told to stop)."""

    def __init__(self) -> None:
        self._queues: set[asyncio.Queue[Any]] = set()
        self.closed = False

    def open(self, queue: asyncio.Queue[Any]) -> None:
        if self.closed:
            queue.put_nowait(None)
        self._queues.add(queue)

    def done(self, queue: asyncio.Queue[Any]) -> None:
        self._queues.discard(queue)

    @property
    def running(self) -> int:
        """How many streams are open now."""
        return len(self._queues)

    def close(self) -> None:
        """End every stream, and every one opened from now on (called on the server's loop)."""
        self.closed = True
        for queue in self._queues:
            queue.put_nowait(None)


def server_feed(holder: GraphHolder) -> CellFeed:
    """The endpoint's feed: a graph is named by its generation and the edits made since."""

    def warn(message: str) -> None:
        print(f"cadkg serve: {message}", file=sys.stderr, flush=True)

    return CellFeed(holder, lambda served: f"{served.generation}+{served.edits}", warn)


def _event(changes: ChangeSet, number: int) -> bytes:
    data = json.dumps(changes.to_json(), separators=(",", ":"), default=str)
    return f"event: changes\nid: {number}\ndata: {data}\n\n".encode()


async def changes(request: Request) -> Response:
    """``GET /api/changes``: Server-Sent Events, one ``changes`` event per change set."""
    feed: ChangeFeed = request.app.state.feed.feed
    loop = asyncio.get_running_loop()
    queue: asyncio.Queue[tuple[ChangeSet, int] | None] = asyncio.Queue()

    def heard(changes: ChangeSet) -> None:
        loop.call_soon_threadsafe(queue.put_nowait, (changes, feed.published))

    streams: Streams = request.app.state.streams

    async def stream() -> AsyncIterator[bytes]:
        # Registered here, where the finally that unregisters runs: a client gone before the
        # response starts streaming leaves nothing behind.
        stop = feed.listen(heard)
        streams.open(queue)
        try:
            latest = feed.latest
            yield b"retry: 3000\n\n"
            if latest is not None:
                yield _event(latest, feed.published)
            while True:
                try:
                    item: Any = await asyncio.wait_for(queue.get(), KEEPALIVE_SECONDS)
                except TimeoutError:
                    if await request.is_disconnected():
                        return
                    yield b": keepalive\n\n"
                    continue
                if item is None:  # the server is stopping
                    return
                yield _event(*item)
        finally:
            streams.done(queue)
            stop()

    headers = {"Cache-Control": "no-store", "X-Accel-Buffering": "no"}
    return StreamingResponse(stream(), media_type="text/event-stream", headers=headers)
