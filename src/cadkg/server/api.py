"""The JSON side of the endpoint: services, named queries, the graph view, info and reload.

- ``GET /api``: the services (with their parameters) and the named queries.
- ``GET|POST /api/<service>?key=value``: one service call, answered as ``cadkg call`` prints
  it. A service whose declared :class:`~cadkg.services.service.Effect` changes something (the
  graph, or a caller's cursor) is taken only by POST with the token; a cursor belongs to the
  client the call names (``client=NAME`` or ``X-Cadkg-Client``), kept apart from those of
  other transports.
- ``GET /api/queries``: the named queries with their text; ``GET /api/queries/<name>?param=value``
  runs one, answered like ``/sparql`` (SPARQL JSON by default).
- ``GET /api/graph?component=LABEL`` or ``?node=IRI``: nodes and edges around a component
  (its pins, the wires to other components) or around any node, for the page's graph view.
- ``GET /api/info``: generation, size, named graphs, limits, query workers.
- ``POST /reload``: open the store again (with the token): the ``reload`` service.

``assign``, ``plan``, ``label_frames`` and ``reload`` are services of the one table
(:mod:`cadkg.services.operations`), served here as every use case's.
"""

from __future__ import annotations

import asyncio
import contextlib
import json
from collections.abc import Callable
from typing import Any
from urllib.parse import parse_qsl

import pyoxigraph as ox
from starlette.requests import Request
from starlette.responses import Response

from cadkg.errors import CadkgError, NotFound, QueryError
from cadkg.query.named import coerce_params, named_queries
from cadkg.served.holder import Served
from cadkg.server.context import Answer, Endpoint, Job, ProtocolError, json_response, status_of
from cadkg.server.evaluation import QuerySpec, embedded, query_job
from cadkg.server.files_root import confine, files_root
from cadkg.server.limits import Deadline
from cadkg.server.protocol import _FORM, fail, read_body
from cadkg.server.results import GRAPH_FORMATS, RESULT_FORMATS, NotAcceptableError, negotiate
from cadkg.server.workbench.routes import find_named
from cadkg.services.service import CONVERT, Effect, Paths, to_jsonable
from cadkg.services.table import SERVICES, call
from cadkg.store import PREFIXES

__all__ = [
    "CLIENT_HEADER",
    "component_graph",
    "graph_view",
    "index",
    "info",
    "named",
    "node_graph",
    "queries",
    "reload",
    "service",
]

_NEIGHBOURS = 150
CLIENT_HEADER = "X-Cadkg-Client"
_PINS = """
SELECT ?label ?component ?pin ?pinName ?level WHERE {
  ?component ck:label ?label ; a ck:Component .
  ?pin ck:pinOf ?component ; ck:pinName ?pinName .
  OPTIONAL { ?pin ck:level ?level }
}"""
_WIRES = """
SELECT ?label ?pin ?wire ?wireNumber ?other ?otherLabel ?otherPinName WHERE {
  { SELECT DISTINCT ?label ?wire ?pin ?otherPin WHERE {
      ?component ck:label ?label ; a ck:Component .
      ?pin ck:pinOf ?component .
      ?wire ck:fromPin|ck:toPin ?pin .
      ?wire ck:fromPin|ck:toPin ?otherPin .
      FILTER(?otherPin != ?pin) } }
  ?wire ck:wireNumber ?wireNumber .
  ?otherPin ck:pinName ?otherPinName ; ck:pinOf ?other .
  ?other ck:label ?otherLabel .
}"""
_AROUND = f"""
SELECT ?node ?p ?o ?out WHERE {{
  {{ ?node ?p ?o . BIND(true AS ?out) }} UNION {{ ?o ?p ?node . BIND(false AS ?out) }}
  FILTER(!isLiteral(?o))
}} LIMIT {_NEIGHBOURS}"""
_LITERALS = """
SELECT ?node ?p ?o WHERE { ?node ?p ?o FILTER(isLiteral(?o)) } LIMIT 60"""
_LABELS = (
    "SELECT ?n ?l WHERE {{ VALUES ?n {{ {nodes} }} ?n ck:label|rdfs:label|ck:pinName|ck:wireNumber ?l }}"
)


def _error(err: Exception) -> Response:
    status, headers = status_of(err)
    return json_response({"error": str(err)}, status, headers)


def _json_value(value: Any) -> Any:
    """A parameter of a JSON body as text; a list of texts (files to load) stays a list."""
    if isinstance(value, list) and all(isinstance(v, str) for v in value):
        return Paths(value)
    return value if isinstance(value, str) else str(value).lower()


async def _params(request: Request, limit: int) -> dict[str, Any]:
    pairs = parse_qsl(request.url.query, keep_blank_values=True)
    if request.method == "POST":
        body = await read_body(request, limit)
        media = request.headers.get("content-type", "").split(";")[0].strip().lower()
        if media == "application/json":
            try:
                data = json.loads(body or b"{}")
            except ValueError as err:
                raise ProtocolError(400, f"the body is not JSON: {err}") from None
            if not isinstance(data, dict):
                raise ProtocolError(400, "the body is a JSON object of parameters")
            pairs += [(str(k), _json_value(v)) for k, v in data.items()]
        elif media == _FORM:
            pairs += parse_qsl(body.decode("utf-8", "replace"), keep_blank_values=True)
        elif body:
            raise ProtocolError(415, "parameters come as a query string, a form or a JSON object")
    return dict(pairs)


async def index(request: Request) -> Response:
    """``GET /api``: what this endpoint offers."""
    services = [
        {
            "name": s.name,
            "profile": s.profile,
            "description": s.description,
            "params": {k: t.__name__.lower() for k, t in s.params.items()},
            "optional": sorted(s.optional),
        }
        for s in sorted(SERVICES.values(), key=lambda s: (s.profile, s.name))
    ]
    return json_response(
        {
            "services": services,
            "queries": [q.name for q in named_queries().values()],
            "endpoints": {
                "sparql": "/sparql",
                "graph_store": "/graph-store",
                "service": "/api/<service>?param=value&client=name",
                "named_query": "/api/queries/<name>?param=value",
                "graph_view": "/api/graph?component=LABEL or ?node=IRI",
                "bound_query": "/api/queries/<name>/bound?param=value",
                "terms": "/api/terms",
                "cell": "/api/cell",
                "plan": "/api/plan",
                "changes": "/api/changes",
                "info": "/api/info",
                "scene": "/api/scene",
                "mesh": "/api/mesh/<ck:meshUri>",
            },
        }
    )


def _check_change(endpoint: Endpoint, request: Request, name: str, effect: Effect) -> None:
    """Refuse a change unless it comes by POST with the token: derived from the declared effect
    alone, so a service cannot be left off a list of those that need it."""
    if request.method != "POST":
        raise ProtocolError(
            405,
            f"{name} changes state ({effect.value}): send it by POST with the token",
            {"Allow": "POST"},
        )
    authorization = request.headers.get("authorization")
    if effect.changes_graph:
        endpoint.check_token(authorization)
    elif effect is Effect.RELOADS:
        endpoint.check_holder(authorization, "a reload")
    else:
        endpoint.check_holder(authorization, f"{name} (it moves a cursor)")


async def service(request: Request) -> Response:
    """``/api/<service>``: one service call, as JSON."""
    return await call_service(request, request.path_params["service"])


async def call_service(
    request: Request, name: str, shape: Callable[[dict[str, Any]], Any] | None = None
) -> Response:
    """Call the service ``name`` of the table (a use case's, or one every cell offers: assign,
    plan, label_frames, reload) with the request's parameters, and answer its result as JSON,
    through ``shape`` when given (a route that keeps an older answer's form)."""
    endpoint: Endpoint = request.app.state.endpoint
    deadline = Deadline(endpoint.limits.timeout)
    try:
        if name not in SERVICES:
            raise NotFound(f"unknown service {name!r}; known: {', '.join(sorted(SERVICES))}")
        effect = SERVICES[name].effect
        if effect.changes:
            _check_change(endpoint, request, name, effect)
        params = await _params(request, endpoint.limits.max_body)
        lists = [
            k for k, v in params.items() if isinstance(v, Paths) and SERVICES[name].params.get(k) is not Paths
        ]
        if lists:
            raise QueryError(f"{name}: {', '.join(lists)} takes one value, not a list")
        client = params.pop("client", "") or request.headers.get(CLIENT_HEADER, "")
        if effect is Effect.CURSOR and not client:
            raise ProtocolError(400, f"{name}: name the cursor's owner with client=NAME or {CLIENT_HEADER}")
        # Over HTTP a client's cursor is its own, never another transport's (a robot's "default").
        owner = f"http:{client}"

        def shaped(result: Any) -> Answer:
            data = to_jsonable(result)
            return Answer(
                json.dumps(shape(data) if shape else data, default=str).encode(), "application/json"
            )

        if effect is Effect.RELOADS:
            # Not a job on the served graph: the graph it replaces goes on answering meanwhile.
            result = await asyncio.to_thread(endpoint.holder.run, name, params, owner)
            return endpoint.respond(shaped(result), endpoint.holder.current.generation)
        # What a service that loads files reads over HTTP is copied from inside the files root
        # first, and handed on as the list of those copies.
        files = {k for k, t in SERVICES[name].params.items() if t is Paths and k in params}
        if effect is Effect.LOADS:
            files_root(endpoint.settings.files_root)
        checked = {k: params[k] if isinstance(params[k], Paths) else CONVERT[Paths](params[k]) for k in files}

        def make_job(served: Served) -> Job:
            def job(_: Deadline) -> Answer:
                with served.lock, contextlib.ExitStack() as stack:  # cursors move one call at a time
                    scratch = []
                    given: dict[str, Any] = dict(params)
                    for key, names in checked.items():
                        folder, copies = stack.enter_context(confine(names, endpoint.settings.files_root))
                        given[key] = Paths(str(c) for c in copies)
                        scratch.append(f"{folder}/")
                    result = call(served.session(), name, given, client=owner)
                    if effect.changes_graph:
                        served.edited()
                answer = shaped(result)
                text = answer.body.decode()
                for prefix in scratch:  # messages name the files as the caller did
                    text = text.replace(json.dumps(prefix)[1:-1], "")
                return Answer(text.encode(), answer.media_type)

            return job

        return await endpoint.answer(make_job, None, deadline, local=True)
    except CadkgError as err:
        return _error(err)


async def queries(request: Request) -> Response:
    """``GET /api/queries``: the named queries, their parameters and text."""
    return json_response(
        [
            {
                "name": q.name,
                "description": q.description,
                "params": [{"name": p.name, "type": p.type, "description": p.description} for p in q.params],
                "text": q.text,
            }
            for q in named_queries().values()
        ]
    )


async def named(request: Request) -> Response:
    """``GET /api/queries/<name>?param=value``: run a named query, answered like ``/sparql``."""
    endpoint: Endpoint = request.app.state.endpoint
    deadline = Deadline(endpoint.limits.timeout)
    text = ""
    try:
        name = request.path_params["name"]
        query = find_named(name)
        text = query.text
        params = dict(parse_qsl(request.url.query, keep_blank_values=True))
        fmt = params.pop("format", None)
        bindings = coerce_params(query, params)
        accept = request.headers.get("accept")
        results_fmt = negotiate(accept, fmt, RESULT_FORMATS)
        not_graph = NotAcceptableError("a named query answers with results")
        spec = QuerySpec(text, results_fmt, not_graph, endpoint.limits.max_rows, bindings)

        def make_job(served: Served) -> Job:
            return query_job(endpoint.settings, served, spec)

        key = ("named", name, tuple(sorted(params.items())), results_fmt.name)
        return await endpoint.answer(make_job, key, deadline)
    except CadkgError as err:
        return fail(err, text, endpoint.settings.retry_after)


def _tail(iri: str) -> str:
    return iri.rstrip("/#").rsplit("#", 1)[-1].rsplit("/", 1)[-1] or iri


def component_graph(graph: Any, label: str) -> dict[str, Any]:
    """A component, its pins and the wires from them to other components, as nodes and edges.

    Raises
    ------
    NotFound
        When no component has this label.
    """
    pins = graph.query(_PINS, label=label).rows
    if not pins:
        raise NotFound(f"no component labelled {label!r} with pins")
    centre = pins[0]["component"]
    nodes: dict[str, dict[str, Any]] = {centre: {"id": centre, "label": label, "kind": "component"}}
    edges: list[dict[str, str]] = []
    for row in pins:
        name = row["pinName"] + (f":{row['level']}" if row["level"] is not None else "")
        if row["pin"] not in nodes:  # the union of the graphs may repeat a row
            nodes[row["pin"]] = {"id": row["pin"], "label": name, "kind": "pin"}
            edges.append({"source": centre, "target": row["pin"], "label": "pin", "kind": "pin"})
    seen: set[tuple[str, str]] = set()
    for row in graph.query(_WIRES, label=label).rows:
        other = row["other"]
        nodes.setdefault(other, {"id": other, "label": row["otherLabel"], "kind": "component"})
        if (row["wire"], row["pin"]) in seen:
            continue
        seen.add((row["wire"], row["pin"]))
        edges.append(
            {
                "source": row["pin"],
                "target": other,
                "label": f"{row['wireNumber']} → {row['otherPinName']}",
                "kind": "wire",
                "wire": row["wire"],
            }
        )
    return {"center": centre, "nodes": list(nodes.values()), "edges": edges, "properties": []}


def node_graph(graph: Any, iri: str) -> dict[str, Any]:
    """A node's neighbours (IRIs and blank nodes, both directions) and its literal properties.

    Raises
    ------
    NotFound
        When nothing in the graph mentions the node.
    """
    try:
        node = ox.NamedNode(iri)
    except ValueError as err:
        raise QueryError(f"node={iri!r} is not an IRI: {err}") from None
    rows = graph.query(_AROUND, node=node).rows
    literals = graph.query(_LITERALS, node=node).rows
    if not rows and not literals:
        raise NotFound(f"nothing in the graph mentions <{iri}>")
    nodes: dict[str, dict[str, Any]] = {iri: {"id": iri, "label": _tail(iri), "kind": "center"}}
    edges = []
    seen: set[tuple[str, str, str]] = set()
    for row in rows:
        other = row["o"]
        nodes.setdefault(other, {"id": other, "label": _tail(other), "kind": "node"})
        source, target = (iri, other) if row["out"] else (other, iri)
        if (source, row["p"], target) not in seen:
            seen.add((source, row["p"], target))
            edges.append({"source": source, "target": target, "label": _tail(row["p"]), "kind": "relation"})
    named = [ox.NamedNode(n) for n in nodes if not n.startswith("_:")]
    if named:
        text = _LABELS.format(nodes=" ".join(str(n) for n in named))
        for row in graph.query(text).rows:
            nodes[row["n"]]["label"] = str(row["l"])
    properties = [{"property": _tail(r["p"]), "iri": r["p"], "value": str(r["o"])} for r in literals]
    return {"center": iri, "nodes": list(nodes.values()), "edges": edges, "properties": properties}


async def graph_view(request: Request) -> Response:
    """``GET /api/graph?component=LABEL`` or ``?node=IRI``."""
    endpoint: Endpoint = request.app.state.endpoint
    deadline = Deadline(endpoint.limits.timeout)
    try:
        params = dict(parse_qsl(request.url.query, keep_blank_values=True))
        label, iri = params.get("component"), params.get("node")
        if bool(label) == bool(iri):
            raise ProtocolError(400, "give component=LABEL or node=IRI")

        def make_job(served: Served) -> Job:
            def job(_: Deadline) -> Answer:
                data = component_graph(served.graph, label) if label else node_graph(served.graph, iri or "")
                return Answer(json.dumps(data, default=str).encode(), "application/json")

            return job

        return await endpoint.answer(make_job, ("graph", label, iri), deadline, local=True)
    except CadkgError as err:
        return _error(err)


def _workers_info(served: Served, size: int) -> dict[str, Any] | None:
    """The query worker processes: ``ready`` once all have started; ``killed`` counts the
    queries stopped at their time limit."""
    if not embedded(served.graph):
        return None
    workers = served.made_workers
    return {
        "processes": size,
        "ready": bool(workers is not None and workers.warm),
        "started": workers.started if workers is not None else 0,
        "killed": workers.killed if workers is not None else 0,
    }


async def info(request: Request) -> Response:
    """``GET /api/info``: what is served, and under which limits."""
    endpoint: Endpoint = request.app.state.endpoint
    deadline = Deadline(endpoint.limits.timeout)
    limits = endpoint.limits
    try:

        def make_job(served: Served) -> Job:
            def job(_: Deadline) -> Answer:
                data = {
                    "generation": served.generation,
                    "triples": served.triples(),
                    "named_graphs": served.graph.named_graphs(),
                    "prefixes": PREFIXES,
                    "limits": {
                        "timeout_s": limits.timeout,
                        "max_rows": limits.max_rows,
                        "max_body_bytes": limits.max_body,
                    },
                    "update": endpoint.settings.allow_update,
                    # Whether a bearer token unlocks changes: the workbench's review panel asks
                    # for it only then.
                    "token": bool(endpoint.settings.token),
                    # Whether the served graph can change (a store directory is rebuilt under it;
                    # with the token, /reload): the page follows /api/changes only then.
                    "changes": bool(endpoint.settings.token)
                    or getattr(served.graph, "directory", None) is not None,
                    "formats": {"results": list(RESULT_FORMATS), "graph": list(GRAPH_FORMATS)},
                    "cache": {
                        "entries": len(endpoint.cache),
                        "hits": endpoint.cache.hits,
                        "misses": endpoint.cache.misses,
                    },
                    "reloads": endpoint.holder.reloads,
                    "workers": _workers_info(served, limits.workers),
                }
                return Answer(json.dumps(data).encode(), "application/json")

            return job

        return await endpoint.answer(make_job, None, deadline, local=True)
    except CadkgError as err:
        return _error(err)


async def reload(request: Request) -> Response:
    """``POST /reload``: the ``reload`` service; requests in flight finish on the old graph."""
    return await call_service(
        request, "reload", lambda data: {"previous": data["previous"], "generation": data["generation"]}
    )
