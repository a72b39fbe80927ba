"""Round trip of cadkg's ROS 2 services over rclpy on loopback, next to the in-process call.

Runs in the ROS venv (``scripts/ros-setup.sh`` makes ``.venv-ros``). For each case, the
node (``python -m cadkg.ros_adapter MANIFEST``) runs in its own process on a bundled
example, and this process:

1. **in process**: builds the same example and times ``services.call(session, name,
   params)``, the function the node's callback calls (``time.perf_counter_ns``);
2. **over ROS**: times ``call_async`` + ``spin_once`` until the answer arrives, one call
   after the other, through a real rclpy client (Fast DDS, ``ROS_AUTOMATIC_DISCOVERY_RANGE=
   LOCALHOST``, a domain of its own);
3. **same answer**: the first ROS response, read back into plain data field by field, is
   compared with the in-process result converted the way the node converts it.

Cases: ``cad_service label=F1500.1`` on ``examples/iema-switchgear`` and ``cable_info
name=CA5`` on ``examples/elvez-cell``. The table gives p50 and p99 in µs, the ratio
ROS / in-process p50, and the target (round trip p50 ≤ 2 ms). Nothing is asserted.

Usage::

    .venv-ros/bin/python benchmarks/bench_ros.py [--calls 1000]
    .venv-ros/bin/python benchmarks/bench_ros.py --quick     # a smoke test (its settings: --help)
"""

from __future__ import annotations

import argparse
import math
import os
import platform
import statistics
import subprocess
import sys
import time
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
os.environ.setdefault("ROS_DOMAIN_ID", str(101 + os.getpid() % 100))
os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"

import rclpy  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402

from cadkg.graph import KnowledgeGraph  # noqa: E402
from cadkg.ros_adapter import convert  # noqa: E402
from cadkg.ros_adapter.node import default_namespace, srv_type  # noqa: E402
from cadkg.services.session import Session  # noqa: E402
from cadkg.services.table import call  # noqa: E402
from quick import add_quick, parse  # noqa: E402

TARGET_US = 2000.0


@dataclass(frozen=True)
class Case:
    profile: str
    example: str
    service: str
    params: Mapping[str, str]


CASES = (
    Case("iema", "iema-switchgear", "cad_service", {"label": "F1500.1"}),
    Case("elvez", "elvez-cell", "cable_info", {"name": "CA5"}),
)


def percentile(values: list[float], share: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, math.ceil(share * len(ordered)) - 1)]


def as_data(msg: Any) -> Any:
    """A ROS message as plain data (dicts, lists, numbers, text), field by field."""
    if hasattr(msg, "get_fields_and_field_types"):
        return {name: as_data(getattr(msg, name)) for name in msg.get_fields_and_field_types()}
    if isinstance(msg, list | tuple) or type(msg).__name__ == "array":
        return [as_data(v) for v in msg]
    return msg


def same(a: Any, b: Any) -> bool:
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) or isinstance(b, float):
        return (math.isnan(a) and math.isnan(b)) or math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-12)
    return bool(a == b)


def expected_response(result: Any, response_type: Any) -> dict[str, Any]:
    if type(result).__name__ in convert.FIELDS:
        return convert.response(result)

    def fields_of(kind: str) -> dict[str, str]:
        package, _, name = kind.replace("/msg/", "/").partition("/")
        module = __import__(f"{package}.msg", fromlist=[name])
        return dict(getattr(module, name)().get_fields_and_field_types())

    return convert.typed_response(result, response_type.get_fields_and_field_types(), fields_of)


def in_process(case: Case, calls: int) -> tuple[list[float], Any]:
    kg = KnowledgeGraph.build(ROOT / "examples" / case.example / "manifest.toml")
    session = Session(kg.cell_model(), kg=kg)
    result = call(session, case.service, dict(case.params))
    times = []
    for _ in range(calls):
        started = time.perf_counter_ns()
        call(session, case.service, dict(case.params))
        times.append((time.perf_counter_ns() - started) / 1000)
    return times, result


def over_ros(case: Case, calls: int) -> tuple[list[float], Any, float]:
    name = f"bench_{case.profile}"
    node_process = subprocess.Popen(
        [sys.executable, "-m", "cadkg.ros_adapter", str(ROOT / "examples" / case.example / "manifest.toml"),
         "--node-name", name],
        stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT, cwd=ROOT,
    )  # fmt: skip
    client_node = rclpy.create_node(f"{name}_client")
    executor = SingleThreadedExecutor()
    executor.add_node(client_node)
    kind = srv_type(case.service)
    client = client_node.create_client(kind, f"{default_namespace(case.profile)}/{case.service}")
    try:
        started = time.monotonic()
        while not client.wait_for_service(timeout_sec=0.5):
            if node_process.poll() is not None or time.monotonic() - started > 120:
                raise SystemExit(f"the {case.profile} node did not come up")
        ready = time.monotonic() - started
        request = kind.Request(**dict(case.params))
        first = None
        times = []
        for index in range(calls + 1):
            begin = time.perf_counter_ns()
            future = client.call_async(request)
            deadline = time.monotonic() + 10.0
            # spin_once, not spin_until_future_complete: in this rclpy every call of the latter
            # leaves work behind in the executor, and the round trip grows with each call.
            while not future.done() and time.monotonic() < deadline:
                executor.spin_once(timeout_sec=0.01)
            elapsed = (time.perf_counter_ns() - begin) / 1000
            if not future.done():
                raise SystemExit(f"{case.service}: no answer within 10 s")
            if index == 0:
                first = future.result()
            else:
                times.append(elapsed)
        return times, first, ready
    finally:
        client_node.destroy_node()
        node_process.terminate()
        node_process.wait(timeout=20)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--calls", type=int, default=1000, help="calls per way (default 1000)")
    add_quick(parser, calls=100)
    args = parse(parser, argv)
    calls = args.calls
    print(f"# cadkg ROS 2 service round trip ({platform.python_version()}, {os.cpu_count()} cores)\n")
    print(f"{calls} calls per way, one after the other, after one first call each.\n")
    print(
        "| service | example | calls | in-process p50 µs | in-process p99 µs | ROS p50 µs | ROS p99 µs"
        " | ROS / in-process p50 | target p50 ≤ 2 ms | same answer |"
    )
    print("|:---|:---|---:|---:|---:|---:|---:|---:|---:|:---|")
    rclpy.init()
    try:
        for case in CASES:
            local, result = in_process(case, calls)
            remote, first, _ = over_ros(case, calls)
            expected = expected_response(result, srv_type(case.service).Response)
            agrees = same(as_data(first), expected)
            local_p50, remote_p50 = statistics.median(local), statistics.median(remote)
            print(
                f"| `{case.service}` | {case.example} | {calls:,} | {local_p50:,.1f} | "
                f"{percentile(local, 0.99):,.1f} | {remote_p50:,.0f} | {percentile(remote, 0.99):,.0f} | "
                f"{remote_p50 / local_p50:,.0f}× | {'met' if remote_p50 <= TARGET_US else 'not met'} | "
                f"{'yes' if agrees else 'differs'} |",
                flush=True,
            )
    finally:
        rclpy.shutdown()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
