"""A real uvicorn server on a free loopback port, in a thread, for the endpoint's tests."""

from __future__ import annotations

import contextlib
import socket
import threading
import time
from collections.abc import Iterator
from typing import Any

import uvicorn

from cadkg.server import Limits, Settings, create_app


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
    app = create_app(graph_or_loader, settings)
    port = free_port()
    config = uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning", access_log=False)
    server = uvicorn.Server(config)
    thread = threading.Thread(target=server.run, daemon=True)
    thread.start()
    deadline = time.monotonic() + 20
    while not server.started:
        if not thread.is_alive() or time.monotonic() > deadline:
            raise RuntimeError("the test server did not start")
        time.sleep(0.02)
    try:
        yield f"http://127.0.0.1:{port}"
    finally:
        server.should_exit = True
        thread.join(20)


@contextlib.contextmanager
def cadkg_serve(*args: str, wait: float = 120) -> Iterator[str]:
    """``cadkg serve ARGS --port <free port>`` in a subprocess until the block ends; yields the base URL.

    The server runs in a process group of its own, killed as a whole at the end.
    """
    import os
    import signal
    import subprocess
    import sys

    import httpx

    from tests.conftest import ROOT

    port = free_port()
    command = [sys.executable, "-m", "cadkg.cli", "serve", *args, "--port", str(port)]
    process = subprocess.Popen(
        command,
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    base = f"http://127.0.0.1:{port}"
    try:
        deadline = time.monotonic() + wait
        while True:
            if process.poll() is not None:
                _, err = process.communicate()
                raise RuntimeError(f"cadkg serve exited with {process.returncode}: {err}")
            try:
                if httpx.get(f"{base}/api/info", timeout=5).status_code == 200:
                    break
            except httpx.TransportError:
                pass
            if time.monotonic() > deadline:
                raise RuntimeError("cadkg serve did not answer in time")
            time.sleep(0.2)
        yield base
    finally:
        process.terminate()
        with contextlib.suppress(subprocess.TimeoutExpired):
            process.wait(15)
        with contextlib.suppress(ProcessLookupError):
            os.killpg(process.pid, signal.SIGKILL)
        process.wait(5)
        if process.stderr:
            process.stderr.close()
