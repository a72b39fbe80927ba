"""How long a browser may keep what the endpoint sends, and answers of an unchanged graph unsent.

- The page's bundle files (``/static/dist/assets/``) carry a hash of their content in their
  names: kept a year, never asked again (``immutable``).
- The page itself (``/``) names the current bundle files: asked again on every visit (``no-cache``).
- A read answer (``GET`` of ``/api/...`` or ``/sparql``, 200, served from a graph) gets an
  ``ETag`` made of the graph's generation and a hash of the answer, and ``no-cache``: the browser
  asks again with ``If-None-Match`` and gets ``304 Not Modified`` with no body while the answer
  is the same (the endpoint's answer cache makes computing it again cheap). The hash, not the
  generation alone, tells an update to an in-memory graph (its generation stays) apart.

Compression is the gzip middleware's, outside this one: the tag is of the uncompressed answer,
hence weak (``W/``), the same for both encodings.
"""

from __future__ import annotations

import hashlib

from starlette.datastructures import Headers, MutableHeaders
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from cadkg.server.context import GENERATION_HEADER

__all__ = ["ASSETS_CACHE", "HttpCaching"]

ASSETS_CACHE = "public, max-age=31536000, immutable"
_REVALIDATE = "no-cache"
_FAVICON = "public, max-age=86400"
_ANSWERS = ("/api/", "/sparql")


def _policy(path: str) -> str | None:
    """The ``Cache-Control`` of a static path, or None for the answers of a graph."""
    if path.startswith("/static/dist/assets/"):
        return ASSETS_CACHE
    if path in ("/", "/static/dist/index.html"):
        return _REVALIDATE
    if path == "/favicon.ico":
        return _FAVICON
    return None


def _matches(if_none_match: str, etag: str) -> bool:
    given = {tag.strip().removeprefix("W/") for tag in if_none_match.split(",")}
    return "*" in given or etag.removeprefix("W/") in given


class HttpCaching:
    """Cache headers on the page and its files; ``ETag`` and ``304`` on the answers of a graph."""

    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or scope["method"] not in ("GET", "HEAD"):
            await self.app(scope, receive, send)
            return
        path: str = scope["path"]
        policy = _policy(path)
        if policy is not None:
            await self.app(scope, receive, self._with_policy(send, policy))
        elif scope["method"] == "GET" and path.startswith(_ANSWERS):
            await self._conditional(scope, receive, send)
        else:
            await self.app(scope, receive, send)

    @staticmethod
    def _with_policy(send: Send, policy: str) -> Send:
        async def sending(message: Message) -> None:
            if message["type"] == "http.response.start" and message["status"] < 400:
                MutableHeaders(scope=message)["cache-control"] = policy
            await send(message)

        return sending

    async def _conditional(self, scope: Scope, receive: Receive, send: Send) -> None:
        start: Message | None = None
        chunks: list[bytes] = []

        async def holding(message: Message) -> None:
            nonlocal start
            if message["type"] == "http.response.start":
                headers = Headers(raw=message.get("headers", []))
                if message["status"] != 200 or GENERATION_HEADER.lower() not in headers:
                    await send(message)  # an error or a service's answer: passed on as it is
                    return
                start = message
                return
            if start is None or message["type"] != "http.response.body":
                await send(message)
                return
            chunks.append(message.get("body", b""))
            if message.get("more_body", False):
                return
            await self._finish(scope, start, b"".join(chunks), send)

        await self.app(scope, receive, holding)

    @staticmethod
    async def _finish(scope: Scope, start: Message, body: bytes, send: Send) -> None:
        headers = MutableHeaders(scope=start)
        digest = hashlib.blake2b(body, digest_size=12).hexdigest()
        etag = f'W/"{headers[GENERATION_HEADER]}-{digest}"'
        headers["etag"] = etag
        headers.setdefault("cache-control", _REVALIDATE)
        asked = Headers(scope=scope).get("if-none-match")
        if asked is not None and _matches(asked, etag):
            kept = [
                (name, value)
                for name, value in start["headers"]
                if name.lower() not in (b"content-length", b"content-type")
            ]
            await send({"type": "http.response.start", "status": 304, "headers": kept})
            await send({"type": "http.response.body", "body": b""})
            return
        await send(start)
        await send({"type": "http.response.body", "body": body})
