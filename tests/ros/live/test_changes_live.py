"""The change feed over ROS: a real rclpy subscriber hears each change set on graph_changes."""

from __future__ import annotations

import json
import shutil
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from cadkg_interfaces import srv
from cadkg_interfaces.msg import GraphChanges
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from tests.ros.live.conftest import MINI, Server, call_service, wait_for

NAMESPACE = "/changes_test"


@pytest.fixture(scope="module")
def feeding(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    cell = tmp_path_factory.mktemp("changes") / "mini"
    shutil.copytree(MINI, cell)
    running = Server(
        cell / "manifest.toml",
        cell.parent / "node.log",
        node_name="cadkg_changes",
        extra=["--allow-assign", "--ros-args", "-r", f"__ns:={NAMESPACE}"],
    )
    yield running
    running.stop()


def _call(ros: Any, server: Server, srv_type: Any, name: str, **fields: Any) -> Any:
    return call_service(ros, server, srv_type, f"{NAMESPACE}/gearbox_handler/{name}", **fields)


def _heard(ros: Any, server: Server, wanted: str) -> Any:
    """The latest message on graph_changes, once it names ``wanted`` among the changed things."""
    qos = QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    received: list[Any] = []
    subscription = ros.create_subscription(GraphChanges, f"{NAMESPACE}/graph_changes", received.append, qos)
    try:
        wait_for(ros, lambda: any(wanted in m.changed_ids for m in received), 120.0, server)
    finally:
        ros.destroy_subscription(subscription)
    return next(m for m in received if wanted in m.changed_ids)


def test_a_subscriber_hears_a_reload_and_an_assignment(ros: Any, feeding: Server) -> None:
    assert _call(ros, feeding, srv.Sparql, "sparql", query="ASK { ?s ?p ?o }", format="json").success
    landed = _call(ros, feeding, srv.GroupConnectionProvider, "group_connection_provider", client="arm")
    assert landed.success and landed.wire == "W1"
    lists = Path(feeding.manifest).parent / "connections.tsv"
    lists.write_text(lists.read_text(encoding="utf-8").replace("\tW1\t", "\tW11\t"), encoding="utf-8")
    reloaded = _call(ros, feeding, srv.Reload, "reload")
    assert reloaded.success, reloaded.message
    message = _heard(ros, feeding, "W11")
    # The wire renumbered, and the file it is listed in.
    assert (message.changed, message.added, message.removed) == (2, 0, 0)
    assert sorted(zip(message.changed_kinds, message.changed_ids, strict=True)) == [
        ("file", "connections.tsv"),
        ("wire", "W11"),
    ]
    (wire,) = [c for c in json.loads(message.json)["changed"] if c["kind"] == "wire"]
    assert wire["attributes"] == {"number": ["W1", "W11"]}
    # The arm had landed W1: renumbered, it is to be redone; the reload says where the cursor is.
    impact = json.loads(message.json)["impact"]
    assert [(i["id"], i["passed_by"]) for i in impact["redo"]] == [("W11", ["iema cursor of arm"])]
    assert "iema cursor of arm: on wire W2" in impact["cursors"]
    assigned = _call(ros, feeding, srv.Assign, "assign", kind="wire", id="W2", performer="human")
    assert assigned.success, assigned.message
    message = _heard(ros, feeding, "W2")
    assert list(message.changed_kinds) == ["wire"] and list(message.changed_ids) == ["W2"]
    assert json.loads(message.json)["changed"][0]["attributes"]["performer"] == [None, "human"]
