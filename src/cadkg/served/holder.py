"""The graph being served, and its replacement by a rebuilt one while requests run.

A request takes the :class:`Served` graph current at its arrival and keeps it to the
end, so an answer never mixes two generations. A reload opens the new graph first
(:meth:`GraphHolder.open`; requests go on meanwhile), then swaps it in under a lock
(:meth:`GraphHolder.swap`); the old one is closed when its last request has finished.
"""

from __future__ import annotations

import itertools
import threading
from collections.abc import Callable, Mapping
from typing import Any

from cadkg.errors import CadkgError, StateError
from cadkg.services.service import Effect
from cadkg.services.session import Session, Work
from cadkg.store import cell_profile

__all__ = ["GraphHolder", "Served"]

_serial = itertools.count(1)
_NONE: Any = object()  # a graph that has no workers (a remote store)


class Served:
    """One opened graph with its service session, its generation and a count of its users.

    ``model(graph)`` derives the cell model the services answer from (default: the one the
    store keeps, :meth:`cadkg.graph.KnowledgeGraph.cell_model`); ``profile`` names the use case
    the cell is served as (default: the graph's own).
    """

    def __init__(
        self,
        graph: Any,
        owned: bool = True,
        *,
        model: Callable[[Any], Any] | None = None,
        profile: str | None = None,
    ) -> None:
        self.graph = graph
        self.owned = owned  # a graph handed in by the caller is the caller's to close
        self._model = model
        self._profile = profile
        # What the reload service calls (set by the holder): serve the store's current generation.
        self.reopen: Callable[[], tuple[str, str]] | None = None
        self.serial = next(_serial)
        # The generation this graph was opened at (a store directory's CURRENT may move on).
        self.generation: str = getattr(graph, "generation", None) or f"memory-{self.serial}"
        self.edits = 0  # updates applied since opening: part of every cache key
        self.lock = threading.Lock()  # one writer at a time; one service call at a time
        self._refs = threading.Lock()
        self._session: Session | None = None
        # The session of the graph this one replaced, whose cursors the next session takes over.
        self._previous: Session | None = None
        self.cursor_notes: list[str] = []
        # Told of every change of this graph in place (an update, an assignment, load_files).
        self.notify: Callable[[Served], None] | None = None
        self._triples: int | None = None
        self._workers: Any = None
        self._workers_lock = threading.Lock()
        self._users = 1  # the holder's own reference
        self._closed = False

    @property
    def key(self) -> tuple[int, int]:
        """What answers of this graph are cached under: changes with every update and reload."""
        return (self.serial, self.edits)

    def session(self) -> Session:
        """The services' session (cell model and cursors), built on first use. Call under :attr:`lock`."""
        if self._session is None:
            model = self._model(self.graph) if self._model is not None else self.graph.cell_model()
            profile = cell_profile(self.graph) if self._profile is None else self._profile
            session = Session(model, kg=self.graph, profile=profile)
            session.reopen = self.reopen
            if self._previous is not None:
                self.cursor_notes = session.carry_over(self._previous)
                self._previous = None
            self._session = session
        return self._session

    def inherit(self, old: Served) -> None:
        """Take over the cursors of ``old``, the graph this one replaces (on the same wire or operation)."""
        self._previous = old._session or old._previous

    def passed_work(self) -> dict[str, list[Work]]:
        """The work the cursors had passed just before this graph's latest change (those of the
        session it replaces), for the change feed to tell which tasks must be redone."""
        previous = self._previous
        if previous is None:
            return {}
        try:
            return previous.done()
        except (CadkgError, OSError, RuntimeError):  # a replaced graph closed meanwhile
            return {}

    def triples(self) -> int:
        """How many triples the graph holds, counted once per change."""
        if self._triples is None:
            self._triples = len(self.graph)
        return self._triples

    def workers(self, make: Callable[[Any], Any]) -> Any:
        """The query workers of this graph as it is now (``make(graph)`` on first use and after
        an update; ``None`` when it makes none)."""
        workers = self._workers
        if workers is None:
            # Under the writers' lock, so the snapshot never sees half an update.
            with self.lock, self._workers_lock:
                if self._closed:
                    return None
                if self._workers is None:
                    made = make(self.graph)
                    self._workers = _NONE if made is None else made
                workers = self._workers
        return None if workers is _NONE else workers

    @property
    def made_workers(self) -> Any:
        """The query workers if they were made (see :meth:`workers`), else ``None``."""
        workers = self._workers
        return None if workers is _NONE else workers

    def _retire_workers(self) -> None:
        with self._workers_lock:
            workers, self._workers = self._workers, None
        if workers is not None and workers is not _NONE:
            workers.close()

    def edited(self) -> None:
        """After an update: new cache keys, and a session and workers made afresh from the
        changed graph. Call under :attr:`lock`."""
        self.edits += 1
        # A change to a store directory is a new generation, which this graph now has open.
        self.generation = getattr(self.graph, "open_generation", None) or self.generation
        self._previous = self._session or self._previous
        self._session = None
        self._triples = None
        self._retire_workers()
        if self.notify is not None:
            self.notify(self)

    def retain(self) -> None:
        with self._refs:
            self._users += 1

    def release(self) -> None:
        with self._refs:
            self._users -= 1
            last = self._users == 0 and not self._closed
            if last:
                self._closed = True
        if last:
            self._retire_workers()
        if last and self.owned:
            self.graph.close()


class GraphHolder:
    """The current :class:`Served` graph; ``load`` opens a fresh one for :meth:`reload`.

    Every transport serves its cell through one: a request (an HTTP call, a ROS service call)
    takes the current graph and its session, and a reload or a change carries the cursors over.
    """

    def __init__(
        self,
        graph: Any,
        load: Callable[[], Any] | None = None,
        *,
        model: Callable[[Any], Any] | None = None,
        profile: str | None = None,
    ) -> None:
        """``graph`` was opened by ``load`` when that is given (and is then closed here), else it
        belongs to the caller; ``model`` and ``profile`` as :class:`Served` takes them."""
        self._model, self._profile = model, profile
        self._load = load
        # What the reload service does: :meth:`reload`, unless a transport serves it its own way
        # (the HTTP endpoint warms its cache on the new graph first).
        self.reopen: Callable[[], tuple[str, str]] = self.reload
        self._current = self._served(graph, owned=load is not None)
        # Told of the graph served after every change: a reload, or a change in place.
        self.on_change: Callable[[Served], None] | None = None
        self._swap = threading.Lock()
        self.reloads = 0

    @property
    def current(self) -> Served:
        return self._current

    def acquire(self) -> Served:
        """The current graph, kept open until :meth:`Served.release`."""
        with self._swap:
            served = self._current
            served.retain()
        return served

    def stale(self) -> bool:
        """Whether the store directory now names another generation than the one served."""
        current = self._current
        graph = current.graph
        if getattr(graph, "directory", None) is None:
            return False
        # The graph's own changes (made under its lock) move it to the generation they make:
        # while one is made, and after, the store has not moved on; only another's change has.
        if not current.lock.acquire(blocking=False):
            return False
        try:
            live = graph.generation
            held = getattr(graph, "open_generation", None) or current.generation
            return bool(live) and live != held
        except OSError:
            return False
        finally:
            current.lock.release()

    def open(self) -> Served:
        """Open the graph again (not served yet: see :meth:`swap`).

        Raises
        ------
        CadkgError
            When the graph cannot be opened.
        StateError
            When this holder was given a graph, not a way to open one.
        """
        if self._load is None:
            raise StateError("this endpoint serves a graph it cannot reopen")
        return self._served(self._load())

    def _served(self, graph: Any, owned: bool = True) -> Served:
        served = Served(graph, owned, model=self._model, profile=self._profile)
        served.notify = self._changed
        served.reopen = lambda: self.reopen()
        return served

    def _changed(self, served: Served) -> None:
        if self.on_change is not None:
            self.on_change(served)

    def swap(self, fresh: Served) -> tuple[str, str]:
        """Serve ``fresh`` from now on; returns the previous and the new generation."""
        with self._swap:
            old, self._current = self._current, fresh
            fresh.inherit(old)
            self.reloads += 1
        # Told while the old graph is open still: the feed asks what its cursors had passed.
        self._changed(fresh)
        old.release()
        return old.generation, fresh.generation

    def reload(self) -> tuple[str, str]:
        """:meth:`open` and :meth:`swap` in one."""
        return self.swap(self.open())

    def run(self, name: str, params: Mapping[str, Any], client: str = "default") -> Any:
        """Run service ``name`` of the table on the graph served now, by its effect: one call at
        a time on the graph; a change in place makes a new session; a reload runs outside the
        graph's lock, so the graph it replaces goes on answering while the new one opens.

        Raises
        ------
        CadkgError
            As the service raises it (an unknown service, a bad parameter, a failed reload).
        """
        from cadkg.services.table import SERVICES, call

        effect = SERVICES[name].effect
        served = self.acquire()
        try:
            with served.lock:
                session = served.session()
                if effect is not Effect.RELOADS:
                    result = call(session, name, params, client=client)
                    if effect.changes_graph and getattr(result, "success", False):
                        served.edited()
                    return result
            return call(session, name, params, client=client)
        finally:
            served.release()

    def close(self) -> None:
        with self._swap:
            current = self._current
        current.release()
