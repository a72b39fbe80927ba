"""Fixtures of the live tests: the cadkg node in its own process on a copy of the mini cell, and a client.

Run only in .venv-ros (``CADKG_ROS_LIVE=1 .venv-ros/bin/python -m pytest tests/ros/live``);
tests/ros/test_live.py does that from the main test run.
"""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import pytest

os.environ.setdefault("ROS_DOMAIN_ID", str(1 + os.getpid() % 100))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"

import rclpy

import cadkg.registry as registry

ROOT = Path(__file__).resolve().parents[3]
MINI = ROOT / "tests" / "data" / "cells" / "mini"
NAMESPACE = "/gearbox_handler"


def underlay_environment() -> dict[str, str]:
    """The environment of a colcon build whose underlay is this venv's ROS wheels, as a ROS
    workspace has its distribution sourced."""
    venv = Path(sys.prefix)
    return {
        **os.environ,
        "PATH": f"{venv / 'bin'}:{os.environ.get('PATH', '')}",
        "AMENT_PREFIX_PATH": str(venv),
        "CMAKE_PREFIX_PATH": str(venv),
    }


class Server:
    def __init__(
        self,
        manifest: Path | str,
        log: Path,
        node_name: str = "cadkg",
        extra: Sequence[str] = (),
        env: Mapping[str, str] | None = None,
    ) -> None:
        self.manifest = manifest
        self.log = log
        self._out = log.open("w")
        self.process = subprocess.Popen(
            [sys.executable, "-m", "cadkg.ros_adapter", str(manifest), "--node-name", node_name, *extra],
            env=None if env is None else {**os.environ, **env},
            stdout=self._out,
            stderr=subprocess.STDOUT,
            cwd=ROOT,
        )

    def output(self) -> str:
        self._out.flush()
        return self.log.read_text()

    def check_alive(self) -> None:
        if self.process.poll() is not None:
            pytest.fail(f"the node exited with {self.process.returncode}:\n{self.output()}")

    def stop(self) -> None:
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
            try:
                self.process.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.process.kill()
                self.process.wait()
                self._out.close()
                pytest.fail(f"the node did not exit within 10 s of SIGINT:\n{self.log.read_text()}")
        self._out.close()


@pytest.fixture(scope="session")
def server(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    cell = tmp_path_factory.mktemp("cell") / "mini"
    shutil.copytree(MINI, cell)
    running = Server(cell / "manifest.toml", cell.parent / "node.log")
    yield running
    running.stop()


@pytest.fixture(scope="session")
def ros(server: Server) -> Iterator[Any]:
    rclpy.init()
    node = rclpy.create_node("cadkg_live_test")
    yield node
    node.destroy_node()
    rclpy.shutdown()


def wait_for(node: Any, done: Callable[[], bool], timeout: float, server: Server) -> None:
    deadline = time.monotonic() + timeout
    while not done():
        server.check_alive()
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout} s; node output:\n{server.output()}")
        rclpy.spin_once(node, timeout_sec=0.05)


# What the node logs when a response is lost: its writer had not yet discovered the client's
# new reader (a discovery race of Fast DDS under load), so the client would wait for ever.
LOST = "failed to send response"
# How long a new client waits, once its service is ready, before a call that changes something:
# the node discovers the client's reader about when the client discovered the node's.
SETTLE = 1.0


def _reads(path: str) -> bool:
    """Whether the service at ``path`` only reads, as its declaration says (``Effect``)."""
    service = registry.services().get(path.rsplit("/", 1)[-1])
    return service is not None and not service.effect.changes


def _lost_since(server: Any, mark: int) -> bool:
    """Whether the node logged a lost response after byte ``mark`` of its log."""
    with server.log.open("rb") as log:
        log.seek(mark)
        return LOST.encode() in log.read()


def _pause(node: Any, seconds: float, server: Any) -> None:
    """Spin ``node`` for ``seconds``."""
    until = time.monotonic() + seconds
    wait_for(node, lambda: time.monotonic() > until, seconds + 1, server)


def _send(node: Any, client: Any, request: Any, timeout: float, server: Any) -> Any:
    """The answered future of one request, or None when the node lost its response."""
    mark = server.log.stat().st_size
    future = client.call_async(request)
    wait_for(node, lambda: future.done() or _lost_since(server, mark), timeout, server)
    if future.done():
        return future
    client.remove_pending_request(future)
    return None


def answer(node: Any, client: Any, request: Any, timeout: float, server: Any, *, fresh: bool = True) -> Any:
    """The response to ``request``, sent through ``client`` once its service is ready. A
    request to a reading service whose response the node says it lost is sent again; a call
    that changes something is never sent twice: a new client settles before it instead.

    ``server`` is the node's process: ``check_alive()``, ``output()`` and its ``log`` file."""
    wait_for(node, client.service_is_ready, timeout, server)
    reads = _reads(client.srv_name)
    if fresh and not reads:
        _pause(node, SETTLE, server)
    for attempt in range(5 if reads else 1):
        # A loss means the node has not yet discovered this client: give discovery longer
        # before each new attempt.
        _pause(node, SETTLE * attempt, server)
        future = _send(node, client, request, timeout, server)
        if future is not None:
            return future.result()
    pytest.fail(f"the node lost the response to {client.srv_name}; node output:\n{server.output()}")


def call_service(
    node: Any, server: Any, srv_type: Any, path: str, timeout: float = 60.0, **fields: Any
) -> Any:
    """One call of the service at ``path`` through a client of its own (:func:`answer`)."""
    client = node.create_client(srv_type, path)
    try:
        return answer(node, client, srv_type.Request(**fields), timeout, server)
    finally:
        node.destroy_client(client)


@pytest.fixture(scope="session")
def call(ros: Any, server: Server) -> Callable[..., Any]:
    """``call(CadService, "cad_service", label="K1")`` → the response, through a real client."""
    clients: dict[str, Any] = {}

    def run(srv_type: Any, name: str, timeout: float = 30.0, **fields: Any) -> Any:
        client = clients.get(name)
        fresh = client is None
        if client is None:
            client = clients[name] = ros.create_client(srv_type, f"{NAMESPACE}/{name}")
        return answer(ros, client, srv_type.Request(**fields), timeout, server, fresh=fresh)

    return run
