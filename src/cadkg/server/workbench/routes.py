"""The JSON routes behind the page's workbench, all read-only.

- ``GET /api/terms``: what the editor completes (:func:`cadkg.server.workbench.terms.completion_terms`).
- ``GET /api/queries/<name>/bound?param=value``: a named query's text with its parameters
  bound as the ``VALUES`` block the server itself would add, so the page shows (and keeps,
  when the text is edited) exactly what runs.
- ``GET /api/cell``: the served cell's name, profile and use case, and the profile each named
  query belongs to (``""``: cadkg's own, for any cell), so the page offers the cell's own.
- ``GET /api/scene``: the cell in 3D (:func:`cadkg.server.workbench.scene.cell_scene`).
- ``GET /api/mesh/<path>``: one binary STL mesh of the served store's files directory, by its
  ``ck:meshUri``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any
from urllib.parse import parse_qsl

from starlette.requests import Request
from starlette.responses import Response

from cadkg import registry
from cadkg.errors import CadkgError, NotFound
from cadkg.query.named import NamedQuery, coerce_params, named_queries
from cadkg.served.holder import Served
from cadkg.server.context import Answer, Endpoint, Job, json_response, status_of
from cadkg.server.limits import Deadline
from cadkg.server.workbench.scene import cell_scene, mesh_bytes
from cadkg.server.workbench.terms import completion_terms
from cadkg.sparql_text import bind_values, values_clause

__all__ = ["bound", "cell", "cell_info", "find_named", "mesh", "scene", "terms"]

_CELL = """
SELECT ?name ?profile ?description WHERE {
  ?c a ck:Cell . OPTIONAL { ?c ck:label ?name } OPTIONAL { ?c ck:profile ?profile }
  OPTIONAL { ?c ck:description|rdfs:comment ?description }
} LIMIT 1"""


def _error(err: Exception) -> Response:
    status, headers = status_of(err)
    return json_response({"error": str(err)}, status, headers)


async def _of_graph(request: Request, build: Callable[[Any], Any], key: str) -> Response:
    """What ``build`` makes of the served graph, as JSON, cached under ``key``."""
    endpoint: Endpoint = request.app.state.endpoint
    try:
        return await endpoint.run_json(
            lambda served: build(served.graph), (key,), Deadline(endpoint.limits.timeout)
        )
    except CadkgError as err:
        return _error(err)


async def terms(request: Request) -> Response:
    """``GET /api/terms``: prefixes, classes, properties and component labels for completion."""
    return await _of_graph(request, completion_terms, "terms")


async def scene(request: Request) -> Response:
    """``GET /api/scene``: the cell's frames, objects, meshes, routes and points of interest."""
    endpoint: Endpoint = request.app.state.endpoint
    try:
        return await endpoint.run_json(
            lambda served: cell_scene(served.graph, served.session()),
            ("scene",),
            Deadline(endpoint.limits.timeout),
            locked=True,  # the services' session is used one call at a time
        )
    except CadkgError as err:
        return _error(err)


def _query_profiles() -> dict[str, str]:
    """Each named query's profile: its use case's name, or ``""`` for cadkg's own."""
    owners: dict[str, str] = {}
    for case in registry.use_cases():
        if case.queries is not None:
            for entry in case.queries.iterdir():
                if entry.name.endswith(".rq"):
                    owners[entry.name[:-3]] = case.name
    return {name: owners.get(name, "") for name in named_queries()}


def cell_info(graph: Any) -> dict[str, Any]:
    """The cell's name, profile (``""`` when the graph names none), use case title and description,
    and the profile of each named query."""
    rows = graph.query(_CELL).rows
    row = rows[0] if rows else {}
    profile = str(row.get("profile") or "")
    try:
        title = registry.use_case(profile).title if profile else ""
    except KeyError:
        title = ""
    return {
        "name": str(row.get("name") or ""),
        "profile": profile,
        "title": title,
        "description": str(row.get("description") or ""),
        "queries": _query_profiles(),
    }


async def cell(request: Request) -> Response:
    """``GET /api/cell``: what the page says of the cell, and which named queries are its own."""
    return await _of_graph(request, cell_info, "cell")


def find_named(name: str) -> NamedQuery:
    """The named query ``name``.

    Raises
    ------
    NotFound
        When there is none of that name.
    """
    known = named_queries()
    if name not in known:
        raise NotFound(f"no named query {name!r}; known: {', '.join(known)}")
    return known[name]


async def bound(request: Request) -> Response:
    """``GET /api/queries/<name>/bound?param=value``: the named query's text with its
    parameters bound, and the ``VALUES`` block alone (JSON ``{"text", "values"}``)."""
    try:
        query = find_named(request.path_params["name"])
        bindings = coerce_params(query, dict(parse_qsl(request.url.query, keep_blank_values=True)))
        return json_response({"text": bind_values(query.text, bindings), "values": values_clause(bindings)})
    except CadkgError as err:
        return _error(err)


async def mesh(request: Request) -> Response:
    """``GET /api/mesh/<path>``: a mesh file of the served store, as binary STL."""
    endpoint: Endpoint = request.app.state.endpoint
    deadline = Deadline(endpoint.limits.timeout)
    rel = request.path_params["path"]
    try:

        def make_job(served: Served) -> Job:
            def job(_: Deadline) -> Answer:
                data = mesh_bytes(served.graph.files_dir, rel)
                if data is None:
                    raise NotFound(
                        f"no mesh file {rel!r} in the served store's files (a remote store holds none)"
                    )
                return Answer(data, "model/stl")

            return job

        answer, generation = await endpoint.run(make_job, ("mesh", rel), deadline)
        response = endpoint.respond(answer, generation)
        # A generation's files never change: the page may keep a mesh as long as it likes.
        response.headers["cache-control"] = "private, max-age=86400, immutable"
        return response
    except CadkgError as err:
        return _error(err)
