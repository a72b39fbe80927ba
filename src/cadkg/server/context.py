"""What every handler of the endpoint shares: settings, the served graph, workers, answer cache."""

from __future__ import annotations

import asyncio
import hmac
import json
import re
from collections import OrderedDict
from collections.abc import Awaitable, Callable, Hashable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from starlette.responses import Response

from cadkg.errors import CadkgError, NotFound, QueryError, StateError, StoreError
from cadkg.limited import leave_network_or_warn
from cadkg.served.holder import GraphHolder, Served
from cadkg.server.limits import BodyTooLargeError, Deadline, Evaluator, Limits, TimeLimitError
from cadkg.server.results import NotAcceptableError

__all__ = [
    "Answer",
    "AnswerCache",
    "Endpoint",
    "Job",
    "JobMaker",
    "ProtocolError",
    "Settings",
    "error_response",
    "json_response",
    "syntax_message",
]

GENERATION_HEADER = "X-Cadkg-Generation"
TRUNCATED_HEADER = "X-Cadkg-Truncated"
_SYNTAX = re.compile(r"SPARQL syntax error at line (\d+), column (\d+)")


@dataclass(frozen=True)
class Settings:
    """How an endpoint is run: limits, writes, the answer cache, the store watch, and what it
    opens beyond its defaults (docs/server.md, Security).

    ``files_root`` is the only directory ``load_files`` reads from over HTTP (none: refused);
    ``cors`` the origins whose web pages may call the endpoint; ``allowed_services`` the
    endpoints a query's ``SERVICE`` may reach (none: every ``SERVICE`` is refused).
    """

    limits: Limits = field(default_factory=Limits)
    allow_update: bool = False
    token: str | None = None
    cache_bytes: int = 64 << 20
    warm_entries: int = 32
    watch_seconds: float = 2.0
    retry_after: int = 5
    files_root: Path | None = None
    cors: tuple[str, ...] = ()
    allowed_services: tuple[str, ...] = ()

    def __post_init__(self) -> None:
        if self.allow_update and not self.token:
            raise ValueError("updates need a token: give one with allow_update")


class ProtocolError(CadkgError):
    """A request the SPARQL 1.1 Protocol does not allow, with the HTTP status to answer."""

    def __init__(self, status: int, message: str, headers: dict[str, str] | None = None) -> None:
        super().__init__(message)
        self.status = status
        self.headers = headers or {}

    def __reduce__(self) -> tuple[Any, ...]:  # raised in a query worker, re-raised here
        return (type(self), (self.status, str(self), self.headers))


@dataclass(frozen=True)
class Answer:
    """A finished response body, cacheable."""

    body: bytes
    media_type: str
    status: int = 200
    headers: tuple[tuple[str, str], ...] = ()


Job = Callable[[Deadline], Answer]
"""What answers one request within its deadline, in a query worker or on a thread here."""
JobMaker = Callable[[Served], Job]
"""What makes a request's job on a served graph; kept, to make it again on a reloaded one."""


class AnswerCache:
    """Answers by key, least recently used out first, bounded in bytes; equal requests that
    arrive while one is computed wait for that one instead of computing again."""

    def __init__(self, max_bytes: int) -> None:
        self.max_bytes = max_bytes
        self._entries: OrderedDict[Hashable, Answer] = OrderedDict()
        self._size = 0
        self._inflight: dict[Hashable, asyncio.Future[Answer]] = {}
        self.hits = 0
        self.misses = 0

    async def get(
        self, key: Hashable, compute: Callable[[], Awaitable[Answer]], deadline: Deadline
    ) -> Answer:
        """The cached answer of ``key``, or the one being computed, or a new computation's.

        Raises
        ------
        TimeLimitError
            When the answer is not there before the deadline.
        """
        if self.max_bytes <= 0:
            return await compute()
        cached = self._entries.get(key)
        if cached is not None:
            self._entries.move_to_end(key)
            self.hits += 1
            return cached
        self.misses += 1
        task = self._inflight.get(key)
        if task is None:
            task = asyncio.ensure_future(compute())
            self._inflight[key] = task
            task.add_done_callback(lambda done: self._finish(key, done))
        try:
            return await asyncio.wait_for(asyncio.shield(task), max(deadline.remaining(), 0.0))
        except TimeoutError:
            raise TimeLimitError(f"the query ran past the time limit of {deadline.seconds:g} s") from None

    def _finish(self, key: Hashable, task: asyncio.Future[Answer]) -> None:
        self._inflight.pop(key, None)
        if task.cancelled() or task.exception() is not None:
            return
        self.put(key, task.result())

    def recent(self, prefix: Hashable, count: int) -> list[Hashable]:
        """The keys ``(prefix, key)`` used most recently, newest first (as their ``key`` parts)."""
        found: list[Hashable] = []
        for full in reversed(self._entries):
            if isinstance(full, tuple) and full[0] == prefix:
                found.append(full[1])
                if len(found) == count:
                    break
        return found

    def put(self, key: Hashable, answer: Answer) -> None:
        """Keep ``answer`` unless it is an error or too large (over a quarter of the cache)."""
        size = len(answer.body)
        if answer.status != 200 or size > self.max_bytes // 4:
            return
        if key in self._entries:
            self._size -= len(self._entries.pop(key).body)
        self._entries[key] = answer
        self._size += size
        while self._size > self.max_bytes:
            _, dropped = self._entries.popitem(last=False)
            self._size -= len(dropped.body)

    def __len__(self) -> int:
        return len(self._entries)

    def clear(self) -> None:
        self._entries.clear()
        self._size = 0


def syntax_message(message: str, text: str) -> str:
    """A syntax error's one line, followed by the offending line of ``text`` and a caret."""
    match = _SYNTAX.match(message)
    if match is None:
        return message
    line, column = int(match.group(1)), int(match.group(2))
    lines = text.splitlines() or [""]
    source = lines[min(max(line, 1), len(lines)) - 1]
    caret = " " * max(min(column, len(source) + 1) - 1, 0) + "^"
    return f"{message}\n{source}\n{caret}"


def error_response(status: int, message: str, headers: dict[str, str] | None = None) -> Response:
    """A plain-text error body: one status, one message, no traceback."""
    return Response(message.rstrip() + "\n", status, headers, media_type="text/plain; charset=utf-8")


def json_response(data: Any, status: int = 200, headers: dict[str, str] | None = None) -> Response:
    body = json.dumps(data, ensure_ascii=False, default=str).encode("utf-8")
    return Response(body, status, headers, media_type="application/json")


# The first class an error is an instance of gives its status: a subclass before its base.
_STATUS: tuple[tuple[type[Exception] | tuple[type[Exception], ...], int], ...] = (
    (TimeLimitError, 503),
    (BodyTooLargeError, 413),
    (NotAcceptableError, 406),
    (NotFound, 404),
    (StateError, 409),
    (StoreError, 502),
    ((QueryError, ValueError), 400),
)


def status_of(err: Exception) -> tuple[int, dict[str, str]]:
    """The HTTP status (and headers) an error of the endpoint is answered with."""
    if isinstance(err, ProtocolError):
        return err.status, err.headers
    status = next((status for kind, status in _STATUS if isinstance(err, kind)), 500)
    return status, {}


class Endpoint:
    """The served graph, the workers and the cache of one running endpoint."""

    def __init__(self, holder: GraphHolder, settings: Settings) -> None:
        self.holder = holder
        self.settings = settings
        # Threads waiting for the query worker processes, and threads for the work done here
        # (services, info, updates), so a burst of slow queries delays no service call.
        self.evaluator = Evaluator(settings.limits.workers)
        self.local = Evaluator(settings.limits.workers)
        # SPARQL updates: on a thread that has left the network (a LOAD fails to connect),
        # unless --allow-service names endpoints a LOAD may reach.
        self.writer = Evaluator(1, None if settings.allowed_services else leave_network_or_warn)
        self.cache = AnswerCache(settings.cache_bytes)
        self.requests = 0
        self.retried = 0
        # How each cached answer is computed, to compute it again on a reloaded graph.
        self._jobs: OrderedDict[Hashable, tuple[JobMaker, bool]] = OrderedDict()
        self._reloading = asyncio.Lock()
        # The loop the endpoint runs on (set as it starts): the reload service, called in a
        # thread, reloads through it.
        self.loop: asyncio.AbstractEventLoop | None = None
        holder.reopen = self._reopen

    def _reopen(self) -> tuple[str, str]:
        """The reload service's reopen: :meth:`reload` on the endpoint's loop (it warms the cache
        on the new graph first), waited for from the thread the service runs in."""
        if self.loop is None:
            raise StateError("the endpoint is not running")
        swapped = asyncio.run_coroutine_threadsafe(self.reload(), self.loop).result()
        assert swapped is not None  # only a watch reload may find nothing to do
        return swapped

    @property
    def limits(self) -> Limits:
        return self.settings.limits

    def _evaluator(self, local: bool) -> Evaluator:
        return self.local if local else self.evaluator

    async def _once(
        self,
        served: Served,
        make_job: JobMaker,
        key: Hashable | None,
        deadline: Deadline,
        local: bool,
    ) -> Answer:
        evaluator = self._evaluator(local)

        async def compute() -> Answer:
            served.retain()  # released when the job ends, even after its caller gave up
            fresh = Deadline(self.limits.timeout)
            return await evaluator.run(make_job(served), fresh, on_done=served.release)

        if key is None:
            served.retain()
            return await evaluator.run(make_job(served), deadline, on_done=served.release)
        self._jobs[key] = (make_job, local)
        self._jobs.move_to_end(key)
        if len(self._jobs) > 4 * max(self.settings.warm_entries, 1):
            self._jobs.popitem(last=False)
        return await self.cache.get((served.key, key), compute, deadline)

    async def run(
        self,
        make_job: JobMaker,
        key: Hashable | None,
        deadline: Deadline,
        *,
        local: bool = False,
    ) -> tuple[Answer, str]:
        """Run a job on the current graph in a thread: a query's (``local`` false: it waits for a
        worker process) or one doing its work here. Returns its answer and the generation.

        A job that fails on a graph replaced meanwhile (its files may be gone) runs once more
        on the new one, so a reload loses no request; so does one that fails on a store rebuilt
        before the watch noticed, once the new generation is served.

        Raises
        ------
        TimeLimitError, QueryError, StoreError
            As the job raises them.
        """
        self.requests += 1
        served = self.holder.acquire()
        try:
            try:
                return await self._once(served, make_job, key, deadline, local), served.generation
            except (QueryError, StoreError, OSError) as err:
                if str(err).startswith("SPARQL syntax error"):
                    raise
                if served is self.holder.current:
                    if not self.holder.stale():
                        raise
                    await self.reload(only_if_stale=True)
                    if served is self.holder.current:
                        raise
            self.retried += 1
            served.release()
            served = self.holder.acquire()
            return await self._once(served, make_job, key, deadline, local), served.generation
        finally:
            served.release()

    async def reload(self, *, only_if_stale: bool = False) -> tuple[str, str] | None:
        """Open the graph again, warm the cache with the most recent answers on it, then serve it.

        Requests go on on the old graph meanwhile, answered from the cache as before, so a
        rebuilt store brings no burst of slow first answers. Returns the previous and the new
        generation, or None when ``only_if_stale`` and the store has not moved on.

        Raises
        ------
        CadkgError
            When the graph cannot be opened; the old one is still served.
        StateError
            When the endpoint was given a graph, not a way to open one.
        """
        async with self._reloading:
            if only_if_stale and not self.holder.stale():
                return None
            fresh = await asyncio.to_thread(self.holder.open)
            await self._warm(fresh)
            return self.holder.swap(fresh)

    async def _warm(self, fresh: Served) -> None:
        if self.cache.max_bytes <= 0 or self.settings.warm_entries <= 0:
            return
        keys = self.cache.recent(self.holder.current.key, self.settings.warm_entries)

        async def one(key: Hashable) -> None:
            if key not in self._jobs:
                return
            make_job, local = self._jobs[key]
            fresh.retain()
            try:
                answer = await self._evaluator(local).run(
                    make_job(fresh), Deadline(self.limits.timeout), on_done=fresh.release
                )
            except Exception:  # the first request for it computes it then
                return
            self.cache.put((fresh.key, key), answer)

        await asyncio.gather(*(one(key) for key in keys))

    async def run_json(
        self,
        build: Callable[[Served], Any],
        key: Hashable | None,
        deadline: Deadline,
        *,
        locked: bool = False,
    ) -> Response:
        """Run ``build`` on the current graph in a worker and answer what it returns as JSON
        (cached by ``key`` unless None). ``locked``: under the served graph's lock, as the
        services' session (its cursors) takes one call at a time.

        Raises
        ------
        CadkgError
            As ``build`` raises it, or on the time limit.
        """

        def make_job(served: Served) -> Job:
            def job(_: Deadline) -> Answer:
                if locked:
                    with served.lock:
                        data = build(served)
                else:
                    data = build(served)
                return Answer(json.dumps(data, ensure_ascii=False, default=str).encode(), "application/json")

            return job

        # Built here, in a thread: the query workers answer SPARQL, not Python callables.
        return await self.answer(make_job, key, deadline, local=True)

    async def answer(
        self,
        make_job: JobMaker,
        key: Hashable | None,
        deadline: Deadline,
        *,
        local: bool = False,
    ) -> Response:
        """:meth:`run`'s answer as the response, naming the generation it came from."""
        answer, generation = await self.run(make_job, key, deadline, local=local)
        return self.respond(answer, generation)

    def respond(self, answer: Answer, generation: str) -> Response:
        headers = dict(answer.headers)
        headers[GENERATION_HEADER] = generation
        return Response(answer.body, answer.status, headers, media_type=answer.media_type)

    def check_token(self, authorization: str | None) -> None:
        """Raises
        ------
        ProtocolError
            403 when the endpoint is read-only, 401 without the right bearer token.
        """
        if not self.settings.allow_update:
            raise ProtocolError(
                403, "this endpoint is read-only; start it with --allow-update --token to accept writes"
            )
        self.check_bearer(authorization)

    def check_holder(self, authorization: str | None, what: str) -> None:
        """For a change that is not a write to the graph (a reload, a cursor): the token.

        Raises
        ------
        ProtocolError
            403 when the endpoint has no token, 401 without the right bearer token.
        """
        if not self.settings.token:
            raise ProtocolError(403, f"{what} needs the endpoint's token; start it with --token")
        self.check_bearer(authorization)

    def check_bearer(self, authorization: str | None) -> None:
        """Raises
        ------
        ProtocolError
            401 unless ``authorization`` is ``Bearer <the endpoint's token>``.
        """
        token = self.settings.token or ""
        scheme, _, given = (authorization or "").partition(" ")
        if (
            not token
            or scheme.lower() != "bearer"
            or not hmac.compare_digest(given.strip().encode(), token.encode())
        ):
            raise ProtocolError(
                401,
                "this needs the endpoint's token: Authorization: Bearer <token>",
                {"WWW-Authenticate": 'Bearer realm="cadkg"'},
            )
