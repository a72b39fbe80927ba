"""The change feed over ROS: a latched ``graph_changes`` topic of ``cadkg_interfaces/GraphChanges``.

The node shows the feed its graph at start and after each reload, assignment or ``load_files``;
the comparison runs in a thread of its own, so the services go on answering meanwhile, and a
subscriber that joins late (transient local durability) receives the latest change set.
"""

from __future__ import annotations

import importlib
import json
from collections.abc import Sequence
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from cadkg.changes.changeset import ChangeSet
from cadkg.changes.feed import ChangeFeed
from cadkg.errors import CadkgError
from cadkg.services.session import Work

__all__ = ["TOPIC", "RosChangeFeed", "to_message"]

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


class RosChangeFeed:
    """Publishes each change set of the node's graph on ``graph_changes``, latched."""

    def __init__(self, node: Node) -> None:
        self.feed = ChangeFeed()
        self._node = node
        qos = QoSProfile(
            depth=1,
            history=HistoryPolicy.KEEP_LAST,
            reliability=ReliabilityPolicy.RELIABLE,
            durability=DurabilityPolicy.TRANSIENT_LOCAL,
        )
        message_type = importlib.import_module("cadkg_interfaces.msg").GraphChanges
        self._publisher = node.create_publisher(message_type, TOPIC, qos)
        self._work = ThreadPoolExecutor(max_workers=1, thread_name_prefix="cadkg-changes")
        self.feed.listen(lambda changes: self._publisher.publish(to_message(changes)))

    def changed(
        self, kg: Any, revision: str, done: dict[str, list[Work]] | None = None, cursors: Sequence[str] = ()
    ) -> None:
        """``kg`` is the graph served from now on (or at start), named ``revision``; ``done``
        the work the cursors had passed on the graph before, ``cursors`` where they are now."""
        self._work.submit(self._observe, kg, revision, done, cursors)

    def _observe(
        self, kg: Any, revision: str, done: dict[str, list[Work]] | None, cursors: Sequence[str]
    ) -> None:
        try:
            self.feed.observe(kg, revision, done, cursors)
        except (CadkgError, OSError, RuntimeError) as err:  # a graph closed by a reload meanwhile
            self._node.get_logger().warning(f"change feed: {err}")

    def shutdown(self) -> None:
        self._work.shutdown(wait=True, cancel_futures=True)
