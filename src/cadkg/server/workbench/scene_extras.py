"""What each profile adds to the 3D view: its points of interest, routes and harnesses.

- elvez: every guide's key frames (``G4_key``, ``G4_key_corner``), the spots a taping
  operation works at, and each cable's route through the keys of its guides (``wh_routes``);
- elimco: the bench pins (one frame each, as ``pin_frames`` gives them) and each cable's
  route over them;
- harnesses (vw, and any cell holding a ``ck:Harness`` with a topology): nodes and segments,
  at the coordinates the graph gives (a node's ``ck:hasPose``), else laid out in a plane from
  the segment lengths (:func:`cadkg.server.workbench.harness_layout.layout`), and said so.

Each is read through the profile's services or the ontology's terms, as a client would.
"""

from __future__ import annotations

from typing import Any

from cadkg.errors import CadkgError
from cadkg.server.workbench.harness_layout import layout
from cadkg.services.service import to_jsonable
from cadkg.services.table import call

__all__ = ["profile_extras"]

_KEY_SUFFIXES = ("_key", "_key_corner")
_HARNESS_GAP = 0.3  # metres between harnesses laid out in one plane
_TAPED = """
SELECT DISTINCT ?spot ?label ?index WHERE {
  ?op a ck:TapeOperation ; ck:atSpot ?spot . ?spot ck:label ?label .
  OPTIONAL { ?op ck:sequenceIndex ?index }
} ORDER BY ?index"""
_GUIDES = "SELECT ?guide ?label WHERE { ?guide a ck:Component ; ck:label ?label }"
_HARNESS_NUMBERS = "SELECT DISTINCT ?n WHERE { ?h a ck:Harness ; ck:harnessNumber ?n } ORDER BY ?n"
_BENCH_PINS = "SELECT ?pin ?label WHERE { ?pin a ck:BenchPin ; ck:label ?label }"
_ROUTES = """
SELECT ?route ?cable ?cableLabel ?index ?pinLabel WHERE {
  ?route a ck:RoutePath ; ck:routeOf ?cable ; ck:hasWaypoint ?wp .
  ?wp ck:sequenceIndex ?index ; ck:atKeypoint ?pin . ?pin a ck:BenchPin ; ck:label ?pinLabel .
  OPTIONAL { ?cable ck:label ?cableLabel }
} ORDER BY ?route ?index"""
_HARNESSES = """
SELECT DISTINCT ?h WHERE { ?h a ck:Harness . ?node ck:partOf ?h ; a ck:HarnessNode }"""
_NODE_POSES = """
SELECT ?node ?x ?y ?z ?frame WHERE {
  ?node a ck:HarnessNode ; ck:hasPose ?pose . ?pose ck:tx ?x ; ck:ty ?y ; ck:tz ?z .
  OPTIONAL { ?pose ck:parentFrame/ck:label ?frame }
}"""


def _labels(graph: Any, text: str, key: str) -> dict[str, str]:
    return {str(row["label"]): row[key] for row in graph.query(text).rows}


def _elvez(graph: Any, session: Any, frames: set[str], out: dict[str, list[Any]]) -> None:
    guides = _labels(graph, _GUIDES, "guide")
    for name in sorted(frames):
        for suffix in _KEY_SUFFIXES:
            label = name.removesuffix(suffix)
            if name.endswith(suffix) and label in guides:
                kind = "key" if suffix == "_key" else "key-corner"
                out["points"].append({"kind": kind, "frame": name, "label": name, "iri": guides[label]})
                break
    for row in graph.query(_TAPED).rows:
        label = str(row["label"])
        frame = f"{label}_key" if f"{label}_key" in frames else None
        if frame is not None:
            text = f"{label}: taping" + (f" (operation {row['index']})" if row["index"] is not None else "")
            out["points"].append({"kind": "tape-spot", "frame": frame, "label": text, "iri": row["spot"]})
    for row in graph.query(_HARNESS_NUMBERS).rows:
        result = to_jsonable(call(session, "wh_routes", {"number": int(row["n"])}))
        for route in result.get("routes", []):
            via = [f"{g}_key" for g in route["guides"] if f"{g}_key" in frames]
            if len(via) >= 2:
                out["routes"].append({"label": route["cable"], "iri": None, "via": via})


def _elimco(graph: Any, session: Any, frames: set[str], out: dict[str, list[Any]]) -> None:
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


def _harnesses(graph: Any, session: Any, out: dict[str, list[Any]]) -> None:
    refs = graph.query(_HARNESSES).rows
    if not refs:
        return
    base = str(graph.query("SELECT ?c WHERE { ?c a ck:Cell } LIMIT 1").rows[0]["c"]).removesuffix("cell/this")
    posed = {row["node"]: row for row in graph.query(_NODE_POSES).rows}
    seen: set[str] = set()
    offset = 0.0  # harnesses laid out side by side, not on top of each other
    for ref in refs:
        if ref["h"] in seen:
            continue
        seen.add(ref["h"])
        result = to_jsonable(call(session, "harness_topology", {"harness": ref["h"], "view": "topology"}))
        if not result.get("success"):
            continue
        nodes = result["nodes"]
        index = {node["id"]: i for i, node in enumerate(nodes)}
        segments = [
            {
                "label": s["label"],
                "iri": base + s["id"],
                "from": index[s["from_node"]],
                "to": index[s["to_node"]],
                "length": s["length_m"],
                "diameter": s["diameter_m"],
                "wires": len(s["wires"]),
            }
            for s in result["segments"]
            if s["from_node"] in index and s["to_node"] in index
        ]
        stated = [posed.get(base + node["id"]) for node in nodes]
        if nodes and all(row is not None for row in stated):
            positions = [[float(r["x"]), float(r["y"]), float(r["z"])] for r in stated if r is not None]
            frame, coordinates = stated[0]["frame"] if stated[0] else None, "graph"
        else:
            planar = layout(len(nodes), [(s["from"], s["to"], s["length"]) for s in segments])
            positions, frame, coordinates = [[x + offset, y, 0.0] for x, y in planar], None, "layout"
            offset = max((p[0] for p in positions), default=offset) + _HARNESS_GAP
        out["harnesses"].append(
            {
                "label": result["harness"],
                "iri": ref["h"],
                "coordinates": coordinates,
                "frame": frame,
                "nodes": [
                    {
                        "label": node["label"],
                        "kind": node["kind"],
                        "iri": base + node["id"],
                        "connectors": node["connectors"],
                        "position": [round(v, 6) for v in position],
                    }
                    for node, position in zip(nodes, positions, strict=True)
                ],
                "segments": segments,
            }
        )


def profile_extras(
    graph: Any, session: Any, profile: str, frames: set[str], problems: list[str]
) -> dict[str, list[Any]]:
    """Points of interest, routes over frames and harness topologies of the cell's profile.

    A profile's services that fail on this cell leave their part out and say why in ``problems``.
    """
    out: dict[str, list[Any]] = {"points": [], "routes": [], "harnesses": []}
    steps = {"elvez": _elvez, "elimco": _elimco}
    try:
        if profile in steps:
            steps[profile](graph, session, frames, out)
        _harnesses(graph, session, out)
    except CadkgError as err:
        problems.append(f"{profile or 'cell'} details left out: {err}")
    return out
