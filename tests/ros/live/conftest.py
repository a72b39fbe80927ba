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

ROOT = Path(__file__).resolve().parents[3]
MINI = ROOT / "tests" / "data" / "cells" / "mini"
NAMESPACE = "/gearbox_handler"


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


@pytest.fixture(scope="session")
def call(ros: Any, server: Server) -> Callable[..., Any]:
    """``call(CadService, "cad_service", label="K1")`` → the response, through a real client."""
    clients: dict[str, Any] = {}

    def run(srv_type: Any, name: str, timeout: float = 30.0, **fields: Any) -> Any:
        client = clients.get(name)
        if client is None:
            client = clients[name] = ros.create_client(srv_type, f"{NAMESPACE}/{name}")
        wait_for(ros, lambda: client.service_is_ready(), timeout, server)
        future = client.call_async(srv_type.Request(**fields))
        wait_for(ros, future.done, timeout, server)
        return future.result()

    return run
