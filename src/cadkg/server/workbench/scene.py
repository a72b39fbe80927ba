"""The cell in 3D for the page's viewer, as JSON-ready data read from the served graph.

The viewer gets what ``cadkg ros`` publishes, so the picture and ``/tf_static`` agree: the
frame tree (:func:`~cadkg.services.frames.static_frames`: the manifest's frames, every
scene item, each component's original, corner and target, the profile's own frames) and the
meshes in their frames (:func:`~cadkg.services.frames.marker_specs`). To that it adds what
a click needs (each object's IRI, label and component), each item's box (drawn when its mesh
file is not at hand, as on a remote store), the wires' routing keypoints of the derived model,
and the profile's points of interest (:mod:`cadkg.server.workbench.scene_extras`).

Poses stay in their parent frames; the page composes them (three.js does that per frame), so
the server does no geometry. Meshes are listed once per distinct content: a cabinet's
thousands of items share a few hundred boxes, which the page draws instanced.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

import cadkg.registry as registry
from cadkg.confined import OutsideRootError, read_inside
from cadkg.errors import CadkgError
from cadkg.query.placements import Placements, placements
from cadkg.server.workbench.scene_extras import profile_extras
from cadkg.services.frames import marker_specs, static_frames
from cadkg.store import cell_profile

__all__ = ["cell_scene", "mesh_bytes"]

_ITEMS = """
SELECT DISTINCT ?item ?id ?minX ?minY ?minZ ?maxX ?maxY ?maxZ WHERE {
  ?item ck:cadId ?id .
  OPTIONAL { ?item ck:minX ?minX ; ck:minY ?minY ; ck:minZ ?minZ ;
                   ck:maxX ?maxX ; ck:maxY ?maxY ; ck:maxZ ?maxZ }
}"""
_COMPONENTS = "SELECT DISTINCT ?component ?label WHERE { ?component a ck:Component ; ck:label ?label }"
_COLOURS = """
SELECT ?thing ?colour ?label WHERE {
  ?thing ck:colour ?colour . OPTIONAL { ?thing ck:label|ck:wireNumber ?label }
}"""
_BOX = ("minX", "minY", "minZ", "maxX", "maxY", "maxZ")
_DIGITS = 6  # a micrometre: finer than any CAD file here states


def _round(values: Any) -> list[float]:
    return [round(float(v), _DIGITS) for v in values]


def _pose(pose: Any) -> dict[str, list[float]]:
    return {"t": _round(pose.position), "q": _round(pose.orientation)}


def mesh_bytes(files_dir: Path, rel: str) -> bytes | None:
    """The bytes of ``rel`` (a ``ck:meshUri``) inside ``files_dir``, or None when it is elsewhere or absent.

    Only a name ending in ``.stl`` is taken, opened inside the directory by
    :func:`cadkg.confined.open_inside`: no ``..``, no absolute path, no link at any step.
    """
    if not rel.lower().endswith(".stl"):
        return None
    try:
        return read_inside(files_dir, rel)
    except OutsideRootError:
        return None


class _Meshes:
    """Mesh files by content: one entry per distinct file, the first path that holds it."""

    def __init__(self, files_dir: Path) -> None:
        self.files_dir = files_dir
        self.entries: list[dict[str, Any]] = []
        self._by_digest: dict[str, int] = {}
        self._by_rel: dict[str, int | None] = {}

    def index(self, rel: str) -> int | None:
        if rel in self._by_rel:
            return self._by_rel[rel]
        data = mesh_bytes(self.files_dir, rel)
        found: int | None = None
        if data is not None:
            digest = hashlib.blake2b(data, digest_size=16).hexdigest()
            found = self._by_digest.get(digest)
            if found is None:
                found = self._by_digest[digest] = len(self.entries)
                self.entries.append({"path": rel, "bytes": len(data), "digest": digest})
        self._by_rel[rel] = found
        return found


def _mesh_rel(uri: str, root: Path) -> str | None:
    """A marker's ``file://`` URI back to its path relative to the (resolved) files directory."""
    path = Path(uri.removeprefix("file://"))
    try:
        return path.relative_to(root).as_posix()
    except ValueError:
        return None


def _frames_and_meshes(
    graph: Any, session: Any, profile: str, problems: list[str]
) -> tuple[list[Any], list[tuple[str, str, str]]]:
    """The frames, and (frame, label, mesh path) of every mesh: the scene items' as placed,
    then the profile's (the ELVEZ platform elements' model meshes)."""
    placed = placements(graph)
    model = session.model
    meshes = [(frame, frame, rel) for frame, rel in sorted(placed.meshes.items())]
    # The items' meshes are taken as placed above: the markers are asked for the profile's only.
    unmeshed = Placements(placed.frames, {})
    try:
        frames = static_frames(placed, model, profile, session)
        markers = marker_specs(unmeshed, model, graph.files_dir, profile, session)
    except CadkgError as err:  # as the ROS node does: the cell's frames without the profile's
        problems.append(f"{profile} frames left out: {err}")
        frames, markers = static_frames(placed, model, profile), []
    root = graph.files_dir.resolve()
    for marker in markers:
        rel = _mesh_rel(marker.mesh_uri, root) if marker.kind == "mesh" else None
        if rel is not None:
            meshes.append((marker.frame_id, marker.text or marker.frame_id, rel))
    return frames, meshes


def _items(graph: Any) -> dict[str, dict[str, Any]]:
    items: dict[str, dict[str, Any]] = {}
    for row in graph.query(_ITEMS).rows:
        entry = items.setdefault(row["id"], {"iri": row["item"], "box": None})
        if entry["box"] is None and row["minX"] is not None:
            entry["box"] = _round(row[key] for key in _BOX)
    return items


def _coloured(graph: Any, routes: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Each route with the ``ck:colour`` of its wire or cable (by IRI, else by label), as written
    (``BU``, ``GNYE``, ``sw/rt``): the page draws a wire in its colour."""
    by_iri: dict[str, str] = {}
    by_label: dict[str, str] = {}
    for row in graph.query(_COLOURS).rows:
        by_iri.setdefault(str(row["thing"]), str(row["colour"]))
        if row["label"] is not None:
            by_label.setdefault(str(row["label"]), str(row["colour"]))
    for route in routes:
        colour = by_iri.get(str(route.get("iri"))) or by_label.get(str(route["label"]))
        if colour:
            route["colour"] = colour
    return routes


def cell_scene(graph: Any, session: Any) -> dict[str, Any]:
    """The frames, objects, meshes, components, routes and points of interest of the cell.

    ``session`` is the services' :class:`~cadkg.services.session.Session` of ``graph``.

    Raises
    ------
    CadkgError
        When the graph cannot be read.
    """
    profile = cell_profile(graph)
    problems: list[str] = []
    frames, mesh_files = _frames_and_meshes(graph, session, profile, problems)
    frame_names = {f.child for f in frames}
    files_dir = graph.files_dir
    meshes = _Meshes(files_dir)
    items = _items(graph)

    objects: list[dict[str, Any]] = []
    by_frame: dict[str, int] = {}

    def add(frame: str, label: str, mesh: int | None) -> None:
        item = items.get(frame, {})
        if frame in by_frame:
            entry = objects[by_frame[frame]]
            entry["mesh"] = entry["mesh"] if entry["mesh"] is not None else mesh
            return
        by_frame[frame] = len(objects)
        objects.append(
            {
                "frame": frame,
                "label": label,
                "iri": item.get("iri"),
                "mesh": mesh,
                "box": item.get("box"),
                "component": None,
            }
        )

    missing_files = 0
    for frame, label, rel in mesh_files:
        mesh = meshes.index(rel)
        missing_files += mesh is None
        add(frame, label, mesh)
    for ident, item in sorted(items.items()):
        if ident in frame_names and item["box"] is not None:
            add(ident, ident, None)

    # A component's items as the derived model holds them (as the services answer).
    components: dict[str, dict[str, Any]] = {}
    model = session.model
    for row in graph.query(_COMPONENTS).rows:
        label = str(row["label"])
        geometry = model.components.get(label)
        if geometry is None or label in components:
            continue
        drawn = [by_frame[item] for item in geometry.items if item in by_frame]
        components[label] = {
            "label": label,
            "iri": row["component"],
            "frame": geometry.frame,
            "objects": drawn,
        }
    for number, entry in enumerate(sorted(components.values(), key=lambda c: c["label"])):
        for index in entry["objects"]:
            objects[index]["component"] = number
            objects[index]["label"] = entry["label"]

    routes = [
        {
            "label": str(step.wire),
            "iri": step.iri,
            "frame": model.frame,
            "performer": step.performer,
            # What group_connection_provider hands out for this wire: the page steps through the
            # robot's wires itself, so that looking at them moves no cursor of the served cell.
            "position": step.position,
            "origin": f"{step.origin.label}:{step.origin.pin}",
            "destination": f"{step.destination.label}:{step.destination.pin}",
            "points": [value for pose in step.keypoints for value in _round(pose.position)],
        }
        for step in model.steps
        if len(step.keypoints) >= 2
    ]
    if missing_files:
        problems.append(
            f"{missing_files} mesh file(s) are not in this store's files directory "
            "(a remote store has none): their items are drawn as boxes"
        )
    extras = profile_extras(graph, session, profile, frame_names, problems)
    return {
        "profile": profile or registry.DEFAULT_PROFILE,
        # By name: the same scene whatever order the store gave the frames in (the page
        # composes them by parent, in any order).
        "frames": [
            {"name": f.child, "parent": f.parent, **_pose(f.pose)}
            for f in sorted(frames, key=lambda f: f.child)
        ],
        "objects": objects,
        "meshes": meshes.entries,
        "components": sorted(components.values(), key=lambda c: c["label"]),
        "routes": _coloured(graph, routes + extras["routes"]),
        "points": extras["points"],
        "harnesses": extras["harnesses"],
        "problems": problems,
    }
