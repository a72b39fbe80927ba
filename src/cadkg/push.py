"""Copy a store's named graphs into an external SPARQL 1.1 store (``cadkg push``).

Two ways, one graph after the other:

- **Graph Store Protocol** (``PUT ?graph=G`` replaces graph G, ``POST`` adds to it), the
  default when a Graph Store endpoint is given;
- **SPARQL Update** (``DROP SILENT GRAPH`` then ``INSERT DATA``), for stores without one,
  or when the Graph Store endpoint answers that it does not exist (404, 405, 501).

Bodies are N-Triples written by pyoxigraph (every IRI and literal escaped), sent in
batches of at most ``batch`` triples. The triples holding blank nodes all go in a graph's
first request: a blank node label means one node only within one request.

Files that come with a store (the STL meshes in its files directory) are not RDF and are
not sent; ``ck:meshUri`` stays relative to a files directory the reader must provide.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Literal

import pyoxigraph as ox

from cadkg.errors import StoreError
from cadkg.graph import KnowledgeGraph
from cadkg.remote import DEFAULT_TIMEOUT, Auth, HttpSparql, is_url

__all__ = ["METHODS", "GraphPush", "PushReport", "push"]

METHODS = ("auto", "graph-store", "update")
# Virtuoso compiles an update to SQL and refuses more than 10000 lines of it: 1000 triples fit.
DEFAULT_BATCH = {"graph-store": 100_000, "update": 1_000}
_FALLBACK_STATUS = (404, 405, 501)


@dataclass(frozen=True)
class GraphPush:
    """One named graph sent: its IRI, triples, requests made and seconds taken."""

    graph: str
    triples: int
    requests: int
    seconds: float


@dataclass(frozen=True)
class PushReport:
    """What :func:`push` sent, how, and what it did not send."""

    method: Literal["graph-store", "update"]
    target: str
    graphs: tuple[GraphPush, ...]
    files_not_sent: int
    notes: tuple[str, ...] = ()

    @property
    def triples(self) -> int:
        return sum(g.triples for g in self.graphs)


def _batches(triples: list[ox.Triple], size: int) -> Iterator[list[ox.Triple]]:
    """Batches of at most ``size`` triples, except that every triple with a blank node is in the
    first one (which may then be larger); an empty graph is one empty batch."""
    blank: list[ox.Triple] = []
    plain: list[ox.Triple] = []
    for t in triples:
        has_blank = isinstance(t.subject, ox.BlankNode) or isinstance(t.object, ox.BlankNode)
        (blank if has_blank else plain).append(t)
    first = max(size - len(blank), 0)
    yield blank + plain[:first]
    for start in range(first, len(plain), size):
        yield plain[start : start + size]


def _ntriples(triples: list[ox.Triple]) -> bytes:
    data = ox.serialize(triples, format=ox.RdfFormat.N_TRIPLES)
    assert data is not None  # serialize() returns bytes when given no output
    return data


class _Sender:
    def __init__(self, http: HttpSparql, endpoint: str | None, graph_store: str | None) -> None:
        self.http = http
        self.endpoint = endpoint
        self.graph_store = graph_store

    def send(self, method: str, graph: str, triples: list[ox.Triple], batch: int | None) -> int:
        """Send one graph in batches; returns the number of requests."""
        requests = 0
        for i, chunk in enumerate(_batches(triples, batch or DEFAULT_BATCH[method])):
            if method == "graph-store":
                self.graph_store_batch(graph, chunk, first=i == 0)
            else:
                self.update_batch(graph, chunk, first=i == 0)
            requests += 1
        return requests

    def graph_store_batch(self, graph: str, triples: list[ox.Triple], first: bool) -> None:
        assert self.graph_store is not None
        params = {"graph": graph}
        if not triples:
            # An empty graph: remove what the store had (absent already is fine).
            self.http.send("DELETE", self.graph_store, params=params, allow=(404,))
            return
        self.http.send(
            "PUT" if first else "POST",
            self.graph_store,
            params=params,
            content=_ntriples(triples),
            headers={"Content-Type": "application/n-triples"},
        )

    def update_batch(self, graph: str, triples: list[ox.Triple], first: bool) -> None:
        assert self.endpoint is not None
        # The graph IRI was validated by pyoxigraph (NamedNode) and every term is escaped.
        node = str(ox.NamedNode(graph))
        body = _ntriples(triples).decode("utf-8")
        operations = [f"DROP SILENT GRAPH {node}"] if first else []
        if any(isinstance(t.subject, ox.BlankNode) or isinstance(t.object, ox.BlankNode) for t in triples):
            # INSERT DATA may hold blank nodes, but Virtuoso refuses them there; a template
            # over the one empty solution makes the same fresh nodes in any store.
            operations.append(f"INSERT {{ GRAPH {node} {{\n{body}}} }} WHERE {{}}")
        elif triples:
            operations.append(f"INSERT DATA {{ GRAPH {node} {{\n{body}}} }}")
        self.http.send("POST", self.endpoint, data={"update": " ;\n".join(operations)})


def push(
    kg: KnowledgeGraph,
    endpoint: str | None = None,
    *,
    graph_store: str | None = None,
    auth: Auth | None = None,
    method: str = "auto",
    batch: int | None = None,
    timeout: float = DEFAULT_TIMEOUT,
    graphs: Iterable[str] | None = None,
    on_graph: Callable[[GraphPush], None] | None = None,
) -> PushReport:
    """Send every named graph of ``kg`` (or those in ``graphs``) to a SPARQL 1.1 store.

    Parameters
    ----------
    kg
        A local store (opened or built in memory).
    endpoint
        The store's SPARQL Update endpoint (used by ``update``, and by ``auto`` when there is
        no ``graph_store`` or it turns out not to exist).
    graph_store
        The store's Graph Store Protocol endpoint (used by ``graph-store`` and ``auto``).
    auth
        Credentials for both endpoints.
    method
        ``auto`` (the Graph Store Protocol when ``graph_store`` is given, else SPARQL Update),
        ``graph-store`` or ``update``.
    batch
        Most triples in one request (default 100000 for the Graph Store Protocol, 1000 for
        Update).
    on_graph
        Called after each graph is sent.

    Raises
    ------
    StoreError
        When ``kg`` is itself remote, an endpoint the method needs is missing or not a URL,
        or the store refuses a request; graphs sent before the failure stay sent.
    QueryError
        When the store rejects an update as malformed.
    """
    if not isinstance(kg, KnowledgeGraph) or getattr(kg, "endpoint", None) is not None:
        raise StoreError("push sends a local store (a store directory or a manifest), not a remote one")
    for url in (endpoint, graph_store):
        if url is not None and not is_url(url):
            raise StoreError(f"{url!r} is not an http(s) URL")
    chosen: Literal["graph-store", "update"]
    if method == "auto":
        chosen = "graph-store" if graph_store else "update"
    elif method == "graph-store":
        chosen = "graph-store"
    elif method == "update":
        chosen = "update"
    else:
        raise StoreError(f"unknown push method {method!r}; one of {', '.join(METHODS)}")
    if chosen == "graph-store" and not graph_store:
        raise StoreError("the Graph Store Protocol needs its endpoint: give --graph-store URL")
    if chosen == "update" and not endpoint:
        raise StoreError("SPARQL Update needs the store's update endpoint: give --endpoint URL")
    if batch is not None and batch < 1:
        raise StoreError(f"batch must be at least 1 triple, not {batch}")

    names = list(graphs) if graphs is not None else kg.named_graphs()
    files = sum(1 for p in kg.files_dir.rglob("*") if p.is_file()) if kg.files_dir.is_dir() else 0
    notes: list[str] = []
    sent: list[GraphPush] = []
    http = HttpSparql(auth, timeout)
    sender = _Sender(http, endpoint, graph_store)
    try:
        for name in names:
            started = time.perf_counter()
            triples = [ox.Triple(q.subject, q.predicate, q.object) for q in kg.graph_quads(name)]
            try:
                requests = sender.send(chosen, name, triples, batch)
            except StoreError as err:
                # Nothing was written yet: a store without the Graph Store Protocol gets Update.
                if not (
                    method == "auto" and chosen == "graph-store" and endpoint and not sent and _missing(err)
                ):
                    raise
                notes.append(f"no Graph Store Protocol at {graph_store} ({err}); used SPARQL Update")
                chosen = "update"
                requests = sender.send(chosen, name, triples, batch)
            report = GraphPush(name, len(triples), requests, time.perf_counter() - started)
            sent.append(report)
            if on_graph is not None:
                on_graph(report)
    finally:
        http.close()
    if files:
        notes.append(
            f"{files} file(s) of the store's files directory (STL meshes) were not sent: "
            "a triple store holds RDF only"
        )
    target = graph_store if chosen == "graph-store" and graph_store else (endpoint or "")
    return PushReport(chosen, target, tuple(sent), files, tuple(notes))


def _missing(err: StoreError) -> bool:
    return any(f"HTTP {status}" in str(err) for status in _FALLBACK_STATUS)
