"""What a cell adds to the 3D view besides its frames and meshes: points of interest, routes and
harnesses.

- the profile's own, from its use case's ``scene`` hook (:class:`cadkg.usecase.UseCase`): an
  ELVEZ cell's guide keys, taping spots and cable routes, an ELIMCO cell's bench pins and
  routes over them;
- harnesses (vw, and any cell holding a ``ck:Harness`` with a topology): nodes and segments,
  at the poses the graph gives in the cell (a node's ``ck:hasPose``: ``coordinates`` is
  ``graph``), else at the harness file's own coordinates (``ck:nodeX/Y/Z``: ``file``), else
  laid out in a plane from the segment lengths
  (:func:`cadkg.server.workbench.harness_layout.layout`: ``layout``), and said so.

Each is read through the profile's services or the ontology's terms, as a client would.
"""

from __future__ import annotations

from typing import Any

import cadkg.registry as registry
from cadkg.errors import CadkgError
from cadkg.server.workbench.harness_layout import layout
from cadkg.services.service import to_jsonable
from cadkg.services.table import call

__all__ = ["profile_extras"]

_HARNESS_GAP = 0.3  # metres between harnesses laid out in one plane
_HARNESSES = """
SELECT DISTINCT ?h WHERE { ?h a ck:Harness . ?node ck:partOf ?h ; a ck:HarnessNode }"""
_NODE_POSES = """
SELECT ?node ?x ?y ?z ?frame WHERE {
  ?node a ck:HarnessNode ; ck:hasPose ?pose . ?pose ck:tx ?x ; ck:ty ?y ; ck:tz ?z .
  OPTIONAL { ?pose ck:parentFrame/ck:label ?frame }
}"""


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
    try:
        own = registry.use_case(profile).scene if profile else None
    except KeyError:  # a store of a use case not installed here: the cell's parts only
        own = None
    try:
        if own is not None:
            own(graph, session, frames, out)
        _harnesses(graph, session, out)
        _beside(out["harnesses"])
    except CadkgError as err:
        problems.append(f"{profile or 'cell'} details left out: {err}")
    return out
