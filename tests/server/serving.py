"""A real uvicorn server on a free loopback port, in a thread, for the endpoint's tests."""

from __future__ import annotations

import contextlib
import resource
import socket
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import uvicorn

from cadkg.server import Limits, Settings, create_app
from cadkg.server.closing import ClosingServer


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


@contextlib.contextmanager
def serving(graph_or_loader: Any, settings: Settings | None = None, **limits: Any) -> Iterator[str]:
    """Serve a graph (or a loader) until the block ends; yields the base URL."""
    if settings is None:
        settings = Settings(limits=Limits(**limits), watch_seconds=0)
    with serving_app(create_app(graph_or_loader, settings)) as base:
        yield base


@contextlib.contextmanager
def serving_app(app: Any) -> Iterator[str]:
    """Serve an app of :func:`cadkg.server.create_app` until the block ends; yields the base URL."""
    port = free_port()
    config = uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning", access_log=False)
    server = ClosingServer(config)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 20
    while not server.started:
        if not thread.is_alive() or time.monotonic() > deadline:
            raise RuntimeError("the test server did not start")
        time.sleep(0.02)
    base = f"http://127.0.0.1:{port}"
    try:
        ready(base)
        yield base
    finally:
        server.should_exit = True
        thread.join(20)


def ready(base: str, wait: float = 120) -> None:
    """Wait until the endpoint's query workers have started (a short time limit in a test would
    otherwise be spent starting them)."""
    import httpx

    deadline = time.monotonic() + wait
    while True:
        workers = httpx.get(f"{base}/api/info", timeout=30).json()["workers"]
        if workers is None or workers["ready"]:
            return
        if time.monotonic() > deadline:
            raise RuntimeError("the endpoint's query workers did not start")
        time.sleep(0.05)


@contextlib.contextmanager
def cadkg_serve(*args: str, wait: float = 120) -> Iterator[str]:
    """``cadkg serve ARGS --port <free port>`` in a subprocess until the block ends; yields the base URL."""
    with cadkg_serve_process(*args, wait=wait) as (base, _):
        yield base


@contextlib.contextmanager
def cadkg_serve_process(
    *args: str, wait: float = 120, descriptors: int | None = None, log: Path | None = None
) -> Iterator[tuple[str, Any]]:
    """As :func:`cadkg_serve`, yielding the process too; it runs in its own process group (its
    query workers with it), killed as a whole at the end. ``descriptors``: the process's limit of
    open files (soft and hard); ``log``: a file its standard error goes to."""
    import os
    import signal
    import subprocess
    import sys

    import httpx

    from tests.conftest import ROOT

    port = free_port()
    command = [sys.executable, "-m", "cadkg.cli", "serve", *args, "--port", str(port)]

    def limit() -> None:
        if descriptors is not None:
            resource.setrlimit(resource.RLIMIT_NOFILE, (descriptors, descriptors))

    with contextlib.ExitStack() as files:
        stderr = subprocess.PIPE if log is None else files.enter_context(log.open("w"))
        process = subprocess.Popen(
            command,
            cwd=ROOT,
            stdout=subprocess.PIPE,
            stderr=stderr,
            text=True,
            start_new_session=True,
            preexec_fn=limit if descriptors is not None else None,
        )
    base = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + wait
        while True:
            if process.poll() is not None:
                _, err = process.communicate()
                err = err if log is None else log.read_text()
                raise RuntimeError(f"cadkg serve exited with {process.returncode}: {err}")
            try:
                info = httpx.get(f"{base}/api/info", timeout=5)
                if info.status_code == 200 and (info.json()["workers"] or {"ready": True})["ready"]:
                    break
            except httpx.TransportError:
                pass
            if time.monotonic() > deadline:
                raise RuntimeError("cadkg serve did not answer in time")
            time.sleep(0.2)
        yield base, process
    finally:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGTERM)
        try:
            process.wait(15)
        except subprocess.TimeoutExpired:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(process.pid, signal.SIGKILL)
            process.wait(5)
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)  # workers left by a server that did not end them
        if process.stdout:
            process.stdout.close()
        if process.stderr:
            process.stderr.close()
