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
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from starlette.requests import Request
from starlette.responses import Response, StreamingResponse

from cadkg.changes.changeset import ChangeSet
from cadkg.changes.feed import ChangeFeed
from cadkg.errors import CadkgError
from cadkg.server.holder import GraphHolder, Served
from cadkg.services.session import Work

__all__ = ["ServerFeed", "changes"]

# A comment line this often keeps proxies and clients from closing an idle stream.
KEEPALIVE_SECONDS = 15.0


class ServerFeed:
    """The feed of one endpoint: fed by the holder after each change, one change at a time."""

    def __init__(self, holder: GraphHolder) -> None:
        self.feed = ChangeFeed()
        self._holder = holder
        self._work = ThreadPoolExecutor(max_workers=1, thread_name_prefix="cadkg-changes")
        holder.on_change = self.changed

    def changed(self, served: Served) -> None:
        """``served`` now holds the served graph as it is after a change (or at start)."""
        served.retain()
        # Now, before the cursors go on over the new graph.
        done = served.passed_work()
        self._work.submit(self._observe, served, done)

    def _observe(self, served: Served, done: dict[str, list[Work]]) -> None:
        # Not under the served graph's lock, which would hold the robot's service calls for as
        # long as the queries take; an edit landing meanwhile is in the next change set.
        try:
            self.feed.observe(served.graph, f"{served.generation}+{served.edits}", done)
        except CadkgError as err:
            print(f"cadkg serve: change feed: {err}", file=sys.stderr, flush=True)
        finally:
            served.release()

    def shutdown(self) -> None:
        self._work.shutdown(wait=True, cancel_futures=True)


def _event(changes: ChangeSet, number: int) -> bytes:
    data = json.dumps(changes.to_json(), separators=(",", ":"), default=str)
    return f"event: changes\nid: {number}\ndata: {data}\n\n".encode()


async def changes(request: Request) -> Response:
    """``GET /api/changes``: Server-Sent Events, one ``changes`` event per change set."""
    feed: ChangeFeed = request.app.state.feed.feed
    loop = asyncio.get_running_loop()
    queue: asyncio.Queue[tuple[ChangeSet, int]] = asyncio.Queue()

    def heard(changes: ChangeSet) -> None:
        loop.call_soon_threadsafe(queue.put_nowait, (changes, feed.published))

    stop = feed.listen(heard)
    latest = feed.latest

    async def stream() -> AsyncIterator[bytes]:
        try:
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
                yield _event(*item)
        finally:
            stop()

    headers = {"Cache-Control": "no-store", "X-Accel-Buffering": "no"}
    return StreamingResponse(stream(), media_type="text/event-stream", headers=headers)
