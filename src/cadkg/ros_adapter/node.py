"""The ROS 2 node: the services of :data:`cadkg.services.table.SERVICES`, SPARQL, reload, TF and markers.

Run it with the Python of ``.venv-ros`` (``scripts/ros-setup.sh``): ``cadkg ros SOURCE`` or
``python -m cadkg.ros_adapter SOURCE``. See ``docs/ros.md``.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import json
import math
import threading
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import rclpy
from builtin_interfaces.msg import Duration
from geometry_msgs.msg import Point, TransformStamped
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

import cadkg.registry as registry
import cadkg.services.table as services
from cadkg.errors import CadkgError
from cadkg.limited import DEFAULT_QUERY_MEMORY
from cadkg.query.workers import WorkerPool
from cadkg.ros_adapter import convert
from cadkg.ros_adapter.changes import ros_feed
from cadkg.ros_adapter.sparql import SPARQL_TEXT_TASK, sparql_text
from cadkg.served.holder import GraphHolder, Served
from cadkg.served.target import model_with, open_target
from cadkg.services.frames import Shown, shown
from cadkg.store import cell_profile

__all__ = ["CadkgNode", "default_namespace", "main", "sparql_text", "srv_type"]

DEFAULT_NAMESPACE = "/cadkg"
# Seconds between two publications of the markers (see CadkgNode).
MARKER_PERIOD = 2.0


def default_namespace(profile: str) -> str:
    """Where a use case's services are served unless the node is told otherwise."""
    try:
        return registry.use_case(profile).ros_namespace or DEFAULT_NAMESPACE
    except KeyError:
        return DEFAULT_NAMESPACE


def srv_type(name: str) -> Any:
    """The ``cadkg_interfaces`` service class of a service (``cad_service`` → ``CadService``;
    a service that names its own type, that type)."""
    module = importlib.import_module("cadkg_interfaces.srv")
    service = services.SERVICES.get(name)
    return getattr(
        module, convert.ros_type_of(service) if service is not None else convert.srv_type_name(name)
    )


@functools.cache
def _fields_of(type_name: str) -> dict[str, str]:
    # Asked for every nested message of every response: built once per message type.
    return dict(_resolve(type_name)().get_fields_and_field_types())


@functools.cache
def _resolve(type_name: str) -> Any:
    package, _, name = type_name.partition("/")
    if "/" in name:  # "pkg/msg/Name"
        name = name.rsplit("/", 1)[-1]
    return getattr(importlib.import_module(f"{package}.msg"), name)


def _latched(depth: int = 1) -> QoSProfile:
    return QoSProfile(
        depth=depth,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )


class CadkgNode:
    """Wraps an rclpy node (``cadkg``) that serves one cell."""

    def __init__(self, node_name: str = "cadkg", parameter_overrides: Sequence[Any] | None = None) -> None:
        self.node = Node(node_name, parameter_overrides=list(parameter_overrides or []))
        node = self.node
        node.declare_parameter("source", "")
        node.declare_parameter("profile", "")
        node.declare_parameter("namespace", "")
        node.declare_parameter("approach_distance", -1.0)
        node.declare_parameter("marker_period", MARKER_PERIOD)
        node.declare_parameter("allow_assign", False)
        node.declare_parameter("max_query_memory", DEFAULT_QUERY_MEMORY)
        self.source = str(node.get_parameter("source").value)
        if not self.source:
            raise CadkgError("parameter 'source' (a manifest or a store directory) is required")
        distance = float(node.get_parameter("approach_distance").value)
        self.approach_distance = distance if distance >= 0 and math.isfinite(distance) else None
        self.allow_assign = bool(node.get_parameter("allow_assign").value)
        self.query_memory = max(int(node.get_parameter("max_query_memory").value), 0)
        self._publishing = threading.Lock()  # one publication of the frames at a time

        def load() -> Any:
            return open_target(self.source, writable=self.allow_assign)

        first = load()
        self.profile = str(node.get_parameter("profile").value) or cell_profile(first)
        model = None if self.approach_distance is None else model_with({"approach_distance": distance})
        # The one served-cell holder of every transport: a call takes the current graph and its
        # session; a reload or a change carries the cursors over to the graph served next.
        self.holder = GraphHolder(first, load, model=model, profile=self.profile)
        # Relative names: the node's namespace (``--ros-args -r __ns:=/cell2``, a launch file's
        # ``namespace``) moves every service. An absolute ``namespace`` parameter pins them.
        pinned = str(node.get_parameter("namespace").value)
        if pinned.startswith("/"):
            self.namespace = pinned.rstrip("/")
        else:
            self.namespace = (pinned or default_namespace(self.profile)).strip("/")
        group = ReentrantCallbackGroup()
        # Every operation of the table (assign, plan, label_frames, reload and the use case's
        # services), then SPARQL, which each transport speaks its own way.
        self._services = [
            node.create_service(
                srv_type(s.name),
                self.name_of(s.ros_name or s.name, s.ros_namespace),
                self._callback(s.name),
                callback_group=group,
            )
            for s in services.served_for(self.profile)
        ]
        self._services.append(
            node.create_service(
                srv_type("sparql"), self.name_of("sparql"), self._sparql, callback_group=group
            )
        )
        self._tf = node.create_publisher(TFMessage, "/tf_static", _latched())
        self._markers = node.create_publisher(MarkerArray, "~/markers", _latched())
        self._marker_message: MarkerArray | None = None
        self.publish()
        self.changes = ros_feed(node, self.holder, self._revision)
        self.changes.changed(self.holder.current)  # what the first change is compared with
        # RViz's Marker display subscribes volatile by default: it sees what is published after
        # it joined, so the markers go out again every marker_period seconds (0: only once).
        period = float(node.get_parameter("marker_period").value)
        if period > 0 and math.isfinite(period):
            node.create_timer(
                period, self._republish_markers, callback_group=MutuallyExclusiveCallbackGroup()
            )
        resolved = node.resolve_service_name(self.name_of("sparql")).rsplit("/", 1)[0]
        node.get_logger().info(
            f"serving {self.source} (profile {self.profile or '-'}) under {resolved}: "
            f"{len(self._services)} services"
        )

    def name_of(self, service: str, namespace: str = "") -> str:
        """The name a service is created with: relative to the node's namespace unless the
        ``namespace`` parameter, or the service's own namespace (``namespace``), is absolute."""
        if namespace:
            prefix = namespace.rstrip("/") if namespace.startswith("/") else namespace.strip("/")
        else:
            prefix = self.namespace
        return f"{prefix}/{service}"

    # -- services ---------------------------------------------------------------------
    def _callback(self, name: str) -> Any:
        service = services.SERVICES[name]

        def handle(request: Any, response: Any) -> Any:
            try:
                refusal = self.refusal(name)
                if refusal:
                    raise CadkgError(refusal)
                params = convert.request_params(service.params, request)
                result = self.holder.run(name, params, convert.client_of(request))
                data = (
                    convert.response(result)
                    if type(result).__name__ in convert.FIELDS
                    else convert.typed_response(result, response.get_fields_and_field_types(), _fields_of)
                )
            except CadkgError as err:
                data = {"success": False, "message": str(err)}
            else:
                if service.changes_frames:
                    self.publish()
            return convert.fill(response, data, _resolve)

        return handle

    def _sparql(self, request: Any, response: Any) -> Any:
        try:
            bindings = json.loads(request.bindings_json) if request.bindings_json.strip() else {}
            if not isinstance(bindings, dict):
                raise CadkgError("bindings_json: expected a JSON object of variable -> value")
            args = (request.query, bindings, request.format)
            served = self.holder.acquire()
            try:
                workers = served.workers(self._make_workers)
                if workers is None:  # a remote store evaluates the query itself
                    response.result = sparql_text(served.graph, *args)
                else:
                    response.result = workers.call(SPARQL_TEXT_TASK, args, seconds=math.inf)
            finally:
                served.release()
            response.success, response.message = True, "ok"
        except (CadkgError, ValueError) as err:
            response.success, response.message = False, str(err)
        return response

    def _make_workers(self, graph: Any) -> WorkerPool | None:
        """The worker answering ``sparql`` (no network, bounded memory: see :mod:`cadkg.limited`)
        over the graph as it is now; the holder makes it again after every change."""
        if graph.remote:
            return None
        return WorkerPool(graph, preload=("cadkg.ros_adapter.sparql",), memory=self.query_memory)

    def refusal(self, name: str) -> str:
        """Why a service is refused here ("" when it is served): a change to the graph, as its
        declared effect says (``assign`` is one), needs ``allow_assign``; a cursor is the
        calling client's own, as every answer is."""
        service = services.SERVICES.get(name)
        if service is not None and service.effect.changes_graph and not self.allow_assign:
            return f"{name} changes the graph; this node does not: start it with allow_assign:=true"
        return ""

    # -- TF and markers -------------------------------------------------------------------
    def _shown(self) -> Shown:
        served = self.holder.acquire()
        try:
            with served.lock:
                return shown(served.session())
        finally:
            served.release()

    def publish(self) -> None:
        """Publish every frame on /tf_static and the markers, latched."""
        with self._publishing:
            self._publish()

    def _publish(self) -> None:
        view = self._shown()
        if view.error:
            # The profile's services report the same error to every caller; the cell's own
            # frames still go out.
            self.node.get_logger().error(f"{self.profile} frames not published: {view.error}")
        frames, specs = view.frames, view.markers
        stamp = self.node.get_clock().now().to_msg()
        transforms = []
        for frame in frames:
            t = TransformStamped()
            t.header.stamp = stamp
            t.header.frame_id = frame.parent
            t.child_frame_id = frame.child
            x, y, z = frame.pose.position
            t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = x, y, z
            qx, qy, qz, qw = frame.pose.orientation
            rotation = t.transform.rotation
            rotation.x, rotation.y, rotation.z, rotation.w = qx, qy, qz, qw
            transforms.append(t)
        self._tf.publish(TFMessage(transforms=transforms))
        markers = [Marker(ns="", action=Marker.DELETEALL)]
        for spec in specs:
            marker = Marker()
            marker.header.stamp = stamp
            marker.header.frame_id = spec.frame_id
            marker.ns, marker.id, marker.action = spec.ns, spec.id, Marker.ADD
            marker.lifetime = Duration()
            marker.frame_locked = True
            convert.fill(marker.pose, convert.pose(spec.pose), _resolve)
            if spec.kind == "mesh":
                marker.type = Marker.MESH_RESOURCE
                marker.mesh_resource = spec.mesh_uri
                marker.scale.x = marker.scale.y = marker.scale.z = 1.0
                marker.color.r = marker.color.g = marker.color.b = 0.7
                marker.color.a = 1.0
            else:
                marker.type = Marker.ARROW
                marker.points = [Point(x=p[0], y=p[1], z=p[2]) for p in spec.points]
                marker.scale.x, marker.scale.y, marker.scale.z = 0.001, 0.002, 0.004
                marker.color.r, marker.color.g, marker.color.b, marker.color.a = 0.9, 0.2, 0.1, 1.0
            marker.text = spec.text
            markers.append(marker)
        self._marker_message = MarkerArray(markers=markers)
        self._markers.publish(self._marker_message)

    def _republish_markers(self) -> None:
        if self._marker_message is not None:
            self._markers.publish(self._marker_message)

    def _revision(self, served: Served) -> str:
        """What a served graph is called in a change set: its generation, or its source."""
        return str(getattr(served.graph, "generation", None) or self.source)

    def destroy(self) -> None:
        self.changes.shutdown()
        self.node.destroy_node()
        self.holder.close()


def _arguments(argv: Sequence[str]) -> tuple[argparse.Namespace, list[str]]:
    parser = argparse.ArgumentParser(prog="cadkg ros", description="Serve a cell to ROS 2.")
    parser.add_argument("source", nargs="?", help="manifest or store directory (or the 'source' parameter)")
    parser.add_argument("--profile", default=None)
    parser.add_argument("--namespace", default=None)
    parser.add_argument("--approach-distance", type=float, default=None)
    parser.add_argument("--marker-period", type=float, default=None)
    parser.add_argument("--allow-assign", action="store_true", default=None)
    parser.add_argument("--node-name", default="cadkg")
    ours, ros_args = [], []
    rest = list(argv)
    if "--ros-args" in rest:
        i = rest.index("--ros-args")
        ours, ros_args = rest[:i], rest[i:]
    else:
        ours = rest
    return parser.parse_args(ours), ros_args


def _source(text: str) -> str:
    # A store's endpoint URL stays as given; a file or directory is made absolute, since
    # the node may be started from anywhere.
    if text.lower().startswith(("http://", "https://")):
        return text
    return str(Path(text).resolve())


def main(argv: Sequence[str] | None = None) -> int:
    """Run the node until interrupted; arguments as ``cadkg ros`` (plus ``--ros-args ...``)."""
    import sys
    import warnings

    from rclpy.parameter import Parameter

    # rclpy warns when a response cannot be sent (the client's reader not yet discovered): each
    # is a client left waiting, so each is logged, not only the first of the process.
    warnings.filterwarnings("always", message="failed to send response", category=RuntimeWarning)
    args, ros_args = _arguments(list(sys.argv[1:] if argv is None else argv))
    overrides = [
        Parameter(name, value=value)
        for name, value in (
            ("source", _source(args.source) if args.source else None),
            ("profile", args.profile),
            ("namespace", args.namespace),
            ("approach_distance", args.approach_distance),
            ("marker_period", args.marker_period),
            ("allow_assign", args.allow_assign),
        )
        if value is not None
    ]
    rclpy.init(args=["cadkg", *ros_args])
    served: CadkgNode | None = None
    executor = MultiThreadedExecutor(num_threads=4)
    try:
        served = CadkgNode(args.node_name, overrides)
        executor.add_node(served.node)
        # SIGINT and SIGTERM shut the context down and wake the wait; the timeout looks at the
        # context again regardless, so a wake-up lost in a race cannot keep the node alive.
        while rclpy.ok():
            executor.spin_once(timeout_sec=0.5)
    except CadkgError as err:
        print(f"cadkg ros: error: {err}", file=sys.stderr)
        return 2
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown(timeout_sec=5.0)  # lets running callbacks end before the node goes
        if served is not None:
            served.destroy()
        if rclpy.ok():
            rclpy.shutdown()
    return 0
