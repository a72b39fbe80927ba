"""What an ELIMCO cell adds to the 3D workbench's scene: the bench pins (one frame each, as
``pin_frames`` gives them) and each cable's route over them.
"""

from __future__ import annotations

from typing import Any

from cadkg.services.service import to_jsonable
from cadkg.services.session import Session
from cadkg.services.table import call

__all__ = ["bench_scene"]

_BENCH_PINS = "SELECT ?pin ?label WHERE { ?pin a ck:BenchPin ; ck:label ?label }"
_ROUTES = """
SELECT ?route ?cable ?cableLabel ?index ?pinLabel WHERE {
  ?route a ck:RoutePath ; ck:routeOf ?cable ; ck:hasWaypoint ?wp .
  ?wp ck:sequenceIndex ?index ; ck:atKeypoint ?pin . ?pin a ck:BenchPin ; ck:label ?pinLabel .
  OPTIONAL { ?cable ck:label ?cableLabel }
} ORDER BY ?route ?index"""


def _labels(graph: Any, text: str, key: str) -> dict[str, str]:
    return {str(row["label"]): row[key] for row in graph.query(text).rows}


def bench_scene(graph: Any, session: Session, frames: set[str], out: dict[str, list[Any]]) -> None:
    """The bench pins (a point in each pin's frame) and each cable's route over them."""
    result = to_jsonable(call(session, "pin_frames", {}))
    pins = _labels(graph, _BENCH_PINS, "pin")
    for frame in result.get("frames", []):
        name = frame["name"]
        label = next((p for p in pins if name in (f"pin_{p}", f"pin_{p}_a", f"pin_{p}_b")), None)
        if label is not None and name in frames:
            out["points"].append({"kind": "bench-pin", "frame": name, "label": label, "iri": pins[label]})
    routes: dict[str, dict[str, Any]] = {}
    for row in graph.query(_ROUTES).rows:
        label = row["cableLabel"] or row["cable"].rsplit("/", 1)[-1]
        route = routes.setdefault(row["route"], {"label": str(label), "iri": row["cable"], "via": []})
        frame = f"pin_{row['pinLabel']}"
        if frame in frames and (not route["via"] or route["via"][-1] != frame):
            route["via"].append(frame)
    for route in routes.values():
        if len(route["via"]) >= 2:
            out["routes"].append(route)
