"""The ``sparql`` service's answer as text, computed in a query worker (no rclpy here: the worker
imports this module alone)."""

from __future__ import annotations

from typing import Any

from cadkg.errors import CadkgError
from cadkg.store import GraphStore

__all__ = ["SPARQL_TEXT_TASK", "sparql_text"]

SPARQL_TEXT_TASK = "cadkg.ros_adapter.sparql:sparql_text"


def sparql_text(kg: GraphStore, query: str, bindings: dict[str, Any], fmt: str) -> str:
    """A query's result as text: SPARQL JSON or CSV results for SELECT/ASK, Turtle or JSON-LD for graphs.

    Raises
    ------
    CadkgError
        On a bad query, binding or format.
    """
    import pyoxigraph as ox

    fmt = (fmt or "json").lower()
    if fmt not in ("json", "csv", "turtle"):
        raise CadkgError(f"unknown format {fmt!r}; one of json, csv, turtle")
    result = kg.raw_query(query, bindings)
    if isinstance(result, ox.QueryTriples):
        graph_format = {"turtle": ox.RdfFormat.TURTLE, "json": ox.RdfFormat.JSON_LD}.get(fmt)
        if graph_format is None:
            raise CadkgError("a CONSTRUCT or DESCRIBE result is given as turtle or json (JSON-LD)")
        data = result.serialize(format=graph_format)
    else:
        results_format = {"json": ox.QueryResultsFormat.JSON, "csv": ox.QueryResultsFormat.CSV}.get(fmt)
        if results_format is None:
            raise CadkgError("a SELECT or ASK result is given as json or csv")
        if isinstance(result, ox.QueryBoolean) and fmt == "csv":
            return "true" if bool(result) else "false"
        data = result.serialize(format=results_format)
    assert data is not None
    return bytes(data).decode("utf-8")
