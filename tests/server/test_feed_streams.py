"""``GET /api/changes`` leaves nothing registered once its stream is over, started or not.

A client may go away between the answer's headers and the first byte of its stream; Starlette
then never starts the stream's generator. The feed's listener and the server's stream queue are
registered where they are unregistered, so such a client leaves neither behind.
"""

from __future__ import annotations

import asyncio
from types import SimpleNamespace
from typing import Any

from starlette.responses import StreamingResponse

from cadkg.changes.feed import ChangeFeed
from cadkg.server.feed import Streams, changes


def _request(feed: ChangeFeed, streams: Streams) -> Any:
    state = SimpleNamespace(feed=SimpleNamespace(feed=feed), streams=streams)

    async def is_disconnected() -> bool:
        return True

    return SimpleNamespace(app=SimpleNamespace(state=state), is_disconnected=is_disconnected)


def _registered(feed: ChangeFeed, streams: Streams) -> tuple[int, int]:
    return feed.listening, streams.running


def test_an_answer_never_streamed_registers_nothing() -> None:
    feed, streams = ChangeFeed(), Streams()

    async def ask() -> None:
        answer = await changes(_request(feed, streams))
        assert isinstance(answer, StreamingResponse)
        assert _registered(feed, streams) == (0, 0)

    asyncio.run(ask())
    assert _registered(feed, streams) == (0, 0)


def test_a_stream_is_registered_while_it_runs_and_not_after() -> None:
    feed, streams = ChangeFeed(), Streams()

    async def ask() -> list[tuple[int, int]]:
        answer = await changes(_request(feed, streams))
        assert isinstance(answer, StreamingResponse)
        body: Any = answer.body_iterator
        first = await body.__anext__()
        assert first.startswith(b"retry:")
        during = _registered(feed, streams)
        await body.aclose()  # the client went away
        return [during, _registered(feed, streams)]

    assert asyncio.run(ask()) == [(1, 1), (0, 0)]


def test_a_stream_opened_after_the_server_closed_ends_at_once() -> None:
    feed, streams = ChangeFeed(), Streams()
    streams.close()

    async def ask() -> list[bytes]:
        answer = await changes(_request(feed, streams))
        assert isinstance(answer, StreamingResponse)
        return [chunk async for chunk in answer.body_iterator]  # type: ignore[misc]

    assert asyncio.run(ask()) == [b"retry: 3000\n\n"]
    assert _registered(feed, streams) == (0, 0)
