"""Where the endpoint's queries are evaluated: in worker processes killed at their time limit.

Every query a client writes or picks (``/sparql``, ``/api/queries/<name>``, graph reads of
``/graph-store``) is described by a :class:`QuerySpec` and answered by :func:`answer` in one
of the served graph's worker processes (:class:`cadkg.query.workers.WorkerPool`, made on first
use from a snapshot of the graph, again after each update). The worker stops a query whose
solutions stream at its deadline by itself and keeps going; one that does not stop within
:data:`GRACE` more is killed, so its core is idle again and a fresh worker takes its place.
A remote store evaluates its own queries: those run here in a thread, as before.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import pyoxigraph as ox

from cadkg.query.workers import WorkerPool
from cadkg.served.holder import Served
from cadkg.server.columns import with_star_order
from cadkg.server.context import TRUNCATED_HEADER, Answer, Job, ProtocolError, Settings
from cadkg.server.limits import Deadline
from cadkg.server.results import (
    Format,
    NotAcceptableError,
    read_solutions,
    read_triples,
    write_boolean,
    write_graph,
    write_table,
)
from cadkg.store import GraphStore, evaluation_errors

__all__ = ["GRACE", "QuerySpec", "answer", "embedded", "evaluate", "pool_maker", "query_job"]

GRACE = 0.5
"""Seconds past its deadline a worker has to stop a query by itself before it is killed."""
_ANSWER = "cadkg.server.evaluation:answer"


def embedded(graph: Any) -> bool:
    """Whether ``graph`` is the embedded store (a remote one answers only :meth:`raw_query`)."""
    return isinstance(graph, GraphStore) and type(graph).raw_query is GraphStore.raw_query


@dataclass(frozen=True)
class QuerySpec:
    """One query to answer: its text, bound parameters or dataset, and the answer's formats.

    ``bindings`` go through :meth:`GraphStore.raw_query`; without them the text goes through
    :meth:`GraphStore.execute`, which keeps the parser's whole message for a 400.
    """

    text: str
    results_fmt: Format | NotAcceptableError
    graph_fmt: Format | NotAcceptableError
    max_rows: int
    bindings: Mapping[str, Any] | None = None
    default_graphs: tuple[str, ...] = ()
    named_graphs: tuple[str, ...] = ()

    def run(self, graph: Any) -> Any:
        if self.bindings is not None:
            return graph.raw_query(self.text, self.bindings)
        dataset = bool(self.default_graphs or self.named_graphs)
        if not embedded(graph):
            if dataset:
                raise ProtocolError(
                    400,
                    "default-graph-uri and named-graph-uri are not supported on a remote store; use GRAPH",
                )
            return graph.raw_query(self.text)
        if not dataset:
            return graph.execute(self.text)
        return graph.execute(self.text, default_graphs=self.default_graphs, named_graphs=self.named_graphs)


def evaluate(
    run: Callable[[], Any],
    results_fmt: Format | NotAcceptableError,
    graph_fmt: Format | NotAcceptableError,
    max_rows: int,
    deadline: Deadline,
) -> Answer:
    """Run a query and write its answer, reading at most ``max_rows`` rows (or triples).

    Raises
    ------
    QueryError, TimeLimitError, NotAcceptableError
        From the query, the deadline, or a format that cannot carry this kind of answer.
    """
    result = run()
    try:
        with evaluation_errors():
            if isinstance(result, bool | ox.QueryBoolean):
                if isinstance(results_fmt, NotAcceptableError):
                    raise results_fmt
                return Answer(write_boolean(bool(result), results_fmt), results_fmt.content_type)
            if hasattr(result, "variables"):
                if isinstance(results_fmt, NotAcceptableError):
                    raise results_fmt
                table = read_solutions(result, max_rows, deadline)
                body, fmt = write_table(table, results_fmt), results_fmt
            else:
                if isinstance(graph_fmt, NotAcceptableError):
                    raise graph_fmt
                table = read_triples(result, max_rows, deadline)
                body, fmt = write_graph(table.rows, graph_fmt), graph_fmt
    finally:
        # pyoxigraph's result iterators must be dropped on the thread that made them, not by
        # the event loop when it discards the traceback of an error.
        del result
    headers = ((TRUNCATED_HEADER, str(max_rows)),) if table.truncated else ()
    return Answer(body, fmt.content_type, headers=headers)


def answer(graph: Any, spec: QuerySpec, seconds: float, at: float) -> Answer:
    """The answer to ``spec`` on ``graph`` by the deadline ``at`` (a monotonic time): the task
    run in a worker process."""
    deadline = Deadline.until(at, seconds)
    return evaluate(
        lambda: with_star_order(spec.run(graph), spec.text),
        spec.results_fmt,
        spec.graph_fmt,
        spec.max_rows,
        deadline,
    )


def pool_maker(settings: Settings) -> Callable[[Any], WorkerPool | None]:
    """How a served graph gets its workers: none for a remote store."""

    def make(graph: Any) -> WorkerPool | None:
        if not embedded(graph):
            return None
        return WorkerPool(
            graph,
            settings.limits.workers,
            allowed_services=settings.allowed_services,
            preload=("cadkg.server.evaluation",),
            memory=settings.limits.query_memory,
        )

    return make


def query_job(settings: Settings, served: Served, spec: QuerySpec) -> Job:
    """The job answering ``spec`` on ``served``: in one of its workers, or here for a remote store."""
    make = pool_maker(settings)

    def job(deadline: Deadline) -> Answer:
        workers = served.workers(make)
        if workers is None:
            return answer(served.graph, spec, deadline.seconds, deadline.at)
        args = (spec, deadline.seconds, deadline.at)
        result: Answer = workers.call(_ANSWER, args, seconds=deadline.seconds, at=deadline.at, grace=GRACE)
        return result

    return job
