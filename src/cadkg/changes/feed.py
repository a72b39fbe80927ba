"""The change feed of a served graph: after each change, what changed since the one before.

A transport (the HTTP endpoint, the ROS node) shows the feed every graph it serves, at start
and after each rebuild, reload, ``load_files`` or assignment (:meth:`ChangeFeed.observe`); the
feed keeps the things of the last one (not the graph, which may be closed or changed in place
by then), compares, keeps the latest change set and hands it to its listeners.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping, Sequence
from typing import Any

from cadkg.changes.changeset import ChangeSet
from cadkg.changes.compare import Tolerances, diff_things
from cadkg.changes.impact import plan_impact
from cadkg.changes.kinds import ThingKind, kinds_for
from cadkg.changes.things import Thing, cell_profiles, read_things
from cadkg.plan.graph import StoredPlan, cell_base, read_plan
from cadkg.services.session import Work

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
        self._plan: StoredPlan | None = None
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

    @property
    def listening(self) -> int:
        """How many listeners are registered now."""
        with self._lock:
            return len(self._listeners)

    def observe(
        self,
        graph: Any,
        revision: str,
        done: Mapping[str, Sequence[Work]] | None = None,
        cursors: Sequence[str] = (),
    ) -> ChangeSet | None:
        """Take the things of ``graph`` (the served graph as it now is, named ``revision``);
        after the first, publish and return what changed since the one before (also when
        nothing did: a listener learns the graph was rebuilt), with its impact on the plan the
        graph before held and on the work the cursors had passed on it (``done``, as
        :meth:`cadkg.services.session.Session.done` gives it just before the change;
        ``cursors`` where each is now).

        Raises
        ------
        QueryError
            When a kind's query fails on the graph.
        """
        cells = cell_profiles(graph)
        kinds = kinds_for(sorted(set(cells)))
        things = {kind.name: (kind, read_things(graph, kind, cells)) for kind in kinds}
        plan = read_plan(graph, cell_base(graph))
        with self._lock:
            before, old, old_plan = self._things, self._revision, self._plan
            self._things, self._revision, self._plan = things, revision, plan
            if before is None:
                return None
            changes = ChangeSet(old, revision)
            for name in sorted({*before, *things}):
                kind = (things.get(name) or before[name])[0]
                old_things = before.get(name, (kind, []))[1]
                new_things = things.get(name, (kind, []))[1]
                for change in diff_things(kind, old_things, new_things, self.tolerances):
                    changes.of(change)
            changes.impact = plan_impact(changes, old_plan, done, plan, cursors)
            self.latest = changes
            self.published += 1
            listeners = list(self._listeners)
        for listener in listeners:
            listener(changes)
        return changes
