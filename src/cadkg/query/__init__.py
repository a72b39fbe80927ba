"""Queries over the cell graph: named SPARQL, graph views, exports and validation."""

from cadkg.query.named import NamedQuery, Param, named_queries, run_named
from cadkg.query.validate import Finding, validate
from cadkg.query.views import DEFAULT_RELATIONS, graph_view, write_graphml

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
