"""What protects the endpoint: a time limit, a result-row cap, a body-size limit, bounded workers.

Each request has a :class:`Deadline`, and its work runs in a bounded pool of threads (an
:class:`Evaluator`), so the event loop stays free:

- the client gets its answer, or a 503 time-out, within the limit (measured from the
  request's arrival, so waiting for a free worker counts);
- a query still waiting for a worker when its time is up never starts;
- a query's thread waits for a worker process (:mod:`cadkg.server.evaluation`), where a query
  whose solutions stream (no ``ORDER BY``, ``GROUP BY``, aggregate or ``DISTINCT`` over
  everything) stops at the next solution after its deadline, and any other (a sort, a
  grouping, a join that finds nothing for long: pyoxigraph cannot cancel them) is killed
  with its process. Either way its core is idle again and its worker free.
"""

from __future__ import annotations

import asyncio
import threading
import time
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import TypeVar

from cadkg.errors import CadkgError, TimeLimitError
from cadkg.limited import DEFAULT_QUERY_MEMORY

__all__ = ["BodyTooLargeError", "Deadline", "Evaluator", "Limits", "TimeLimitError"]

T = TypeVar("T")


@dataclass(frozen=True)
class Limits:
    """The endpoint's limits: seconds per request, rows (or triples) per answer, bytes per body,
    seconds per request head, connections open at once."""

    timeout: float = 30.0
    max_rows: int = 10_000
    max_body: int = 1 << 20
    workers: int = 4
    query_memory: int = DEFAULT_QUERY_MEMORY  # MiB a query's worker may grow by (0: no limit)
    # Seconds a connection has to send a whole request head, and a body between two chunks.
    header_timeout: float = 10.0
    max_connections: int = 0  # connections open at once (0: from the descriptor limit)

    def __post_init__(self) -> None:
        if not self.timeout > 0 or self.max_rows < 1 or self.max_body < 1 or self.workers < 1:
            raise ValueError(f"limits must be positive: {self}")
        if self.query_memory < 0:
            raise ValueError(f"query_memory is MiB, 0 for no limit: {self}")
        if not self.header_timeout > 0 or self.max_connections < 0:
            raise ValueError(f"header_timeout must be positive, max_connections 0 or more: {self}")


class BodyTooLargeError(CadkgError):
    """A request body is larger than the limit."""


class Deadline:
    """When a request's time is up; :meth:`check` raises once it is, or once it was abandoned."""

    __slots__ = ("_abandoned", "at", "seconds")

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        self.at = time.monotonic() + seconds
        self._abandoned = False

    @classmethod
    def until(cls, at: float, seconds: float) -> Deadline:
        """The deadline at the monotonic time ``at`` (of any process: the clock is the system's),
        of a limit of ``seconds``."""
        deadline = cls(seconds)
        deadline.at = at
        return deadline

    def remaining(self) -> float:
        return self.at - time.monotonic()

    def abandon(self) -> None:
        self._abandoned = True

    def check(self) -> None:
        """Raises
        ------
        TimeLimitError
            When the deadline has passed or nobody waits for the answer any more.
        """
        if self._abandoned or time.monotonic() > self.at:
            raise TimeLimitError(f"the query ran past the time limit of {self.seconds:g} s")


class Evaluator:
    """A bounded pool of threads running blocking jobs, each against a :class:`Deadline`;
    ``initializer`` runs first in each thread."""

    def __init__(self, workers: int, initializer: Callable[[], None] | None = None) -> None:
        self._pool = ThreadPoolExecutor(
            max_workers=workers, thread_name_prefix="cadkg-query", initializer=initializer
        )
        self._lock = threading.Lock()
        self.running = 0

    async def run(
        self, job: Callable[[Deadline], T], deadline: Deadline, on_done: Callable[[], None] | None = None
    ) -> T:
        """Run ``job(deadline)`` in a worker and wait for it at most until the deadline.

        ``on_done`` is called when the job has ended or was cancelled before starting, even
        when that is after the caller stopped waiting (the job holds what it reads until then).

        Raises
        ------
        TimeLimitError
            When the deadline passes first; the job is told to stop at its next check.
        """

        def guarded() -> T:
            deadline.check()  # waited in the queue past its time: do not start
            with self._lock:
                self.running += 1
            try:
                return job(deadline)
            finally:
                with self._lock:
                    self.running -= 1

        future = self._pool.submit(guarded)
        if on_done is not None:
            future.add_done_callback(lambda _: on_done())
        try:
            return await asyncio.wait_for(asyncio.wrap_future(future), max(deadline.remaining(), 0.0))
        except TimeoutError:
            deadline.abandon()
            future.cancel()
            raise TimeLimitError(f"the query ran past the time limit of {deadline.seconds:g} s") from None

    def shutdown(self) -> None:
        self._pool.shutdown(wait=False, cancel_futures=True)
