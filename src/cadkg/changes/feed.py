"""The change feed of a served graph: after each change, what changed since the one before.

A transport (the HTTP endpoint, the ROS node) shows the feed every graph it serves, at start
and after each rebuild, reload, ``load_files`` or assignment (:meth:`ChangeFeed.observe`); the
feed keeps the things of the last one (not the graph, which may be closed or changed in place
by then), compares, keeps the latest change set and hands it to its listeners.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from cadkg.changes.changeset import ChangeSet
from cadkg.changes.compare import Tolerances, diff_things, profiles_of
from cadkg.changes.kinds import ThingKind, kinds_for
from cadkg.changes.things import Thing, read_things

__all__ = ["ChangeFeed", "Listener"]

Listener = Callable[[ChangeSet], None]
_Things = dict[str, tuple[ThingKind, list[Thing]]]


class ChangeFeed:
    """The change sets of one served graph, in order; ``latest`` the last one (latched)."""

    def __init__(self, tolerances: Tolerances | None = None) -> None:
        self.tolerances = tolerances or Tolerances()
        self.latest: ChangeSet | None = None
        self.published = 0
        self._things: _Things | None = None
        self._revision = ""
        self._lock = threading.Lock()
        self._listeners: list[Listener] = []

    def listen(self, listener: Listener) -> Callable[[], None]:
        """Call ``listener`` with every change set from now on; returns what stops it."""
        with self._lock:
            self._listeners.append(listener)

        def stop() -> None:
            with self._lock:
                if listener in self._listeners:
                    self._listeners.remove(listener)

        return stop

    def observe(self, graph: Any, revision: str) -> ChangeSet | None:
        """Take the things of ``graph`` (the served graph as it now is, named ``revision``);
        after the first, publish and return what changed since the one before (also when
        nothing did: a listener learns the graph was rebuilt).

        Raises
        ------
        QueryError
            When a kind's query fails on the graph.
        """
        kinds = kinds_for(profiles_of(graph))
        things = {kind.name: (kind, read_things(graph, kind)) for kind in kinds}
        with self._lock:
            before, old = self._things, self._revision
            self._things, self._revision = things, revision
            if before is None:
                return None
            changes = ChangeSet(old, revision)
            for name in sorted({*before, *things}):
                kind = (things.get(name) or before[name])[0]
                old_things = before.get(name, (kind, []))[1]
                new_things = things.get(name, (kind, []))[1]
                for change in diff_things(kind, old_things, new_things, self.tolerances):
                    changes.of(change)
            self.latest = changes
            self.published += 1
            listeners = list(self._listeners)
        for listener in listeners:
            listener(changes)
        return changes
