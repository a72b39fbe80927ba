"""The node as a ROS 2 package: ``cadkg_ros`` built with colcon, its executable run as ``ros2 run``
runs it (found through the ament index), under a namespace that moves every service; markers a
volatile subscriber (RViz's default) receives; ``assign`` and ``label_frames``.

ros2launch and ros2cli have no wheels, so ``ros2 launch``/``ros2 run`` themselves are not run:
the executable they would start is, with the arguments the launch file passes, and the launch
file is checked against the node's parameters.
"""

from __future__ import annotations

import ast
import os
import shutil
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
import rclpy
from cadkg_interfaces import srv
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from visualization_msgs.msg import MarkerArray

from tests.ros.live.conftest import MINI, ROOT, call_service, underlay_environment, wait_for

PACKAGE = ROOT / "ros2" / "cadkg_ros"
LAUNCH = PACKAGE / "launch" / "cadkg.launch.py"


class _Node:
    """The installed executable in a process group of its own, stopped by SIGINT."""

    def __init__(self, command: list[str], log: Path, env: dict[str, str]) -> None:
        self.log = log
        self._out = log.open("w")
        self.process = subprocess.Popen(
            command, stdout=self._out, stderr=subprocess.STDOUT, cwd=ROOT, env=env, start_new_session=True
        )

    def check_alive(self) -> None:
        if self.process.poll() is not None:
            pytest.fail(f"the node exited with {self.process.returncode}:\n{self.output()}")

    def output(self) -> str:
        self._out.flush()
        return self.log.read_text()

    def stop(self) -> None:
        if self.process.poll() is None:
            os.killpg(self.process.pid, signal.SIGINT)
            try:
                self.process.wait(timeout=20)
            except subprocess.TimeoutExpired:
                os.killpg(self.process.pid, signal.SIGKILL)
                self.process.wait()
                pytest.fail(f"the node did not exit within 20 s of SIGINT:\n{self.output()}")
        self._out.close()


@pytest.fixture(scope="module")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """``cadkg_ros`` built and installed by colcon, as in a ROS workspace."""
    workspace = tmp_path_factory.mktemp("ws")
    (workspace / "src").mkdir()
    (workspace / "src" / "cadkg_ros").symlink_to(PACKAGE)
    build = subprocess.run(
        [
            str(Path(sys.prefix) / "bin" / "colcon"),
            "build",
            "--packages-select",
            "cadkg_ros",
            "--event-handlers",
            "console_direct-",
        ],
        cwd=workspace,
        env=underlay_environment(),
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    assert build.returncode == 0, (build.stdout + build.stderr)[-4000:]
    return workspace / "install"


def _env(install: Path) -> dict[str, str]:
    """The environment after ``. install/setup.sh``, as a ROS user has it before ``ros2 run``."""
    sourced = subprocess.run(
        ["sh", "-c", ". ./setup.sh && env -0"],
        cwd=install,
        env={**os.environ, "COLCON_CURRENT_PREFIX": str(install)},
        capture_output=True,
        timeout=60,
        check=True,
    )
    return dict(line.split("=", 1) for line in sourced.stdout.decode().split("\0") if "=" in line)


def test_the_launch_file_passes_the_parameters_the_node_declares() -> None:
    tree = ast.parse(LAUNCH.read_text())
    table = next(
        n.value
        for n in ast.walk(tree)
        if isinstance(n, ast.Assign) and ast.unparse(n.targets[0]) == "ARGUMENTS"
    )
    arguments = [ast.literal_eval(row)[0] for row in table.elts]
    assert arguments == [
        "source",
        "profile",
        "namespace",
        "approach_distance",
        "marker_period",
        "allow_assign",
        "max_query_memory",
    ]
    node = next(n for n in ast.walk(tree) if isinstance(n, ast.Call) and getattr(n.func, "id", "") == "Node")
    keywords = {k.arg: k.value for k in node.keywords}
    assert ast.literal_eval(keywords["package"]) == "cadkg_ros"
    assert ast.literal_eval(keywords["executable"]) == "cadkg_node"
    passed = {ast.literal_eval(k) for k in keywords["parameters"].elts[0].keys}
    # Every launch argument reaches the node: as a parameter, or (namespace) as its namespace.
    assert passed | {"namespace"} == set(arguments)
    source = ast.parse((ROOT / "src" / "cadkg" / "ros_adapter" / "node.py").read_text())
    declared = {
        ast.literal_eval(call.args[0])
        for call in ast.walk(source)
        if isinstance(call, ast.Call) and getattr(call.func, "attr", "") == "declare_parameter"
    }
    assert passed <= declared


def test_the_package_is_indexed_and_its_executable_installed(installed: Path) -> None:
    probe = (
        "from ament_index_python.packages import get_package_prefix; print(get_package_prefix('cadkg_ros'))"
    )
    found = subprocess.run(
        [sys.executable, "-c", probe],
        env=_env(installed),
        capture_output=True,
        text=True,
        timeout=60,
        check=False,
    )
    assert found.returncode == 0, found.stderr
    prefix = Path(found.stdout.strip())
    assert os.access(prefix / "lib" / "cadkg_ros" / "cadkg_node", os.X_OK)
    assert (prefix / "share" / "cadkg_ros" / "launch" / "cadkg.launch.py").is_file()


@pytest.fixture(scope="module")
def cell2(installed: Path, ros: Any, tmp_path_factory: pytest.TempPathFactory) -> Iterator[_Node]:
    """The installed executable on a store of the mini cell, under the namespace /cell2, as
    ``ros2 run cadkg_ros cadkg_node --ros-args -r __ns:=/cell2 ...`` starts it."""
    folder = tmp_path_factory.mktemp("cell2")
    shutil.copytree(MINI, folder / "mini")
    store = folder / "store"
    built = subprocess.run(
        [
            sys.executable,
            "-m",
            "cadkg.cli",
            "build",
            str(folder / "mini" / "manifest.toml"),
            "--store",
            str(store),
        ],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert built.returncode == 0, built.stderr
    executable = installed / "cadkg_ros" / "lib" / "cadkg_ros" / "cadkg_node"
    node = _Node(
        [
            str(executable),
            "--ros-args",
            "-r",
            "__ns:=/cell2",
            "-p",
            f"source:={store}",
            "-p",
            "marker_period:=0.5",
            "-p",
            "allow_assign:=true",
        ],
        folder / "node.log",
        _env(installed),
    )
    yield node
    node.stop()


def _services_of(ros: Any, prefix: str) -> set[str]:
    return {name for name, _ in ros.get_service_names_and_types() if name.startswith(prefix)}


def test_a_namespace_moves_every_service(ros: Any, cell2: _Node) -> None:
    client = ros.create_client(srv.CadReference, "/cell2/gearbox_handler/cad_reference")
    wait_for(ros, client.service_is_ready, 90.0, cell2)
    future = client.call_async(srv.CadReference.Request(label="K1"))
    wait_for(ros, future.done, 30.0, cell2)
    assert future.result().success
    deadline = time.monotonic() + 30
    expected = {
        "cad_service",
        "full_cad_service",
        "get_item_screw_service",
        "get_terminal_data",
        "cluster_service",
        "cad_reference",
        "full_connection_provider",
        "group_connection_provider",
        "reset_connection_list",
        "reset_to_connection_list",
        "rail_scanner",
        "reset_rail_scanner",
        # the reference node's own names, under its namespace
        "get_item_screw_targets",
        "connection_provider_service",
        "gearbox_display",
        "sparql",
        "reload",
        "assign",
        "report_progress",
        "replan",
        "label_frames",
    }
    while {s.rsplit("/", 1)[-1] for s in _services_of(ros, "/cell2/gearbox_handler/")} < expected:
        assert time.monotonic() < deadline, sorted(_services_of(ros, "/cell2/"))
        rclpy.spin_once(ros, timeout_sec=0.1)
    # Nothing of this node is left outside its namespace. Discovery may list the node's services
    # before the node's own name, and asking by a name not yet discovered raises.
    while ("cadkg", "/cell2") not in ros.get_node_names_and_namespaces():
        assert time.monotonic() < deadline, ros.get_node_names_and_namespaces()
        rclpy.spin_once(ros, timeout_sec=0.1)
    ours = [name for name, _ in ros.get_service_names_and_types_by_node("cadkg", "/cell2")]
    assert ours and all(name.startswith("/cell2/") for name in ours)


def test_a_volatile_subscriber_receives_the_markers(ros: Any, cell2: _Node) -> None:
    received: list[MarkerArray] = []
    volatile = QoSProfile(
        depth=1, reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE
    )
    # Subscribed well after the node published its markers once: only a republication arrives.
    subscription = ros.create_subscription(MarkerArray, "/cell2/cadkg/markers", received.append, volatile)
    try:
        wait_for(ros, lambda: bool(received), 30.0, cell2)
    finally:
        ros.destroy_subscription(subscription)
    markers = received[0].markers
    assert markers[0].action == markers[0].DELETEALL
    assert any(m.type == m.MESH_RESOURCE for m in markers) and any(m.type == m.ARROW for m in markers)


def _call(ros: Any, node: _Node, srv_type: Any, name: str, **fields: Any) -> Any:
    return call_service(ros, node, srv_type, f"/cell2/gearbox_handler/{name}", **fields)


def test_label_frames_maps_labels_to_frame_ids(ros: Any, cell2: _Node) -> None:
    answer = _call(ros, cell2, srv.LabelFrames, "label_frames", label="K1")
    assert answer.success, answer.message
    assert set(answer.labels) == {"K1"}
    assert {"K1/original", "K1/corner", "K1/target"} <= set(answer.frame_ids)
    everything = _call(ros, cell2, srv.LabelFrames, "label_frames", label="")
    assert len(everything.labels) == len(everything.frame_ids) > len(answer.frame_ids)
    unknown = _call(ros, cell2, srv.LabelFrames, "label_frames", label="NOPE")
    assert not unknown.success and list(unknown.frame_ids) == []


def test_assign_changes_what_the_provider_gives_at_once(ros: Any, cell2: _Node) -> None:
    first = _call(ros, cell2, srv.GroupConnectionProvider, "group_connection_provider", client="assign-test")
    assert not first.end
    reset = _call(ros, cell2, srv.ResetConnectionList, "reset_connection_list", client="assign-test")
    assert reset.success
    assigned = _call(ros, cell2, srv.Assign, "assign", kind="wire", id=first.wire, performer="human")
    assert assigned.success, assigned.message
    assert assigned.target.endswith(f"wire/{first.wire}") and "kept in the store" in assigned.message
    after = _call(ros, cell2, srv.GroupConnectionProvider, "group_connection_provider", client="assign-test")
    assert after.wire != first.wire  # the human's wire is skipped from the next call on
    undone = _call(ros, cell2, srv.Assign, "assign", kind="wire", id=first.wire, performer="robot")
    assert undone.success
    bad = _call(ros, cell2, srv.Assign, "assign", kind="wire", id="NO-SUCH-WIRE", performer="human")
    assert not bad.success and "NO-SUCH-WIRE" in bad.message


def test_report_progress_is_kept_and_the_provider_skips_what_is_done(ros: Any, cell2: _Node) -> None:
    first = _call(
        ros, cell2, srv.GroupConnectionProvider, "group_connection_provider", client="progress-test"
    )
    assert not first.end
    reset = _call(ros, cell2, srv.ResetConnectionList, "reset_connection_list", client="progress-test")
    assert reset.success
    done = _call(ros, cell2, srv.ReportProgress, "report_progress", task=first.wire, state="done", reason="")
    assert done.success and done.status == "done", done.message
    assert done.target.endswith(f"wire/{first.wire}") and "kept in the store" in done.message
    after = _call(
        ros, cell2, srv.GroupConnectionProvider, "group_connection_provider", client="progress-test"
    )
    assert after.wire != first.wire  # the wire done is skipped from the next call on
    for task, state in (("NO-SUCH-WIRE", "done"), (first.wire, "finished")):
        bad = _call(ros, cell2, srv.ReportProgress, "report_progress", task=task, state=state, reason="")
        assert not bad.success and (task if state == "done" else state) in bad.message


def test_replan_gives_a_wire_to_a_person_with_the_times_before_and_after(ros: Any, cell2: _Node) -> None:
    first = _call(ros, cell2, srv.GroupConnectionProvider, "group_connection_provider", client="replan-test")
    assert not first.end
    answer = _call(ros, cell2, srv.Replan, "replan", task=first.wire, performer="human")
    assert answer.success, answer.message
    moved = [(m.task, m.before, m.after) for m in answer.moved]
    assert (first.wire, "robot", "human") in moved, moved
    assert answer.person_time_s > answer.person_time_s_before
    step = next(s for s in answer.steps if s.task == first.wire)
    assert (step.performer, step.status) == ("human", "pending") and step.end_s > step.start_s
    reset = _call(ros, cell2, srv.ResetConnectionList, "reset_connection_list", client="replan-test")
    assert reset.success
    after = _call(ros, cell2, srv.GroupConnectionProvider, "group_connection_provider", client="replan-test")
    assert after.wire != first.wire  # a person's now: the provider skips it
    bad = _call(ros, cell2, srv.Replan, "replan", task="NO-SUCH-WIRE", performer="human")
    assert not bad.success and "NO-SUCH-WIRE" in bad.message
    back = _call(ros, cell2, srv.Replan, "replan", task=first.wire, performer="robot")
    assert back.success and [(m.task, m.after) for m in back.moved] == [(first.wire, "robot")]
