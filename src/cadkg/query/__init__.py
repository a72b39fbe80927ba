"""Queries over the cell graph: named SPARQL, graph views, exports and validation."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from cadkg.query.named import NamedQuery, Param, named_queries, run_named
from cadkg.query.validate import Finding, validate

if TYPE_CHECKING:
    from cadkg.query.views import DEFAULT_RELATIONS, graph_view, write_graphml

# The views import networkx: loaded when one is asked for, not with every query.
_VIEWS = ("DEFAULT_RELATIONS", "graph_view", "write_graphml")

__all__ = [
    "DEFAULT_RELATIONS",
    "Finding",
    "NamedQuery",
    "Param",
    "graph_view",
    "named_queries",
    "run_named",
    "validate",
    "write_graphml",
]


def __getattr__(name: str) -> Any:
    if name in _VIEWS:
        from cadkg.query import views

        return getattr(views, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
