"""Stopping the endpoint while pages hold its event streams open.

uvicorn, told to stop (SIGTERM, Ctrl-C), stops accepting and waits for every response in
flight to end; an event stream (``/api/changes``) never ends by itself, so with one page open
``cadkg serve`` never stopped. :class:`ClosingServer` ends the app's streams
(:class:`cadkg.server.feed.Streams`) first, then stops as uvicorn does: the queries and updates
in flight finish, and what still runs after :data:`GRACE_SECONDS` is cancelled.
"""

from __future__ import annotations

import socket

import uvicorn

from cadkg.server.feed import Streams

__all__ = ["GRACE_SECONDS", "ClosingServer"]

# How long requests in flight (not event streams) are given to finish once the server is told
# to stop; a query's own time limit is usually shorter.
GRACE_SECONDS = 30


class ClosingServer(uvicorn.Server):
    """uvicorn's server that ends the app's event streams (its ``streams``) when told to stop."""

    async def shutdown(self, sockets: list[socket.socket] | None = None) -> None:
        streams: Streams | None = getattr(self.config.app, "streams", None)
        if streams is not None:
            streams.close()
        await super().shutdown(sockets)
