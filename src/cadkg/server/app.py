"""The ASGI application of the endpoint (Starlette), and :func:`serve`, which runs it with uvicorn.

Routes: ``/`` the web page (:mod:`cadkg.server.workbench.page`); ``/sparql`` the SPARQL 1.1 Protocol;
``/graph-store`` the Graph Store Protocol; ``/api/...`` services, named queries, the graph view
and info (see :mod:`cadkg.server.api`), completion terms, the 3D scene and its meshes (see
:mod:`cadkg.server.workbench.routes`); ``POST /reload`` to serve a rebuilt store.
In front of them a guard refuses requests meant for another host (DNS rebinding) and
requests a web page of another origin makes, unless the operator named that origin
(``--cors``): those get CORS headers, so a page elsewhere (YASGUI) can query the endpoint.
Behind it text is sent gzip-compressed, with the cache headers of :mod:`cadkg.server.caching`.
"""

from __future__ import annotations

import asyncio
import contextlib
import ipaddress
import sys
from collections.abc import AsyncIterator, Callable
from typing import Any

from starlette.applications import Starlette
from starlette.middleware import Middleware
from starlette.middleware.gzip import GZipMiddleware
from starlette.requests import ClientDisconnect
from starlette.responses import Response
from starlette.routing import Mount, Route
from starlette.staticfiles import StaticFiles
from starlette.types import ASGIApp, Message, Receive, Scope, Send

import cadkg.server.api as api
import cadkg.server.plan_api as plan_api
import cadkg.server.workbench.page as page
import cadkg.server.workbench.routes as workbench
from cadkg.errors import StoreError
from cadkg.served.holder import GraphHolder
from cadkg.server.api import CLIENT_HEADER
from cadkg.server.caching import HttpCaching
from cadkg.server.connections import ACCEPT_BURST, bounded_protocol, connection_bound
from cadkg.server.context import Endpoint, Settings
from cadkg.server.evaluation import pool_maker
from cadkg.server.feed import Streams, server_feed
from cadkg.server.feed import changes as changes_feed
from cadkg.server.protocol import graph_store, sparql

__all__ = ["STATIC", "create_app", "is_loopback", "serve"]

STATIC = page.STATIC
# The page loads only its own files; nothing is fetched from elsewhere.
_SECURITY_HEADERS = [
    (b"x-content-type-options", b"nosniff"),
    (b"referrer-policy", b"no-referrer"),
    (b"x-frame-options", b"DENY"),
    (
        b"content-security-policy",
        b"default-src 'self'; img-src 'self' data: blob:; style-src 'self'; script-src 'self'; "
        b"connect-src 'self'; frame-ancestors 'none'",
    ),
]


def is_loopback(host: str) -> bool:
    """Whether ``host`` (a name or an address, without port) is this machine only."""
    name = host.strip("[]").lower()
    if name == "localhost" or name.endswith(".localhost"):
        return True
    try:
        return ipaddress.ip_address(name).is_loopback
    except ValueError:
        return False


def _host_of(header: str) -> str:
    if header.startswith("["):
        return header[1 : header.find("]")] if "]" in header else header
    return header.rsplit(":", 1)[0] if header.count(":") == 1 else header


def _refusal(message: str, status: int = 400) -> Response:
    return Response(message + "\n", status, media_type="text/plain; charset=utf-8")


class _Guard:
    """Refuses requests whose ``Host`` is not this machine (so a web page on another site cannot
    reach a loopback endpoint through DNS rebinding) and requests from a web page of another
    origin than the endpoint's own and the ``cors`` ones; adds the security headers, and the
    CORS headers for a ``cors`` origin."""

    def __init__(
        self,
        app: Starlette,
        loopback_hosts_only: bool,
        cors: tuple[str, ...] = (),
    ) -> None:
        self.app = app
        self.loopback_hosts_only = loopback_hosts_only
        self.cors = {origin.rstrip("/") for origin in cors}

    @property
    def streams(self) -> Streams:
        """The app's event streams, which :class:`cadkg.server.closing.ClosingServer` ends."""
        streams: Streams = self.app.state.streams
        return streams

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        if scope["method"] == "HEAD":
            # A HEAD is answered as its GET, which changes nothing anywhere (uvicorn drops the
            # body, seeing its own scope's HEAD): no route can take a HEAD for a POST.
            scope = {**scope, "method": "GET"}
        headers = dict(scope.get("headers") or [])
        host = headers.get(b"host", b"").decode("latin-1")
        if self.loopback_hosts_only and host and not is_loopback(_host_of(host)):
            refused = f"host {host!r} is not this machine; the endpoint answers only loopback names"
            await _refusal(refused)(scope, receive, send)
            return
        extra = list(_SECURITY_HEADERS)
        origin = headers.get(b"origin", b"").decode("latin-1")
        if origin:
            if origin in self.cors:
                extra += self._cors_headers(origin)
                if scope["method"] == "OPTIONS" and b"access-control-request-method" in headers:
                    preflight = Response(status_code=204, headers=dict(self._preflight()))
                    preflight.raw_headers += extra
                    await preflight(scope, receive, send)
                    return
            elif origin.split("://", 1)[-1].lower() != host.lower():
                # No CORS by default, and not even an answer the page cannot read: a page
                # elsewhere must not make the endpoint work, let alone change anything.
                refused = (
                    f"a request from a web page of another origin ({origin}) is refused; "
                    "the endpoint answers such pages only when started with --cors ORIGIN"
                )
                await _refusal(refused, 403)(scope, receive, send)
                return

        async def send_with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                message["headers"] = list(message.get("headers", [])) + extra
            await send(message)

        # A client gone mid-body (or closed for stalling, cadkg.server.connections) has nobody
        # to answer and is no error of the endpoint's.
        with contextlib.suppress(ClientDisconnect):
            await self.app(scope, receive, send_with_headers)

    @staticmethod
    def _cors_headers(origin: str) -> list[tuple[bytes, bytes]]:
        return [
            (b"access-control-allow-origin", origin.encode("latin-1")),
            (b"vary", b"Origin"),
            (b"access-control-expose-headers", b"X-Cadkg-Generation, X-Cadkg-Truncated"),
        ]

    @staticmethod
    def _preflight() -> list[tuple[str, str]]:
        allowed = f"Accept, Authorization, Content-Type, {CLIENT_HEADER}"
        return [
            ("access-control-allow-methods", "GET, POST"),
            ("access-control-allow-headers", allowed),
            ("access-control-max-age", "600"),
        ]


def _prepare(holder: GraphHolder, settings: Settings) -> None:
    served = holder.acquire()
    try:
        workers = served.workers(pool_maker(settings))
        if workers is not None:
            workers.prestart()
    except Exception as err:  # the first query says it again, as its answer
        print(f"cadkg serve: query workers not ready: {err}", file=sys.stderr)
    finally:
        served.release()


async def _watch(endpoint: Endpoint, seconds: float) -> None:
    """Serve a rebuilt store: poll its ``CURRENT`` pointer and reload when it moves."""
    while True:
        await asyncio.sleep(seconds)
        if endpoint.holder.stale():
            try:
                swapped = await endpoint.reload(only_if_stale=True)
            except Exception as err:  # keep serving the old graph, say why, try again later
                print(f"cadkg serve: reload failed, still serving the old graph: {err}", file=sys.stderr)
                continue
            if swapped is not None:
                print(f"cadkg serve: reloaded {swapped[0]} → {swapped[1]}", file=sys.stderr, flush=True)


def create_app(
    graph_or_loader: Any | Callable[[], Any],
    settings: Settings | None = None,
    *,
    loopback_hosts_only: bool = True,
) -> ASGIApp:
    """The endpoint's ASGI app over a graph, or over a loader that opens it (then ``/reload``
    and the store watch can open it again).

    ``graph_or_loader`` is a :class:`~cadkg.graph.KnowledgeGraph`, a remote graph with the same
    read methods, or a function returning one.
    """
    settings = settings or Settings()
    if callable(graph_or_loader) and not hasattr(graph_or_loader, "raw_query"):
        holder = GraphHolder(graph_or_loader(), graph_or_loader)
    else:
        holder = GraphHolder(graph_or_loader)
    endpoint = Endpoint(holder, settings)
    feed = server_feed(holder)

    @contextlib.asynccontextmanager
    async def lifespan(app: Starlette) -> AsyncIterator[None]:
        watcher = None
        endpoint.loop = asyncio.get_running_loop()
        if settings.watch_seconds > 0 and getattr(holder.current.graph, "directory", None) is not None:
            watcher = asyncio.create_task(_watch(endpoint, settings.watch_seconds))
        # The first query should not wait for the snapshot and the first worker process.
        ready = asyncio.create_task(asyncio.to_thread(_prepare, holder, settings))
        feed.changed(holder.current)  # what the first change is compared with
        try:
            yield
        finally:
            if watcher is not None:
                watcher.cancel()
            with contextlib.suppress(Exception):
                await ready
            feed.shutdown()
            endpoint.evaluator.shutdown()
            endpoint.local.shutdown()
            endpoint.writer.shutdown()
            holder.close()

    methods = ["GET", "POST"]
    app = Starlette(
        routes=[
            Route("/", page.page, methods=["GET"]),
            Route("/favicon.ico", page.favicon, methods=["GET"]),
            Route("/sparql", sparql, methods=methods),
            Route("/graph-store", graph_store, methods=["GET", "PUT", "POST", "DELETE"]),
            Route("/api", api.index, methods=["GET"]),
            Route("/api/info", api.info, methods=["GET"]),
            Route("/api/graph", api.graph_view, methods=["GET"]),
            Route("/api/queries", api.queries, methods=["GET"]),
            Route("/api/queries/{name}", api.named, methods=["GET"]),
            Route("/api/queries/{name}/bound", workbench.bound, methods=["GET"]),
            Route("/api/terms", workbench.terms, methods=["GET"]),
            Route("/api/cell", workbench.cell, methods=["GET"]),
            Route("/api/scene", workbench.scene, methods=["GET"]),
            Route("/api/mesh/{path:path}", workbench.mesh, methods=["GET"]),
            Route("/api/changes", changes_feed, methods=["GET"]),
            Route("/api/plan", plan_api.plan, methods=methods),
            Route("/api/{service}", api.service, methods=methods),
            Route("/reload", api.reload, methods=["POST"]),
            Mount("/static", StaticFiles(directory=STATIC), name="static"),
        ],
        lifespan=lifespan,
        # Text (the page's code, JSON, SPARQL results) goes compressed to a client that accepts
        # it; cache headers and ETags are set on the answer before it is compressed.
        middleware=[Middleware(GZipMiddleware, minimum_size=1024), Middleware(HttpCaching)],
    )
    app.state.endpoint = endpoint
    app.state.feed = feed
    app.state.streams = Streams()
    return _Guard(app, loopback_hosts_only, settings.cors)


def serve(
    load: Callable[[], Any],
    settings: Settings,
    host: str = "127.0.0.1",
    port: int = 7878,
    *,
    allow_non_loopback: bool = False,
) -> None:
    """Run the endpoint with uvicorn until interrupted.

    Raises
    ------
    StoreError
        When ``host`` is not a loopback address and ``allow_non_loopback`` is not given, or
        when ``settings.limits.max_connections`` leaves too few descriptors for the rest.
    """
    import uvicorn

    from cadkg.server.closing import GRACE_SECONDS, ClosingServer

    loopback = is_loopback(host)
    if not loopback and not allow_non_loopback:
        raise StoreError(
            f"refusing to listen on {host}: the endpoint has no user accounts and is meant for this "
            "machine; give --allow-non-loopback to serve other machines (see docs/server.md)"
        )
    # Sized (and the descriptor limit raised) before anything opens the store or forks a worker.
    limits = settings.limits
    bound = connection_bound(limits.max_connections)
    app = create_app(load, settings, loopback_hosts_only=loopback)
    mode = "read-write (token)" if settings.allow_update else "read-only"
    # What the operator opened beyond the defaults, said where they will look first.
    if settings.files_root is not None:
        mode += f"; load_files under {settings.files_root}"
    if settings.allowed_services:
        mode += f"; SERVICE to {', '.join(settings.allowed_services)}"
    if settings.cors:
        mode += f"; pages of {', '.join(settings.cors)}"
    shown = f"[{host}]" if ":" in host else host
    print(f"cadkg serve: http://{shown}:{port}/ ({mode})", file=sys.stderr, flush=True)
    missing = page.bundle_missing()
    if missing:
        print(f"cadkg serve: {missing}", file=sys.stderr, flush=True)
    print(
        f"cadkg serve: {bound.describe()}; a request head within {limits.header_timeout:g} s",
        file=sys.stderr,
        flush=True,
    )
    config = uvicorn.Config(
        app,
        host=host,
        port=port,
        log_level="warning",
        access_log=False,
        timeout_keep_alive=30,
        timeout_graceful_shutdown=GRACE_SECONDS,
        http=bounded_protocol(limits.header_timeout, bound),
        backlog=ACCEPT_BURST,
        loop="asyncio",  # whose accepting ACCEPT_BURST bounds (not uvloop's, were it installed)
    )
    ClosingServer(config).run()
