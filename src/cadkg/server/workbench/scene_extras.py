"""What each profile adds to the 3D view: its points of interest, routes and harnesses.

- elvez: the key centre and key corner of every guide of every jig and comb (``jig_info``,
  in the reference frame), the spots a taping operation works at (a jig's taping spot of that
  number, else its guide of that number), and each cable's route through the keys of its
  guides (``wh_routes``);
- elimco: the bench pins (one frame each, as ``pin_frames`` gives them) and each cable's
  route over them;
- harnesses (vw, and any cell holding a ``ck:Harness`` with a topology): nodes and segments,
  at the poses the graph gives in the cell (a node's ``ck:hasPose``: ``coordinates`` is
  ``graph``), else at the harness file's own coordinates (``ck:nodeX/Y/Z``: ``file``), else
  laid out in a plane from the segment lengths
  (:func:`cadkg.server.workbench.harness_layout.layout`: ``layout``), and said so.

Each is read through the profile's services or the ontology's terms, as a client would.
"""

from __future__ import annotations

from typing import Any

from cadkg.errors import CadkgError
from cadkg.server.workbench.harness_layout import layout
from cadkg.services.service import to_jsonable
from cadkg.services.table import call
from cadkg.usecases.elvez.services import REFERENCE_NAMESPACE

__all__ = ["profile_extras"]

_HARNESS_GAP = 0.3  # metres between harnesses laid out in one plane
_TAPED = """
SELECT ?spot ?label ?guide ?index WHERE {
  ?op a ck:TapeOperation ; ck:atSpot ?spot . ?spot ck:label ?label ; ck:guideId ?guide .
  OPTIONAL { ?op ck:sequenceIndex ?index }
} ORDER BY ?index ?label ?guide"""
_ELEMENTS = "SELECT DISTINCT ?e ?label WHERE { ?e a ck:Element ; ck:label ?label } ORDER BY ?label"
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


def _at(pose: dict[str, Any] | None) -> list[float] | None:
    if not pose:
        return None
    at = pose["position"]
    return [round(float(at[axis]), 9) for axis in "xyz"]


_Points = dict[str, list[float]]


def _guides(
    graph: Any, session: Any, frames: set[str], out: dict[str, list[Any]]
) -> tuple[str, _Points, _Points]:
    """The key points of every guide of every jig and comb, in the reference frame; returns
    that frame and where a cable passes each guide or is taped at each spot (``J3.1``)."""
    reference = ""
    keys: _Points = {}
    spots: _Points = {}
    for row in graph.query(_ELEMENTS).rows:
        label = str(row["label"])
        jig = to_jsonable(call(session, f"{REFERENCE_NAMESPACE}.jig_info", {"jig": label}))
        # The services give poses in the cell's reference frame, which their message names.
        frame = str(jig["message"]).rsplit(" in ", 1)[-1]
        if not jig.get("success") or frame not in frames:
            continue  # a box, tool or station: no guides
        reference = frame
        for guide in jig["guides"]:
            for kind, key in (("key", "key_center_frame"), ("key-corner", "key_corner_frame")):
                at = _at(guide.get(key))
                if at is None:
                    continue
                text = f"{label} guide {guide['id']}" + (" key corner" if kind == "key-corner" else "")
                point = {"kind": kind, "frame": frame, "position": at, "label": text, "iri": row["e"]}
                out["points"].append(point)
                if kind == "key":
                    keys[f"{label}.{guide['id']}"] = at
        for spot in jig["taping_spots"]:
            at = _at(spot.get("center_frame"))
            if at is not None:
                spots[f"{label}.{spot['id']}"] = at
    return reference, keys, spots


def _elvez(graph: Any, session: Any, frames: set[str], out: dict[str, list[Any]]) -> None:
    reference, keys, spots = _guides(graph, session, frames, out)
    # A taping operation at a jig without that taping spot tapes at the guide of its number.
    spots = {**keys, **spots}
    taped: dict[str, tuple[str, list[str]]] = {}
    for row in graph.query(_TAPED).rows:
        name = f"{row['label']}.{row['guide']}"
        indices = taped.setdefault(name, (row["spot"], []))[1]
        if row["index"] is not None and str(row["index"]) not in indices:
            indices.append(str(row["index"]))
    for name, (iri, indices) in taped.items():
        if name in spots:
            text = f"{name}: taping" + (f" (operation {', '.join(indices)})" if indices else "")
            point = {
                "kind": "tape-spot",
                "frame": reference,
                "position": spots[name],
                "label": text,
                "iri": iri,
            }
            out["points"].append(point)
    for row in graph.query(_HARNESS_NUMBERS).rows:
        result = to_jsonable(call(session, "wh_routes", {"number": int(row["n"])}))
        for route in result.get("routes", []):
            via = [keys[g] for g in route["guides"] if g in keys]
            if len(via) >= 2:
                points = [v for at in via for v in at]
                out["routes"].append(
                    {"label": route["cable"], "iri": None, "frame": reference, "points": points}
                )


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
        elif nodes and all(node.get("x") is not None for node in nodes):
            # The harness file's own coordinates (a KBL's or VEC's node points), in metres.
            positions = [[float(node[axis]) for axis in "xyz"] for node in nodes]
            frame, coordinates = None, "file"
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


def _beside(harnesses: list[dict[str, Any]]) -> None:
    """Moves the laid-out harnesses beside those drawn at their files' coordinates (a
    vehicle's, metres from the origin), so one view shows all of them."""
    placed = [n["position"] for h in harnesses if h["coordinates"] == "file" for n in h["nodes"]]
    laid = [n["position"] for h in harnesses if h["coordinates"] == "layout" for n in h["nodes"]]
    if not placed or not laid:
        return
    shift = [
        max(p[0] for p in placed) + _HARNESS_GAP - min(p[0] for p in laid),
        min(p[1] for p in placed) - min(p[1] for p in laid),
        min(p[2] for p in placed),
    ]
    for position in laid:
        position[:] = [round(v + d, 6) for v, d in zip(position, shift, strict=True)]


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
        _beside(out["harnesses"])
    except CadkgError as err:
        problems.append(f"{profile or 'cell'} details left out: {err}")
    return out
