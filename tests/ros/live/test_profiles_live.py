"""The node serving the ELVEZ, ELIMCO, Volkswagen and ENKI examples, called through real rclpy clients.

One node per profile, each in its own process under its own name and namespace; expected
values are the hand computations in each example's README.
"""

from __future__ import annotations

import math
import shutil
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from cadkg_interfaces import srv
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

from tests.ros.live.conftest import ROOT, Server, call_service, wait_for
from tests.ros.live.test_node_live import _latched

NAMESPACES = {"elvez": "/elvez", "elimco": "/elimco", "vw": "/vw_harness", "enki": "/enki"}
EXAMPLES = {"elvez": "elvez-cell", "elimco": "elimco-bench", "vw": "vw-harness", "enki": "enki-hose"}


@pytest.fixture(scope="module", params=sorted(EXAMPLES))
def profile(
    request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory
) -> Iterator[tuple[str, Server]]:
    name = str(request.param)
    cell = tmp_path_factory.mktemp(name) / EXAMPLES[name]
    shutil.copytree(ROOT / "examples" / EXAMPLES[name], cell)
    running = Server(cell / "manifest.toml", cell.parent / "node.log", node_name=f"cadkg_{name}")
    yield name, running
    running.stop()


def _call(ros: Any, server: Server, namespace: str) -> Callable[..., Any]:
    def run(srv_type: Any, service: str, **fields: Any) -> Any:
        return call_service(ros, server, srv_type, f"{namespace}/{service}", **fields)

    return run


def _frames(ros: Any, server: Server, wanted: str) -> dict[str, Any]:
    """The /tf_static message (of any node) holding frame ``wanted``, from a late subscriber."""
    found: dict[str, Any] = {}

    def keep(message: TFMessage) -> None:
        frames = {t.child_frame_id: t for t in message.transforms}
        if wanted in frames:
            found.update(frames)

    subscription = ros.create_subscription(TFMessage, "/tf_static", keep, _latched())
    try:
        wait_for(ros, lambda: bool(found), 60.0, server)
    finally:
        ros.destroy_subscription(subscription)
    return found


def close(actual: tuple[float, ...], expected: tuple[float, ...], tol: float = 1e-6) -> bool:
    return all(math.isclose(a, e, abs_tol=tol) for a, e in zip(actual, expected, strict=True))


def test_every_service_of_the_profile_answers(ros: Any, profile: tuple[str, Server]) -> None:
    from cadkg.ros_adapter.convert import ros_service_name, ros_type_of
    from cadkg.services.table import services_for

    name, server = profile
    namespace = NAMESPACES[name]
    call = _call(ros, server, namespace)
    expected = {
        ros_service_name(s, namespace): [f"cadkg_interfaces/srv/{ros_type_of(s)}"] for s in services_for(name)
    }
    wait_for(
        ros,
        lambda: all(dict(ros.get_service_names_and_types()).get(k) == v for k, v in expected.items()),
        60.0,
        server,
    )

    if name == "elvez":
        j1 = call(srv.GuideInfo, "guide_info", name="J1", frame="")
        assert j1.success and j1.id == "ID0002" and j1.frame == "robot_base"
        p, q = j1.key_frame.position, j1.key_frame.orientation
        assert close((p.x, p.y, p.z), (0.662, -0.305, 0.345))
        assert close((q.x, q.y, q.z, q.w), (0.0, 0.0, -0.7071068, 0.7071068))
        assert close((j1.key_length, j1.key_gap, j1.key_height), (0.010, 0.008, 0.030))
        assert not call(srv.GuideInfo, "guide_info", name="J99", frame="").success
        cable = call(srv.CableInfo, "cable_info", name="CA5")
        assert (
            cable.success
            and cable.wh == 1
            and cable.connector == "GR12"
            and list(cable.con_index) == [4, 0, 1, 0]
        )
        assert call(srv.ConInfo, "con_info", name="WH1").success
        assert call(srv.WhInfo, "wh_info", number=2).success
        assert list(call(srv.AllTools, "all_tools").names) == ["gun", "gripper"]
        assert call(srv.ToolInfo, "tool_info", name="gun").success
        plan = call(srv.AllOp, "all_op")
        assert plan.success and [op.index for op in plan.operations] == list(range(1, 10))
        first = call(srv.IndexOp, "index_op", index=1)
        assert first.success and first.type == "EC" and list(first.spot) == ["C1.1.L"]
        assert call(srv.WhRoutes, "wh_routes", number=1).success
        reference = _call(ros, server, "/CAD_platform")
        guide = reference(srv.PlatformGuideInfo, "guide_info", jig="J1", guide="1")
        p = guide.data.key_center_frame.position
        assert guide.success and close((p.x, p.y, p.z), (0.662, -0.305, 0.345))
        assert list(guide.data.collisions) == [0.0, 0.01, -0.008, 0.022]
        unset = guide.data.jig_corner_frame.orientation
        assert (unset.x, unset.y, unset.z, unset.w) == (0.0, 0.0, 0.0, 1.0)
        connector = reference(srv.ConnectorInfo, "connector_info", label="WH1")
        assert connector.wh == "1" and [c.label for c in connector.cables][:2] == ["CA1", "CA2"]
        assert reference(srv.PlatformCableInfo, "cable_info", label="CA5").length == 620.0
        assert reference(srv.TrayInfo, "tray_info", box="B1", tray="2").wh == "2"
        assert len(reference(srv.JigInfo, "jig_info", jig="J3").taping_spots) == 1
        assert reference(srv.TapingSpotInfo, "taping_spot_info", jig="J3", spot="1").success
        assert [g.id for g in reference(srv.GuideAllInfo, "all_guides").data] == [
            "J1",
            "J2",
            "J3",
            "J3",
            "J4",
        ]
        assert len(reference(srv.AllCadComponents, "all_cad_components").data) == 8
        assert list(reference(srv.GetList, "get_tools_service").data) == ["gun", "gripper"]
        assert reference(srv.PlatformToolInfo, "tool_info", name="gripper").type == "gripper"
        assert len(reference(srv.AllOperations, "all_operations", client="").data) == 9
        step = reference(srv.NextOperation, "next_operation", client="arm")
        assert (step.type, step.spot[0].jig, step.spot[0].side, step.end) == ("EC", "C1", "L", False)
        assert reference(srv.NextOperation, "next_operation", client="arm").type == "PC"
        assert reference(srv.NextOperation, "next_operation", client="other").type == "EC"
        last = reference(srv.IndexOperation, "index_operation", index=8, client="arm")
        assert (last.type, last.index, last.end) == ("TJ", 0, True)
        assert not reference(srv.ResetTo, "reset_sequence_list_to", index=9, client="arm").success
        assert reference(srv.ResetSequenceList, "reset_sequence_list", client="arm").success
    elif name == "elimco":
        centred = call(
            srv.GetPinPositions, "get_pin_positions", use_centroid=True, pin_connector_distance=0.0
        )
        assert centred.success and centred.frame == "pins_centroid"
        assert close((centred.centroid.position.x, centred.centroid.position.y), (11.939, 2.724))
        pins = {p.name: p for p in centred.pins}
        assert close((pins["A1UZ3C"].pose.position.x, pins["A1UZ3C"].pose.position.y), (0.461, -0.722))
        assert pins["pin_1_doble"].is_double and close((pins["pin_1_doble"].double_distance,), (0.02,))
        assert len(call(srv.PinFrames, "pin_frames").frames) > len(pins)
        cables = call(srv.GetCableList, "get_cable_list")
        assert cables.success and {c.name for c in cables.cables} >= {
            "A4351-1669",
            "A4351-2401",
            "A4351-1677",
        }
        path = call(srv.GetPathPositions, "get_path_positions", cable="A4351-1677")
        assert path.success and close((path.total_length,), (1.168,))
        # Declared as loading files: a node started without allow_assign refuses it.
        refused = call(
            srv.LoadFiles, "load_files", paths=[str(ROOT / "examples" / "elimco-bench" / "pin_info.xml")]
        )
        assert not refused.success and "allow_assign:=true" in refused.message
    elif name == "vw":
        topology = call(srv.HarnessTopology, "harness_topology", harness="DOOR-L", view="")
        assert topology.success and len(topology.segments) == 5 and len(topology.wires) == 7
        assert "<graphml" in topology.graphml[:200] and topology.graphml.count("<edge ") == 5
    else:
        hose = call(srv.HoseInfo, "hose_info", product="HX-25")
        assert hose.success and close((hose.diameter, hose.bend_radius), (0.0254, 0.125))
        assert math.isnan(hose.length) and hose.material == "PVC"
        assert not call(srv.HoseInfo, "hose_info", product="HX-99").success


def test_tf_static_and_markers_of_the_profile(ros: Any, profile: tuple[str, Server]) -> None:
    name, server = profile
    if name == "elvez":
        frames = _frames(ros, server, "ID0002platformguide1")
        assert frames["ID0002platformguide1"].header.frame_id == "ID0002platform"
        assert {"ID0002combs", "robot_base", "platform_rf", "ID000002ATC_ATC_base_gun"} <= set(frames)
        meshes: list[Marker] = []

        def keep(message: MarkerArray) -> None:
            meshes.extend(m for m in message.markers if m.ns == "elements")

        subscription = ros.create_subscription(MarkerArray, "/cadkg_elvez/markers", keep, _latched())
        try:
            wait_for(ros, lambda: bool(meshes), 60.0, server)
        finally:
            ros.destroy_subscription(subscription)
        j1 = next(m for m in meshes if m.text == "J1")
        assert j1.type == Marker.MESH_RESOURCE and j1.header.frame_id == "ID0002platform"
        assert Path(j1.mesh_resource.removeprefix("file://")).is_file()
    elif name == "elimco":
        frames = _frames(ros, server, "pins_centroid")
        assert any(f.startswith("pin_") for f in frames)
    else:
        server.check_alive()  # no geometry of their own: the manifest's frames only
