"""Named SPARQL queries: the ``.rq`` files of ``query/sparql`` and of each use case's ``queries``.

Each file starts with a comment header::

    # components: every component with its label, CAD items and pins.
    # param label: string — the component label, e.g. F1500.1

The first line names and describes the query; ``param`` lines declare its
parameters (``string``, ``integer``, ``decimal`` or ``iri``). Parameters are bound
by a ``VALUES`` block opening the query's WHERE group (:func:`cadkg.sparql_text.bind_values`),
where pyoxigraph's planner starts its joins; so that it can go on from there, a query
states its required patterns before its ``OPTIONAL`` ones.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from functools import cache
from importlib import resources
from typing import TYPE_CHECKING, Any

import pyoxigraph as ox

import cadkg.registry as registry
from cadkg.errors import QueryError

if TYPE_CHECKING:
    from cadkg.store import GraphStore, QueryResult

__all__ = ["NamedQuery", "Param", "coerce_params", "named_queries", "run_named"]

_PARAM = re.compile(r"^#\s*param\s+(\w+)\s*:\s*(string|integer|decimal|iri)\s*(?:[—-]+\s*(.*))?$")
_HEAD = re.compile(r"^#\s*([\w-]+)\s*:\s*(.+)$")


@dataclass(frozen=True)
class Param:
    name: str
    type: str
    description: str


@dataclass(frozen=True)
class NamedQuery:
    name: str
    description: str
    params: tuple[Param, ...]
    text: str


def _parse(name: str, text: str) -> NamedQuery:
    lines = text.splitlines()
    head = _HEAD.match(lines[0]) if lines else None
    if head is None or head.group(1) != name:
        raise QueryError(f"{name}.rq: the first line must be '# {name}: what it answers'")
    params = []
    for line in lines[1:]:
        if not line.startswith("#"):
            break
        match = _PARAM.match(line.strip())
        if match:
            params.append(Param(match.group(1), match.group(2), (match.group(3) or "").strip()))
    return NamedQuery(name, head.group(2).strip(), tuple(params), text)


@cache
def named_queries() -> dict[str, NamedQuery]:
    """Every named query of cadkg and of its use cases, by name.

    Raises
    ------
    QueryError
        When two folders hold a query of the same name.
    """
    folders = [resources.files("cadkg.query").joinpath("sparql"), *registry.query_folders()]
    queries: dict[str, NamedQuery] = {}
    for folder in folders:
        for entry in sorted(folder.iterdir(), key=lambda e: e.name):
            if entry.name.endswith(".rq"):
                name = entry.name[:-3]
                if name in queries:
                    raise QueryError(f"two named queries are called {name!r} (one in {folder})")
                queries[name] = _parse(name, entry.read_text(encoding="utf-8"))
    return dict(sorted(queries.items()))


def coerce_params(query: NamedQuery, params: dict[str, Any]) -> dict[str, Any]:
    """Check and convert parameters (strings from a command line are fine).

    Raises
    ------
    QueryError
        On a missing or unknown parameter, or a value of the wrong type.
    """
    declared = {p.name: p for p in query.params}
    unknown = sorted(set(params) - set(declared))
    if unknown:
        raise QueryError(
            f"query {query.name!r} has no parameter {unknown[0]!r}; "
            f"parameters: {', '.join(declared) or 'none'}"
        )
    values: dict[str, Any] = {}
    for param in query.params:
        if param.name not in params:
            raise QueryError(f"query {query.name!r} needs {param.name}=... ({param.description})")
        raw = params[param.name]
        try:
            if param.type == "integer":
                values[param.name] = int(raw)
            elif param.type == "decimal":
                values[param.name] = Decimal(str(raw))
            elif param.type == "iri":
                values[param.name] = ox.NamedNode(str(raw))
            else:
                values[param.name] = str(raw)
        except (ValueError, InvalidOperation):
            raise QueryError(f"parameter {param.name}={raw!r} is not a valid {param.type}") from None
    return values


def run_named(kg: GraphStore, name: str, **params: Any) -> QueryResult:
    """Run the named query ``name`` with its parameters.

    Raises
    ------
    QueryError
        When the query does not exist or a parameter is missing, unknown or malformed.
    """
    queries = named_queries()
    if name not in queries:
        raise QueryError(f"no named query {name!r}; known: {', '.join(queries)}")
    query = queries[name]
    return kg.query(query.text, **coerce_params(query, params))
