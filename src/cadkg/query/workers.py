"""Queries run in worker processes that are killed when their time is up.

pyoxigraph (0.5.13) cannot cancel a query: ``Store.query`` takes no deadline and no
cancellation token, and a blocking step (a sort, a grouping, a join that finds nothing for
long) runs to its end, holding a core, whatever its caller does. A query that must stop at
its time limit therefore runs in a child process that opens a snapshot of the graph
read-only (:meth:`cadkg.store.GraphStore.snapshot`); when the time is up the child is killed
(SIGKILL) and the next query gets a fresh one.

Children are forked by multiprocessing's fork server, which is started once per process and
has cadkg imported, so a replacement is ready in tens of milliseconds instead of the second a
new interpreter takes. A child dies with the fork server, which ends with its parent
(``PR_SET_PDEATHSIG``), leaves Ctrl-C to its parent, and runs tasks named
``"module:function"``: ``function(graph, *args)`` with the snapshot opened as a read-only
:class:`~cadkg.store.GraphStore` holding the parent's ``allowed_services``.

A worker is a limited child (:mod:`cadkg.limited`), long-lived: it leaves the network as it starts,
unless its pool allows a ``SERVICE`` endpoint, and once the snapshot is open its memory may grow
by ``memory`` MiB only; a worker that dies past it is answered as
:class:`~cadkg.errors.MemoryLimitError` and replaced when next needed.

>>> with WorkerPool(graph) as workers:                      # doctest: +SKIP
...     workers.query("SELECT (COUNT(*) AS ?n) WHERE { ?s ?p ?o }", seconds=5)

As with any multiprocessing code, a script using this runs its work under
``if __name__ == "__main__":`` (the fork server imports the main module).
"""

from __future__ import annotations

import contextlib
import ctypes
import importlib
import math
import multiprocessing
import pickle
import signal
import threading
import time
from collections.abc import Callable, Iterable
from multiprocessing.connection import Connection
from multiprocessing.context import ForkServerContext
from typing import Any, Self

import pyoxigraph as ox

from cadkg.errors import CadkgError, QueryError, StoreError, TimeLimitError
from cadkg.limited.limits import DEFAULT_QUERY_MEMORY, Limits, cause, exceeded, limit_memory
from cadkg.limited.network import leave_network, warn_unconfined
from cadkg.store import GraphStore, QueryResult

__all__ = ["WorkerPool", "query_within"]

# The main module too, as multiprocessing does: imported once by the fork server, not by each child.
_PRELOAD = {"__main__", "cadkg.query.workers"}
_PR_SET_PDEATHSIG = 1
_SELECT = "cadkg.query.workers:select"
_START = 120.0  # seconds a worker may take to start when the caller's clock waits for it


def _context(preload: Iterable[str]) -> ForkServerContext:
    """The fork server context; ``preload`` modules are imported by the fork server (once it runs,
    later additions are imported by each child instead)."""
    _PRELOAD.update(preload)
    context = multiprocessing.get_context("forkserver")
    assert isinstance(context, ForkServerContext)
    context.set_forkserver_preload(sorted(_PRELOAD))
    return context


def _die_with_parent() -> None:
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)


def _portable(err: CadkgError) -> CadkgError:
    """``err``, or a :class:`QueryError` with its message when it would not survive pickling."""
    try:
        pickle.loads(pickle.dumps(err))
    except Exception:
        return QueryError(str(err))
    return err


def _task(name: str) -> Callable[..., Any]:
    module, _, function = name.partition(":")
    found: Callable[..., Any] = getattr(importlib.import_module(module), function)
    return found


def _left(until: float) -> float | None:
    """Seconds from now to the monotonic time ``until``; ``None`` (no limit) for an infinite one."""
    return None if math.isinf(until) else max(until - time.monotonic(), 0.0)


def _serve(
    conn: Connection, directory: str, allowed: frozenset[str], modules: tuple[str, ...], memory: int
) -> None:
    """A child's life: leave the network (unless it may reach ``allowed`` endpoints), import its
    tasks' modules (when the fork server has not), open the snapshot, limit its memory, say so
    (with why it could not leave the network, if so), then answer requests until the pipe closes."""
    _die_with_parent()
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    unconfined = None if allowed else leave_network()
    for module in modules:
        importlib.import_module(module)
    try:
        graph = GraphStore(ox.Store.read_only(directory), read_only=True)
    except OSError as err:
        conn.send(("error", StoreError(f"cannot open the graph for a query worker: {err}")))
        return
    graph.allowed_services = allowed
    limit_memory(memory)
    conn.send(("ready", unconfined))
    tasks: dict[str, Callable[..., Any]] = {}
    while True:
        try:
            name, args = conn.recv()
        except (EOFError, OSError):
            return
        reply: tuple[str, Any]
        try:
            if name not in tasks:
                tasks[name] = _task(name)
            reply = ("ok", tasks[name](graph, *args))
        except CadkgError as err:
            reply = ("error", _portable(err))
        except MemoryError:
            reply = ("error", exceeded(Limits(memory=memory), "memory"))
        except Exception as err:  # a task's bug: one line to the caller, the worker goes on
            reply = ("error", QueryError(f"{type(err).__name__}: {err}"))
        try:
            conn.send(reply)
        except (pickle.PicklingError, TypeError, AttributeError) as err:
            conn.send(("error", QueryError(f"an answer that cannot leave its worker: {err}")))


def select(graph: GraphStore, sparql: str, bindings: dict[str, Any]) -> QueryResult:
    """The task of :meth:`WorkerPool.query`."""
    return graph.query(sparql, **bindings)


class _Worker:
    """One child process and the pipe to it."""

    def __init__(
        self,
        context: ForkServerContext,
        directory: str,
        allowed: frozenset[str],
        modules: tuple[str, ...],
        memory: int,
    ) -> None:
        self.conn, theirs = context.Pipe()
        args = (theirs, directory, allowed, modules, memory)
        self.process = context.Process(target=_serve, args=args, daemon=True)
        self.process.start()
        theirs.close()
        self.memory = memory
        self.ready = False

    def _died(self) -> CadkgError:
        self.process.join(1)
        code = self.process.exitcode
        limits = Limits(memory=self.memory)
        if self.ready and code is not None and cause(limits, code) == "memory":
            # Killed by a signal while answering: an allocation past the limit aborts pyoxigraph.
            return exceeded(limits, "memory")
        return QueryError(f"the query's worker process ended unexpectedly (exit code {code})")

    def wait_ready(self, until: float) -> bool:
        """Whether the worker has opened the graph, waiting until the monotonic time ``until``.

        Raises
        ------
        CadkgError
            When it could not open the graph, or died.
        """
        if self.ready:
            return True
        try:
            if not self.conn.poll(_left(until)):
                return False
            status, value = self.conn.recv()
        except (EOFError, OSError):
            raise self._died() from None
        if status != "ready":
            raise value
        if value is not None:
            warn_unconfined(value)
        self.ready = True
        return True

    def call(self, request: tuple[str, tuple[Any, ...]], until: float, seconds: float) -> tuple[str, Any]:
        """Send ``request`` to the ready worker and wait for its reply until ``until``.

        Raises
        ------
        TimeLimitError
            When no reply came in time (the caller kills the worker).
        QueryError
            When the worker died.
        """
        try:
            self.conn.send(request)
            if not self.conn.poll(_left(until)):
                raise exceeded(Limits(wall=seconds), "wall")
            reply: tuple[str, Any] = self.conn.recv()
        except (EOFError, OSError):
            raise self._died() from None
        return reply

    def kill(self) -> None:
        with contextlib.suppress(OSError, ValueError):
            self.process.kill()
            self.process.join(5)
        self.conn.close()


class WorkerPool:
    """At most ``size`` worker processes answering queries on a snapshot of ``graph``.

    The snapshot is taken here (the graph as it is now: later changes are not seen) and
    removed by :meth:`close` once the last running query has ended. Workers start when first
    needed (or at :meth:`prestart`) and are kept while they answer in time; one killed is
    replaced at once, so the next query finds it ready. Thread-safe. Queries may reach the
    ``allowed_services`` (by default the graph's own, :attr:`GraphStore.allowed_services`): only
    then do the workers keep the network. A query may take ``memory`` MiB (0: no limit).
    ``preload`` names the modules of the tasks: the fork server imports them if it starts now,
    else each worker does before it says it is ready, so no query waits for an import.

    Raises
    ------
    CadkgError
        When the snapshot cannot be taken.
    """

    def __init__(
        self,
        graph: GraphStore,
        size: int = 1,
        *,
        allowed_services: Iterable[str] | None = None,
        preload: Iterable[str] = (),
        memory: int = DEFAULT_QUERY_MEMORY,
    ) -> None:
        self.size = size
        self.snapshot = graph.snapshot()
        allowed = graph.allowed_services if allowed_services is None else allowed_services
        self._allowed = frozenset(allowed)
        self._modules = tuple(preload)
        self._memory = memory
        self._context = _context(self._modules)
        self._slots = threading.BoundedSemaphore(size)
        self._lock = threading.Lock()
        self._idle: list[_Worker] = []
        self._busy = 0
        self._closed = False
        self.started = 0
        self.killed = 0
        self.warm = False

    def call(
        self,
        task: str,
        args: tuple[Any, ...],
        *,
        seconds: float,
        at: float | None = None,
        grace: float = 0.0,
    ) -> Any:
        """``task(graph, *args)`` in a worker, killed if no answer comes within ``seconds``.

        With ``at`` (a monotonic time) everything counts, waiting for a worker too, and the
        worker has ``grace`` more seconds for a task that stops by itself at ``at`` (keeping its
        worker); without, the clock starts when the worker is ready (starting one may take a
        second the first time). ``seconds`` may be ``math.inf``: no time limit.

        Raises
        ------
        TimeLimitError
            When the time is up.
        CadkgError
            As the task raises it.
        """
        until = at if at is not None else time.monotonic() + _START + seconds
        late = TimeLimitError(f"the query ran past the time limit of {seconds:g} s waiting for a worker")
        left = _left(until)
        if not self._slots.acquire(timeout=-1 if left is None else left):
            raise late
        try:
            worker = self._take()
            try:
                ready = worker.wait_ready(until)
            except BaseException:
                self._done(worker, kill=True)
                raise
            if not ready:  # still starting: the next query gets it
                self._done(worker)
                raise late
            at = time.monotonic() + seconds if at is None else at
            try:
                status, value = worker.call((task, args), at + grace, seconds)
            except TimeLimitError:
                self._done(worker, kill=True, replace=True)
                raise
            except BaseException:
                self._done(worker, kill=True)
                raise
            self._done(worker)
        finally:
            self._slots.release()
        if status == "ok":
            return value
        raise value

    def query(self, sparql: str, seconds: float, **bindings: Any) -> QueryResult:
        """A SELECT query's rows, computed in a worker that is killed after ``seconds``.

        Raises
        ------
        TimeLimitError
            When the query ran past ``seconds`` (it is stopped: no core is left busy).
        QueryError
            As :meth:`cadkg.store.GraphStore.query`.
        """
        result: QueryResult = self.call(_SELECT, (sparql, bindings), seconds=seconds)
        return result

    def prestart(self) -> None:
        """Start every worker now (and the fork server, once per process) and wait until they
        are ready, so the first queries do not wait for them; then :attr:`warm` is true."""
        with self._lock:
            count = 0 if self._closed else max(self.size - len(self._idle) - self._busy, 0)
            self._busy += count
        started: list[_Worker] = []
        try:
            for _ in range(count):
                started.append(self._start())
        finally:
            for _ in range(count - len(started)):
                self._done(None)
        for worker in started:  # booting side by side; each is idle once ready
            try:
                worker.wait_ready(time.monotonic() + _START)
            except CadkgError:
                self._done(worker, kill=True)
                raise
            self._done(worker)
        self.warm = True

    def _spare(self) -> None:
        """Start a worker and keep it idle (it says it is ready when first used)."""
        with self._lock:
            if self._closed:
                return
            self._busy += 1
        try:
            worker = self._start()
        except BaseException:
            self._done(None)
            raise
        self._done(worker)

    def _start(self) -> _Worker:
        worker = _Worker(self._context, str(self.snapshot.path), self._allowed, self._modules, self._memory)
        with self._lock:
            self.started += 1
        return worker

    def _take(self) -> _Worker:
        with self._lock:
            if self._closed:
                raise StoreError("the query workers of this graph were closed")
            self._busy += 1
            if self._idle:
                return self._idle.pop()
        try:
            return self._start()
        except BaseException:
            self._done(None)
            raise

    def _done(self, worker: _Worker | None, *, kill: bool = False, replace: bool = False) -> None:
        with self._lock:
            self._busy -= 1
            self.killed += kill
            keep = worker is not None and not kill and not self._closed
            if keep:
                assert worker is not None
                self._idle.append(worker)
            last = self._closed and self._busy == 0
        if worker is not None and not keep:
            worker.kill()
        if last:
            self.snapshot.remove()
        elif replace:
            # A killed worker's replacement starts now, not when the next query needs it.
            with contextlib.suppress(CadkgError, OSError):
                self._spare()

    def close(self) -> None:
        """Stop the idle workers now, the running ones when their query ends, then remove the
        snapshot."""
        with self._lock:
            if self._closed:
                return
            self._closed = True
            idle, self._idle = self._idle, []
            last = self._busy == 0
        for worker in idle:
            worker.kill()
        if last:
            self.snapshot.remove()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def query_within(graph: GraphStore, sparql: str, seconds: float, **bindings: Any) -> QueryResult:
    """Run one SELECT query on ``graph``, stopped after ``seconds`` (see :class:`WorkerPool`).

    Raises
    ------
    TimeLimitError
        When the query ran past ``seconds``; it was stopped.
    QueryError
        As :meth:`cadkg.store.GraphStore.query`.
    """
    with WorkerPool(graph) as workers:
        return workers.query(sparql, seconds, **bindings)
