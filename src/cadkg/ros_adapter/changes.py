"""The change feed over ROS: a latched ``graph_changes`` topic of ``cadkg_interfaces/GraphChanges``.

The served cell's holder tells the feed of its graph at start and after each reload,
assignment or ``load_files``; the comparison runs in a thread of its own, so the services go
on answering meanwhile, and a subscriber that joins late (transient local durability)
receives the latest change set.
"""

from __future__ import annotations

import importlib
import json
from collections.abc import Callable
from typing import Any

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from cadkg.changes.changeset import ChangeSet
from cadkg.served.feed import CellFeed
from cadkg.served.holder import GraphHolder, Served

__all__ = ["TOPIC", "ros_feed", "to_message"]

TOPIC = "graph_changes"


def to_message(changes: ChangeSet) -> Any:
    """A ``GraphChanges`` message: counts, each thing's kind and identity, the JSON change set."""
    message = importlib.import_module("cadkg_interfaces.msg").GraphChanges()
    message.old_revision, message.new_revision = changes.old, changes.new
    for name in ("added", "removed", "changed"):
        items = getattr(changes, name)
        setattr(message, name, len(items))
        setattr(message, f"{name}_kinds", [c.kind for c in items])
        setattr(message, f"{name}_ids", [c.id for c in items])
    message.json = json.dumps(changes.to_json(), default=str)
    return message


def ros_feed(node: Node, holder: GraphHolder, revision: Callable[[Served], str]) -> CellFeed:
    """The served cell's feed (:class:`cadkg.served.feed.CellFeed`), each change set published
    on ``graph_changes``, latched."""
    qos = QoSProfile(
        depth=1,
        history=HistoryPolicy.KEEP_LAST,
        reliability=ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL,
    )
    message_type = importlib.import_module("cadkg_interfaces.msg").GraphChanges
    publisher = node.create_publisher(message_type, TOPIC, qos)
    feed = CellFeed(holder, revision, node.get_logger().warning)
    feed.feed.listen(lambda changes: publisher.publish(to_message(changes)))
    return feed
