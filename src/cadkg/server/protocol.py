"""The SPARQL 1.1 Protocol (queries and updates at ``/sparql``) and the Graph Store Protocol
(``/graph-store``).

Queries come by GET (``?query=``), by POST of a form (``query=``) or by POST of
``application/sparql-query``; updates by POST of a form (``update=``) or of
``application/sparql-update``. ``default-graph-uri`` and ``named-graph-uri`` fix the
dataset; without them the default graph is the union of the named graphs, as everywhere
in cadkg, and the prefixes ``ck: rdf: rdfs: owl: xsd:`` are declared. The answer's format
comes from ``Accept`` or a ``format`` parameter (``json xml csv tsv`` for results,
``ttl nt jsonld rdfxml`` for graphs).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from urllib.parse import parse_qsl

import pyoxigraph as ox
from starlette.requests import Request
from starlette.responses import Response

from cadkg.errors import CadkgError, QueryError, StoreError
from cadkg.outbound import check_outbound
from cadkg.served.holder import Served
from cadkg.server.context import (
    Answer,
    Endpoint,
    Job,
    ProtocolError,
    error_response,
    status_of,
    syntax_message,
)
from cadkg.server.evaluation import QuerySpec, embedded, query_job
from cadkg.server.limits import BodyTooLargeError, Deadline
from cadkg.server.results import GRAPH_FORMATS, RESULT_FORMATS, Format, NotAcceptableError, negotiate
from cadkg.store import PREFIXES

__all__ = ["Operation", "graph_store", "read_body", "read_operation", "sparql"]

_FORM = "application/x-www-form-urlencoded"
_QUERY = "application/sparql-query"
_UPDATE = "application/sparql-update"


@dataclass(frozen=True)
class Operation:
    """One protocol request: a query or an update, its dataset, the requested format."""

    text: str
    update: bool
    default_graphs: tuple[str, ...]
    named_graphs: tuple[str, ...]
    fmt: str | None

    @property
    def has_dataset(self) -> bool:
        return bool(self.default_graphs or self.named_graphs)


async def read_body(request: Request, limit: int) -> bytes:
    """The request body, refused as soon as it passes ``limit`` bytes.

    Raises
    ------
    BodyTooLargeError
        When ``Content-Length`` or the bytes received pass the limit.
    """
    declared = request.headers.get("content-length")
    # Compared as text first: int() refuses over 4,300 digits, and '²'.isdigit() holds.
    digits = (declared or "").lstrip("0")
    if (
        declared is not None
        and declared.isascii()
        and declared.isdigit()
        and (len(digits) > len(str(limit)) or int(digits or "0") > limit)
    ):
        raise BodyTooLargeError(f"the request body of {declared} bytes is over the limit of {limit} bytes")
    chunks: list[bytes] = []
    size = 0
    async for chunk in request.stream():
        size += len(chunk)
        if size > limit:
            raise BodyTooLargeError(f"the request body is over the limit of {limit} bytes")
        chunks.append(chunk)
    return b"".join(chunks)


def _media(request: Request) -> str:
    return request.headers.get("content-type", "").split(";")[0].strip().lower()


def _decode(body: bytes) -> str:
    try:
        return body.decode("utf-8")
    except UnicodeDecodeError as err:
        raise ProtocolError(400, f"the request body is not UTF-8 (byte {err.start})") from None


def _pick(pairs: Sequence[tuple[str, str]], name: str) -> list[str]:
    return [value for key, value in pairs if key == name]


async def read_operation(request: Request, limit: int) -> Operation:
    """The operation of a ``/sparql`` request.

    Raises
    ------
    ProtocolError
        On a method or media type the protocol does not allow, or no or two operations.
    BodyTooLargeError
        When the body is over ``limit`` bytes.
    """
    url_pairs = parse_qsl(request.url.query, keep_blank_values=True)
    pairs = list(url_pairs)
    body_text: str | None = None
    update = False
    if request.method == "POST":
        media = _media(request)
        body = await read_body(request, limit)
        if media == _FORM:
            pairs += parse_qsl(_decode(body), keep_blank_values=True)
        elif media == _QUERY:
            body_text = _decode(body)
        elif media == _UPDATE:
            body_text, update = _decode(body), True
        else:
            raise ProtocolError(
                415, f"a POST is {_FORM}, {_QUERY} or {_UPDATE}, not {media or 'without a content type'}"
            )
    queries, updates = _pick(pairs, "query"), _pick(pairs, "update")
    if request.method != "POST" and updates:
        raise ProtocolError(400, "an update is sent by POST, never by GET")
    if body_text is None:
        if len(queries) + len(updates) != 1:
            raise ProtocolError(
                400, "give exactly one query= or update= parameter (or a sparql-query/update body)"
            )
        body_text, update = (queries[0], False) if queries else (updates[0], True)
    elif queries or updates:
        raise ProtocolError(400, "a sparql-query or sparql-update body comes without query= or update=")
    if update and (_pick(pairs, "using-graph-uri") or _pick(pairs, "using-named-graph-uri")):
        raise ProtocolError(400, "using-graph-uri and using-named-graph-uri are not supported; use USING")
    if not body_text.strip():
        raise ProtocolError(400, "the query is empty")
    formats = _pick(pairs, "format")
    return Operation(
        body_text,
        update,
        tuple(_pick(pairs, "default-graph-uri")),
        tuple(_pick(pairs, "named-graph-uri")),
        formats[-1] if formats else None,
    )


def _maybe(accept: str | None, fmt: str | None, formats: dict[str, Format]) -> Format | NotAcceptableError:
    try:
        return negotiate(accept, fmt, formats)
    except NotAcceptableError as err:
        return err


def fail(err: Exception, text: str = "", retry_after: int = 5) -> Response:
    """The clean error response of ``err`` (a syntax error shows its line and column)."""
    status, headers = status_of(err)
    message = str(err)
    if isinstance(err, QueryError):
        message = syntax_message(message, text)
    if status == 503:
        headers = {**headers, "Retry-After": str(retry_after)}
    return error_response(status, message, headers)


async def sparql(request: Request) -> Response:
    """``/sparql``: SPARQL 1.1 Protocol queries (GET, POST) and updates (POST)."""
    endpoint: Endpoint = request.app.state.endpoint
    deadline = Deadline(endpoint.limits.timeout)
    text = ""
    try:
        op = await read_operation(request, endpoint.limits.max_body)
        text = op.text
        # Before anything runs, on any store: a remote one would fetch for us just the same.
        check_outbound(text, endpoint.settings.allowed_services, PREFIXES)
        if op.update:
            return await _update(endpoint, request, op, deadline)
        accept = request.headers.get("accept")
        results_fmt = _maybe(accept, op.fmt, RESULT_FORMATS)
        graph_fmt = _maybe(accept, op.fmt, GRAPH_FORMATS)
        if isinstance(results_fmt, NotAcceptableError) and isinstance(graph_fmt, NotAcceptableError):
            raise results_fmt
        spec = QuerySpec(
            op.text,
            results_fmt,
            graph_fmt,
            endpoint.limits.max_rows,
            default_graphs=op.default_graphs,
            named_graphs=op.named_graphs,
        )

        def make_job(served: Served) -> Job:
            return query_job(endpoint.settings, served, spec)

        key = ("sparql", op.text, op.default_graphs, op.named_graphs, str(results_fmt), str(graph_fmt))
        return await endpoint.answer(make_job, key, deadline)
    except CadkgError as err:
        return fail(err, text, endpoint.settings.retry_after)


async def _update(endpoint: Endpoint, request: Request, op: Operation, deadline: Deadline) -> Response:
    endpoint.check_token(request.headers.get("authorization"))
    if op.has_dataset:
        raise ProtocolError(400, "an update takes no default-graph-uri or named-graph-uri; use WITH or USING")

    def make_job(served: Served) -> Job:
        def job(_: Deadline) -> Answer:
            if not embedded(served.graph):
                raise ProtocolError(501, "updates are not supported on a remote store; use cadkg push")
            with served.lock:
                served.graph.execute(op.text, update=True)
                served.edited()
            return Answer(b"updated\n", "text/plain; charset=utf-8")

        return job

    # An update is never retried on another graph: it ran, or it failed as a whole.
    served = endpoint.holder.acquire()
    try:
        answer = await endpoint.writer.run(make_job(served), deadline)
        return endpoint.respond(answer, served.generation)
    finally:
        served.release()


# -- Graph Store Protocol ---------------------------------------------------------------------


def _target(request: Request) -> str | None:
    """The graph IRI of a Graph Store request, ``None`` for ``?default``.

    Raises
    ------
    ProtocolError
        Without exactly one of ``graph=IRI`` and ``default``, or with a malformed IRI.
    """
    pairs = parse_qsl(request.url.query, keep_blank_values=True)
    graphs = _pick(pairs, "graph")
    default = any(key == "default" for key, _ in pairs)
    if len(graphs) + int(default) != 1:
        raise ProtocolError(400, "name the graph: ?graph=IRI or ?default")
    if default:
        return None
    try:
        return ox.NamedNode(graphs[0]).value
    except ValueError as err:
        raise ProtocolError(400, f"graph={graphs[0]!r} is not an IRI: {err}") from None


async def graph_store(request: Request) -> Response:
    """``/graph-store``: read a named graph (GET; a HEAD comes as a GET) or, with the token,
    replace (PUT), add to (POST) or remove (DELETE) it."""
    endpoint: Endpoint = request.app.state.endpoint
    deadline = Deadline(endpoint.limits.timeout)
    try:
        graph_iri = _target(request)
        if request.method == "GET":
            return await _read_graph(endpoint, request, graph_iri, deadline)
        endpoint.check_token(request.headers.get("authorization"))
        if graph_iri is None:
            raise ProtocolError(400, "every triple of a cadkg store lives in a named graph; give ?graph=IRI")
        data = b""
        rdf_format: ox.RdfFormat | None = None
        if request.method in ("PUT", "POST"):
            media = _media(request)
            rdf_format = ox.RdfFormat.from_media_type(media) if media else None
            if rdf_format is None:
                raise ProtocolError(415, f"cannot read a graph sent as {media or 'no content type'}")
            data = await read_body(request, endpoint.limits.max_body)
        return await _write_graph(endpoint, request.method, graph_iri, data, rdf_format, deadline)
    except CadkgError as err:
        return fail(err, "", endpoint.settings.retry_after)


async def _read_graph(
    endpoint: Endpoint, request: Request, graph_iri: str | None, deadline: Deadline
) -> Response:
    fmt = negotiate(request.headers.get("accept"), None, GRAPH_FORMATS)
    inner = "?s ?p ?o" if graph_iri is None else f"GRAPH <{graph_iri}> {{ ?s ?p ?o }}"
    text = f"CONSTRUCT {{ ?s ?p ?o }} WHERE {{ {inner} }}"
    spec = QuerySpec(text, fmt, fmt, endpoint.limits.max_rows, {})

    def make_job(served: Served) -> Job:
        answer = query_job(endpoint.settings, served, spec)

        def job(d: Deadline) -> Answer:
            if graph_iri is not None and graph_iri not in served.graph.named_graphs():
                raise ProtocolError(404, f"no graph <{graph_iri}> in the store")
            return answer(d)

        return job

    return await endpoint.answer(make_job, ("graph-store", graph_iri, fmt.name), deadline)


async def _write_graph(
    endpoint: Endpoint,
    method: str,
    graph_iri: str,
    data: bytes,
    rdf_format: ox.RdfFormat | None,
    deadline: Deadline,
) -> Response:
    triples: bytes = b""
    if rdf_format is not None:
        try:
            parsed = [q.triple for q in ox.parse(data, format=rdf_format, base_iri=graph_iri)]
        except SyntaxError as err:
            raise ProtocolError(400, f"the graph does not parse: {err}") from None
        # pyoxigraph writes every term escaped, so the data cannot leave INSERT DATA.
        triples = ox.serialize(parsed, format=ox.RdfFormat.N_TRIPLES) or b""
    node = f"<{graph_iri}>"
    inserts = f"INSERT DATA {{ GRAPH {node} {{ {triples.decode('utf-8')} }} }}"
    served = endpoint.holder.acquire()
    try:

        def job(_: Deadline) -> Answer:
            if not embedded(served.graph):
                raise ProtocolError(501, "writes are not supported on a remote store; use cadkg push")
            with served.lock:
                existed = graph_iri in served.graph.named_graphs()
                if method == "DELETE":
                    if not existed:
                        raise ProtocolError(404, f"no graph {node} in the store")
                    served.graph.execute(f"DROP GRAPH {node}", update=True)
                elif method == "PUT":
                    served.graph.execute(f"DROP SILENT GRAPH {node} ; {inserts}", update=True)
                else:
                    served.graph.execute(inserts, update=True)
                served.edited()
            status = 201 if method in ("PUT", "POST") and not existed else 204
            return Answer(b"", "text/plain; charset=utf-8", status)

        answer = await endpoint.local.run(job, deadline)
        return endpoint.respond(answer, served.generation)
    except (QueryError, StoreError) as err:
        raise ProtocolError(400, str(err)) from None
    finally:
        served.release()
