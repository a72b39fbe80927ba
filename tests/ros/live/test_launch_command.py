"""The node started with only ``--ros-args`` parameters, as a launch file or ``ros2 run`` starts
it; an absolute ``namespace`` parameter pins its services there (test_package_live.py checks
the launch file itself and the relative names a node namespace moves)."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

from cadkg_interfaces import srv

from tests.ros.live.conftest import MINI, ROOT, wait_for


class _Process:
    def __init__(self, process: subprocess.Popen[bytes], log: Path) -> None:
        self.process, self.log = process, log

    def check_alive(self) -> None:
        assert self.process.poll() is None, self.log.read_text()

    def output(self) -> str:
        return self.log.read_text()


def test_the_launch_command_line_serves_the_cell(ros: Any, tmp_path: Path) -> None:
    cell = tmp_path / "mini"
    shutil.copytree(MINI, cell)
    log = tmp_path / "node.log"
    with log.open("w") as out:
        process = subprocess.Popen(
            [sys.executable, "-m", "cadkg.ros_adapter", "--ros-args", "-r", "__node:=cadkg_launched",
             "-p", f"source:='{cell / 'manifest.toml'}'", "-p", "profile:=''",
             "-p", "namespace:='/launched'", "-p", "approach_distance:=-1.0"],
            stdout=out, stderr=subprocess.STDOUT, cwd=ROOT,
        )  # fmt: skip
    server = _Process(process, log)
    client = ros.create_client(srv.CadReference, "/launched/cad_reference")
    try:
        wait_for(ros, client.service_is_ready, 60.0, server)
        future = client.call_async(srv.CadReference.Request(label="K1"))
        wait_for(ros, future.done, 30.0, server)
        answer = future.result()
        assert answer.success
        # tests/usecases/iema/test_services.py: K1's corner in the mini cabinet.
        corner = answer.corner_pose.position
        assert (round(corner.x, 9), round(corner.y, 9), round(corner.z, 9)) == (0.15, 0.5, 0.0075)
    finally:
        ros.destroy_client(client)
        process.terminate()
        try:
            process.wait(timeout=20)
        except subprocess.TimeoutExpired:
            process.kill()  # not left behind: a hung node would outlive the test run
            process.wait()
            message = f"the node did not exit within 20 s of SIGTERM:\n{server.output()}"
            raise AssertionError(message) from None
