"""The ROS node's side of the declaration every service makes (``Service.effect``): a service
that changes the graph, and ``assign``, are refused unless the node is started with
``allow_assign``; reading services and the calling client's own cursor are served. The HTTP
side is in ``tests/security/test_state_declared.py``."""

from __future__ import annotations

from types import SimpleNamespace

from cadkg.ros_adapter.node import CadkgNode
from cadkg.services.table import SERVICES


def test_the_node_guards_exactly_the_services_declared_to_change_the_graph() -> None:
    closed, opened = SimpleNamespace(allow_assign=False), SimpleNamespace(allow_assign=True)
    refused = {name for name in [*SERVICES, "assign"] if CadkgNode.refusal(closed, name)}  # type: ignore[arg-type]
    assert refused == {name for name, s in SERVICES.items() if s.effect.changes_graph} | {"assign"}
    assert "load_files" in refused
    assert all("allow_assign:=true" in CadkgNode.refusal(closed, name) for name in refused)  # type: ignore[arg-type]
    assert not any(CadkgNode.refusal(opened, name) for name in [*SERVICES, "assign"])  # type: ignore[arg-type]
