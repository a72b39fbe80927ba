"""What an ELVEZ cell adds to the 3D workbench's scene: the key centre and key corner of every
guide of every jig and comb (``jig_info``, in the reference frame), the spots a taping
operation works at (a jig's taping spot of that number, else its guide of that number), and
each cable's route through the keys of its guides (``wh_routes``), read through the services
as a client would.
"""

from __future__ import annotations

from typing import Any

from cadkg.services.service import to_jsonable
from cadkg.services.session import Session
from cadkg.services.table import call
from cadkg.usecases.elvez.services import REFERENCE_NAMESPACE

__all__ = ["platform_scene"]

_TAPED = """
SELECT ?spot ?label ?guide ?index WHERE {
  ?op a ck:TapeOperation ; ck:atSpot ?spot . ?spot ck:label ?label ; ck:guideId ?guide .
  OPTIONAL { ?op ck:sequenceIndex ?index }
} ORDER BY ?index ?label ?guide"""
_ELEMENTS = "SELECT DISTINCT ?e ?label WHERE { ?e a ck:Element ; ck:label ?label } ORDER BY ?label"
_HARNESS_NUMBERS = "SELECT DISTINCT ?n WHERE { ?h a ck:Harness ; ck:harnessNumber ?n } ORDER BY ?n"


def _at(pose: dict[str, Any] | None) -> list[float] | None:
    if not pose:
        return None
    at = pose["position"]
    return [round(float(at[axis]), 9) for axis in "xyz"]


_Points = dict[str, list[float]]


def _guides(
    graph: Any, session: Session, frames: set[str], out: dict[str, list[Any]]
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


def platform_scene(graph: Any, session: Session, frames: set[str], out: dict[str, list[Any]]) -> None:
    """The guides' key points, the taping spots and each cable's route through its guides."""
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
