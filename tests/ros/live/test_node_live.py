"""The node on the mini cell, called through real rclpy clients from another process.

Expected values: tests/usecases/iema/test_services.py (hand-computed for the mini cabinet).
"""

from __future__ import annotations

import json
import math
import time
from pathlib import Path
from typing import Any

from cadkg_interfaces import srv
from geometry_msgs.msg import Pose
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

from tests.ros.live.conftest import NAMESPACE, Server, wait_for

HALF_TURN = (0.0, 0.0, 1.0, 0.0)


def xyz(msg: Any) -> tuple[float, float, float]:
    return (msg.x, msg.y, msg.z)


def close(actual: tuple[float, ...], expected: tuple[float, ...]) -> bool:
    return all(math.isclose(a, e, abs_tol=1e-9) for a, e in zip(actual, expected, strict=True))


def test_every_service_is_advertised_with_its_type(ros: Any, server: Server) -> None:
    from cadkg.ros_adapter.convert import ros_type_of
    from cadkg.services.table import services_for

    expected = {
        f"{NAMESPACE}/{s.name}": [f"cadkg_interfaces/srv/{ros_type_of(s)}"] for s in services_for("iema")
    }
    expected[f"{NAMESPACE}/sparql"] = ["cadkg_interfaces/srv/Sparql"]
    expected[f"{NAMESPACE}/reload"] = ["cadkg_interfaces/srv/Reload"]

    def advertised() -> bool:
        names = dict(ros.get_service_names_and_types())
        return all(names.get(k) == v for k, v in expected.items())

    wait_for(ros, advertised, 30.0, server)


def test_cad_service(call: Any) -> None:
    k1 = call(srv.CadService, "cad_service", label="K1")
    assert k1.success and k1.message == "ok"
    assert close(xyz(k1.original_pose.position), (0.15, 0.5, 0.0075))
    assert close(xyz(k1.dimensions), (0.03, 0.08, 0.06))
    assert close(xyz(k1.corner_pose.position), (0.15, 0.5, 0.0075))
    assert close(xyz(k1.target_pose.position), (0.165, 0.54, 0.2175))
    assert k1.target_pose.orientation.x == 1.0  # turned a half turn about x, as the reference node
    pins = {p.pin: p for p in k1.pins}
    assert sorted(pins) == ["13", "A1", "A2"]
    assert close(xyz(pins["A1"].screw.position), (0.155, 0.57, 0.0675))
    assert pins["13"].item == "ID000003" and pins["13"].has_hole and not pins["13"].missing
    assert close(xyz(pins["13"].hole.position), (0.175, 0.505, 0.0575))
    k2 = call(srv.CadService, "cad_service", label="=-K2")
    q = k2.original_pose.orientation
    assert math.isclose(abs(q.x * 0 + q.y * 0 + q.z * 1 + q.w * 0), 1.0, abs_tol=1e-9)
    assert close(xyz(k2.target_pose.position), (0.29, 0.46, 0.2175))
    nope = call(srv.CadService, "cad_service", label="NOPE")
    assert not nope.success and "NOPE" in nope.message


def test_full_cad_service(call: Any) -> None:
    result = call(srv.FullCadService, "full_cad_service", label="K1")
    assert result.success and [c.wire for c in result.connections] == ["W1", "W2", "W4"]
    w4 = result.connections[-1]
    assert w4.destination == "K9:1" and w4.missing_pin_data and w4.list_position == 3
    assert (w4.source, w4.pin, w4.target_pin, w4.connection_list) == ("orig", "A2", "1", "connections.tsv")
    by_item = call(srv.FullCadService, "full_cad_service", cad_item="ID000003")
    assert [(c.wire, c.pin, c.target_item, c.target_pin) for c in by_item.connections] == [
        ("W2", "13", "ID000005", "2:b")
    ]


def test_get_item_screw_service(call: Any) -> None:
    detected = Pose()
    detected.position.x, detected.position.y, detected.position.z = 0.16, 0.52, 0.0075
    detected.orientation.x, detected.orientation.y, detected.orientation.z, detected.orientation.w = HALF_TURN
    moved = call(srv.GetItemScrewService, "get_item_screw_service", label="K1", detected_pose=detected)
    assert moved.success and list(moved.pins) == ["13", "A1", "A2"]
    assert close(xyz(moved.screws[1].position), (0.155, 0.45, 0.0675))
    assert close(xyz(moved.holes[0].position), (0.16 - 0.025, 0.52 - 0.005, 0.0575))
    assert moved.screw_data[1].wire == "W1" and moved.screw_data[1].termination == "PUNTALINO_vite"
    bad = Pose()
    bad.orientation.w = 0.0
    refused = call(srv.GetItemScrewService, "get_item_screw_service", label="K1", detected_pose=bad)
    assert not refused.success and "quaternion" in refused.message


def test_get_terminal_data(call: Any) -> None:
    x1 = call(srv.GetTerminalData, "get_terminal_data", label="X1")
    assert x1.success and list(x1.pins) == ["1:a", "1:b", "2:a", "2:b"]
    assert close(xyz(x1.terminal_start.position), (0.25, 0.5, 0.0075))
    assert close(xyz(x1.screws[0].position), (0.2525, 0.54, 0.0475))
    assert close(xyz(x1.holes[3].position), (0.2575, 0.505, 0.0375))
    assert math.isclose(x1.length, 0.012) and math.isclose(x1.height, 0.05)
    assert not call(srv.GetTerminalData, "get_terminal_data", label="K1").success


def test_cluster_service_and_cad_reference(call: Any) -> None:
    k1 = call(srv.ClusterService, "cluster_service", label="K1")
    assert [list(c.pins) for c in k1.horizontal] == [["A1", "A2"]] and list(k1.vertical) == []
    assert k1.horizontal[0].axis == "horizontal" and len(k1.horizontal[0].points) == 2
    x1 = call(srv.ClusterService, "cluster_service", label="X1")
    assert [list(c.pins) for c in x1.vertical] == [["1:b", "1:a"], ["2:b", "2:a"]]
    reference = call(srv.CadReference, "cad_reference", label="K1")
    assert close(xyz(reference.corner_pose.position), (0.15, 0.5, 0.0075))


def test_group_connection_provider_and_reset(call: Any) -> None:
    first = call(srv.GroupConnectionProvider, "group_connection_provider", client="g")
    assert (first.wire, first.list_position, first.wire_path) == ("W1", 0, "=-U1")
    assert first.origin.label == "K1" and first.origin.pin == "A1" and first.destination.label == "X1"
    assert close(xyz(first.origin.component_pose.position), (0.165, 0.54, 0.2175))
    points = [xyz(p.position) for p in first.path_keypoints]
    assert (
        len(points) == 4
        and close(points[1], (0.155, 0.62, 0.03))
        and close(points[3], (0.2525, 0.545, 0.0375))
    )
    w2 = call(srv.GroupConnectionProvider, "group_connection_provider", client="g")
    w4 = call(srv.GroupConnectionProvider, "group_connection_provider", client="g")
    assert (w2.wire, w4.wire, w4.missing_pin_data) == ("W2", "W4", "K9:1")
    assert w4.destination.missing and not w4.destination.has_screw
    end = call(srv.GroupConnectionProvider, "group_connection_provider", client="g")
    assert end.end and end.success
    other = call(srv.GroupConnectionProvider, "group_connection_provider", client="h")
    assert other.wire == "W1"  # cursors are per client
    assert call(srv.ResetConnectionList, "reset_connection_list", client="g").success
    assert call(srv.GroupConnectionProvider, "group_connection_provider", client="g").wire == "W1"


def test_full_connection_provider(call: Any) -> None:
    def end(occupancy: bool) -> Any:
        return call(
            srv.FullConnectionProvider,
            "full_connection_provider",
            has_occupancy=True,
            occupancy=occupancy,
            client="f",
        )

    origin, again = end(False), end(False)
    assert (
        (origin.label, origin.pin, origin.direction) == ("K1", "A1", True) == (again.label, again.pin, True)
    )
    assert (origin.source, origin.connection_list, origin.list_position, origin.wire) == (
        "orig",
        "connections.tsv",
        0,
        "W1",
    )
    destination = end(True)
    assert (destination.label, destination.pin, destination.source) == ("X1", "1:a", "dest")
    assert close(xyz(destination.component_pose.position), (0.256, 0.525, 0.1975))  # X1's target
    assert end(False).wire == "W2"


def test_full_connection_provider_with_the_reference_nodes_empty_request(call: Any) -> None:
    ends = [call(srv.FullConnectionProvider, "full_connection_provider", client="e") for _ in range(3)]
    assert [(e.wire, e.source) for e in ends] == [("W1", "orig"), ("W1", "dest"), ("W2", "orig")]
    older = call(srv.FullConnectionProvider, "connection_provider_service", client="o")
    assert (older.wire, older.source, older.label) == ("W1", "orig", "K1")


def test_reset_to_connection_list(call: Any) -> None:
    moved = call(
        srv.ResetToConnectionList,
        "reset_to_connection_list",
        data=1.0,
        connection_list="connections.tsv",
        client="r",
    )
    assert moved.success and "W2" in moved.output
    assert call(srv.GroupConnectionProvider, "group_connection_provider", client="r").wire == "W2"
    human = call(srv.ResetToConnectionList, "reset_to_connection_list", data=2.0, client="r")
    assert not human.success
    dest = call(srv.ResetToConnectionList, "reset_to_connection_list", data=3.0, source="dest", client="r")
    assert dest.success
    w4 = call(srv.FullConnectionProvider, "full_connection_provider", client="r")
    assert (w4.wire, w4.source, w4.label, w4.missing_pin_data) == ("W4", "dest", "K9", True)


def test_get_item_screw_targets(call: Any) -> None:
    detected = Pose()
    # K1's target (0.165, 0.54, 0.2175), turned about x, detected 0.12 m lower.
    detected.position.x, detected.position.y, detected.position.z = 0.165, 0.42, 0.2175
    detected.orientation.x, detected.orientation.w = 1.0, 0.0
    moved = call(srv.GetItemScrewTargets, "get_item_screw_targets", label="K1", cad_pose=detected)
    assert moved.success and list(moved.pins) == ["13", "A1", "A2"]
    assert close(xyz(moved.screws[1].position), (0.155, 0.45, 0.0675))


def test_rail_scanner_and_reset(call: Any) -> None:
    rail = call(srv.RailScanner, "rail_scanner", client="s")
    assert not rail.end and rail.rail == "RAIL1" and list(rail.components_label) == ["K1", "X1", "K2"]
    assert close(xyz(rail.rail_start.position), (0.1, 0.5, 0.0))
    assert close(xyz(rail.components_dimensions[1]), (0.012, 0.05, 0.04))
    assert close(xyz(rail.component_poses[0].position), (0.15, 0.5, 0.0075))
    assert call(srv.RailScanner, "rail_scanner", client="s").end
    assert call(srv.ResetRailScanner, "reset_rail_scanner", client="s").success
    assert call(srv.RailScanner, "rail_scanner", client="s").rail == "RAIL1"


def test_sparql(call: Any) -> None:
    rows = call(
        srv.Sparql,
        "sparql",
        query="SELECT ?w WHERE { ?x ck:wireNumber ?w ; ck:missingPinData ?m } ORDER BY ?w",
        bindings_json=json.dumps({"m": True}),
        format="json",
    )
    assert rows.success, rows.message
    values = [b["w"]["value"] for b in json.loads(rows.result)["results"]["bindings"]]
    assert values == ["W4"]
    as_csv = call(
        srv.Sparql,
        "sparql",
        query='SELECT DISTINCT ?l WHERE { ?c ck:label "K1" ; ck:label ?l }',
        format="csv",
    )
    assert as_csv.success and as_csv.result.split() == ["l", "K1"]
    graph = call(
        srv.Sparql,
        "sparql",
        query='CONSTRUCT { ?c ck:label "K1" } WHERE { ?c ck:label "K1" }',
        format="turtle",
    )
    assert graph.success and '"K1"' in graph.result
    bad = call(srv.Sparql, "sparql", query="SELECT WHERE {", format="json")
    assert not bad.success and "syntax" in bad.message


def _latched() -> QoSProfile:
    return QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )


def _receive(ros: Any, server: Server, msg_type: Any, topic: str) -> Any:
    received: list[Any] = []
    subscription = ros.create_subscription(msg_type, topic, received.append, _latched())
    try:
        wait_for(ros, lambda: bool(received), 30.0, server)
    finally:
        ros.destroy_subscription(subscription)
    return received[-1]


def test_late_subscriber_gets_every_frame_on_tf_static(ros: Any, server: Server, call: Any) -> None:
    call(srv.CadReference, "cad_reference", label="K1")  # the node is up and has published long ago
    time.sleep(0.5)
    message = _receive(ros, server, TFMessage, "/tf_static")
    frames = {t.child_frame_id: t for t in message.transforms}
    assert len(frames) == len(message.transforms)
    cabinet = frames["cabinet"]
    assert cabinet.header.frame_id == "world" and close(xyz(cabinet.transform.translation), (1.0, 0.0, 0.0))
    corner = frames["K1/corner"]
    assert corner.header.frame_id == "cabinet"
    assert close(xyz(corner.transform.translation), (0.15, 0.5, 0.0075))
    assert {"K1/original", "K1/target", "X1/terminal_start", "RAIL1/start", "ID000003"} <= set(frames)
    for t in message.transforms:
        q = t.transform.rotation
        assert math.isclose(q.x**2 + q.y**2 + q.z**2 + q.w**2, 1.0, abs_tol=1e-9)


def test_gearbox_display_withdraws_and_publishes_the_cabinet_frames(
    ros: Any, server: Server, call: Any
) -> None:
    off = call(srv.GearboxDisplay, "gearbox_display")
    assert off.success and off.display is False
    withdrawn = {t.child_frame_id for t in _receive(ros, server, TFMessage, "/tf_static").transforms}
    assert "cabinet" in withdrawn and "K1/corner" not in withdrawn
    on = call(srv.GearboxDisplay, "gearbox_display")
    assert on.success and on.display is True
    published = {t.child_frame_id for t in _receive(ros, server, TFMessage, "/tf_static").transforms}
    assert {"K1/original", "K1/corner", "K1/target"} <= published


def test_markers(ros: Any, server: Server) -> None:
    message = _receive(ros, server, MarkerArray, "/cadkg/markers")
    meshes = [m for m in message.markers if m.type == Marker.MESH_RESOURCE]
    assert len(meshes) == 8
    for marker in meshes:
        assert marker.mesh_resource.startswith("file:///") and marker.mesh_resource.endswith(".stl")
        assert Path(marker.mesh_resource.removeprefix("file://")).is_file()
    arrows = [m for m in message.markers if m.type == Marker.ARROW]
    a1 = next(m for m in arrows if m.text == "K1:A1")
    assert a1.header.frame_id == "cabinet" and close(xyz(a1.points[1]), (0.155, 0.57, 0.0675))


def test_reload_swaps_the_cell_while_serving(ros: Any, call: Any, server: Server) -> None:
    """Last: edits the copied cell (approach 0.15 → 0.25 m) and reloads while calls go on."""
    before = call(srv.CadReference, "cad_reference", label="K1")
    assert close(xyz(before.target_pose.position), (0.165, 0.54, 0.2175))
    text = server.manifest.read_text()
    server.manifest.write_text(text.replace("approach_distance = 0.15", "approach_distance = 0.25"))
    reload_client = ros.create_client(srv.Reload, f"{NAMESPACE}/reload")
    query_client = ros.create_client(srv.CadReference, f"{NAMESPACE}/cad_reference")
    wait_for(ros, lambda: reload_client.service_is_ready() and query_client.service_is_ready(), 30.0, server)
    reloading = reload_client.call_async(srv.Reload.Request())
    during = [query_client.call_async(srv.CadReference.Request(label="K1")) for _ in range(5)]
    wait_for(ros, lambda: reloading.done() and all(f.done() for f in during), 30.0, server)
    assert reloading.result().success, reloading.result().message
    # Each answer comes from one whole cell, the old or the new, never a mix.
    for future in during:
        z = future.result().target_pose.position.z
        assert any(math.isclose(z, expected) for expected in (0.2175, 0.3175)), z
    after = call(srv.CadReference, "cad_reference", label="K1")
    assert close(xyz(after.target_pose.position), (0.165, 0.54, 0.3175))
    server.manifest.write_text(text.replace("approach_distance = 0.15", "approach_distance = ]"))
    broken = call(srv.Reload, "reload")
    assert not broken.success and "still serving" in broken.message
    assert close(
        xyz(call(srv.CadReference, "cad_reference", label="K1").target_pose.position), (0.165, 0.54, 0.3175)
    )
