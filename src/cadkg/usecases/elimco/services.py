"""The ELIMCO services of D3.1 section 4.2 (profile ``elimco``), transport-free.

``load_files`` swaps the route-design files (and the cable list) of the served graph;
``get_pin_positions``, ``pin_frames``, ``get_cable_list`` and ``get_path_positions``
answer from :class:`~cadkg.usecases.elimco.bench.ElimcoModel`, built from the graph once per
session and dropped after a load. Conventions (frames, route direction, connector
distance) are in :mod:`cadkg.usecases.elimco.bench` and docs/elimco-services.md. Lengths and
positions are metres; an unknown cable gives ``success=False`` and a message.
"""

from __future__ import annotations

import contextlib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from cadkg.errors import CadkgError
from cadkg.geometry.poses import Pose
from cadkg.limited import read_limited
from cadkg.registry import reader_for, sniff_kind
from cadkg.services.display import Frame
from cadkg.services.service import Effect, Paths, Service, model_services
from cadkg.services.session import Session
from cadkg.usecase import Answer
from cadkg.usecases.elimco.bench import (
    CENTROID_FRAME,
    DRAWING_FRAME,
    ElimcoModel,
    consistency_problems,
    elimco_model,
    frame_id,
)
from cadkg.usecases.elimco.route_design import BenchPinSpec, RouteCable, RoutePathSpec

__all__ = [
    "ELIMCO_KINDS",
    "SERVICES",
    "BenchCable",
    "CableListResult",
    "LoadFilesResult",
    "NamedFrame",
    "PathPositionsResult",
    "PinFramesResult",
    "PinPosition",
    "PinPositionsResult",
    "bench_frames",
    "get_cable_list",
    "get_path_positions",
    "get_pin_positions",
    "load_files",
    "pin_frames",
]

ELIMCO_KINDS = ("elimco-cable-list", "pin-info", "cable-info", "path-info")
"""The input kinds ``load_files`` replaces."""
_MODEL = "elimco"


@dataclass(frozen=True)
class PinPosition:
    """A bench pin where the robot places it.

    ``connector_distance`` is how far (metres) it was moved from its connector's point
    towards the next pin of its route; ``double_distance`` is 0 for a simple pin.
    """

    name: str
    role: str
    pose: Pose
    is_double: bool
    double_distance: float
    connector_distance: float


@dataclass(frozen=True)
class PinPositionsResult(Answer):
    frame: str = ""
    centroid: Pose | None = None
    pins: tuple[PinPosition, ...] = ()


@dataclass(frozen=True)
class NamedFrame:
    """A frame to publish: ``pose`` of ``name`` in ``parent``."""

    name: str
    parent: str
    pose: Pose


@dataclass(frozen=True)
class PinFramesResult(Answer):
    frames: tuple[NamedFrame, ...] = ()


@dataclass(frozen=True)
class BenchCable:
    """A cable of the harness; ``path`` is the index of its route, -1 without one."""

    name: str
    initial_connector: str
    final_connector: str
    length: float
    path: int
    wires: tuple[str, ...]


@dataclass(frozen=True)
class CableListResult(Answer):
    cables: tuple[BenchCable, ...] = ()


@dataclass(frozen=True)
class PathPositionsResult(Answer):
    cable: str = ""
    path: int = -1
    frame: str = ""
    pins: tuple[str, ...] = ()
    poses: tuple[Pose, ...] = ()
    segment_lengths: tuple[float, ...] = ()
    total_length: float = 0.0
    cable_length: float = 0.0


@dataclass(frozen=True)
class LoadFilesResult(Answer):
    sources: tuple[str, ...] = ()


def _notes(model: ElimcoModel, *more: str) -> str:
    return "; ".join((*more, *model.problems))


def get_pin_positions(
    model: ElimcoModel, use_centroid: bool, pin_connector_distance: float = 0.0
) -> PinPositionsResult:
    """Every bench pin's pose, in the drawing frame or in the pins' centroid frame.

    ``pin_connector_distance`` (metres) > 0 moves every initial and final pin that far from
    its connector towards the next pin of its route; 0 (or less) moves each by its own
    ``connector_distance`` of pin_info.xml (none when it has none).
    """
    if not model.pins:
        return PinPositionsResult(False, "no bench pins in the graph: load a pin_info.xml")
    pins = []
    unmoved = []
    for name, pin in model.pins.items():
        pose, moved = model.pose(name, pin_connector_distance, in_centroid=use_centroid)
        wanted = pin_connector_distance if pin_connector_distance > 0 else pin.connector_distance or 0.0
        if wanted > 0 and moved == 0.0 and pin.role != "intermediate":
            unmoved.append(name)
        pins.append(PinPosition(name, pin.role, pose, pin.double, pin.double_distance or 0.0, moved))
    frame = CENTROID_FRAME if use_centroid else DRAWING_FRAME
    note = f"{len(pins)} pins in frame {frame}"
    extra = [f"on no route, so not moved from the connector: {', '.join(unmoved)}"] if unmoved else []
    return PinPositionsResult(True, _notes(model, note, *extra), frame, Pose(model.centroid), tuple(pins))


def pin_frames(model: ElimcoModel) -> PinFramesResult:
    """The frames to publish for checking the pins in RViz: centroid frame, one per pin, two per double pin.

    The centroid frame hangs in the drawing frame, unless the manifest places it (then
    the drawing frame hangs in it, so the tree keeps one parent per frame).
    """
    if not model.pins:
        return PinFramesResult(False, "no bench pins in the graph: load a pin_info.xml")
    cx, cy, cz = model.centroid
    frames: list[NamedFrame] = []
    if CENTROID_FRAME in model.placed_by_manifest:
        if DRAWING_FRAME not in model.placed_by_manifest:
            frames.append(NamedFrame(DRAWING_FRAME, CENTROID_FRAME, Pose((0.0 - cx, 0.0 - cy, 0.0 - cz))))
    else:
        frames.append(NamedFrame(CENTROID_FRAME, DRAWING_FRAME, Pose((cx, cy, cz))))
    for name, pin in model.pins.items():
        pose, _ = model.pose(name, None, in_centroid=True)
        own = frame_id(name)
        frames.append(NamedFrame(own, CENTROID_FRAME, pose))
        if pin.double and pin.double_distance:
            half = pin.double_distance / 2
            frames.append(NamedFrame(f"{own}_a", own, Pose((0.0, half, 0.0))))
            frames.append(NamedFrame(f"{own}_b", own, Pose((0.0, -half, 0.0))))
    return PinFramesResult(True, _notes(model, f"{len(frames)} frames"), tuple(frames))


def get_cable_list(model: ElimcoModel) -> CableListResult:
    """Every cable of the harness, in the order of their routes."""
    if not model.cables:
        return CableListResult(False, "no cables in the graph: load a cable_info.xml or a cable list")
    routes = {r.cable: r.index for r in model.routes.values()}
    cables = tuple(
        BenchCable(
            c.name,
            c.initial_connector,
            c.final_connector,
            c.length or 0.0,
            routes.get(c.name, -1),
            c.wires,
        )
        for c in model.cables.values()
    )
    return CableListResult(True, _notes(model, f"{len(cables)} cables"), cables)


def get_path_positions(model: ElimcoModel, cable: str) -> PathPositionsResult:
    """The pin poses along the route of ``cable`` (or of the path numbered ``cable``), in the centroid frame.

    The poses are those ``get_pin_positions(use_centroid=True)`` gives: end pins moved by
    their own connector distance.
    """
    route = model.route_of(cable.strip())
    if route is None:
        known = ", ".join(r.cable for r in model.routes.values()) or "none"
        return PathPositionsResult(False, f"no path of cable {cable!r}; cables with a path: {known}")
    missing = [p for p in route.pins if p not in model.pins]
    if missing:
        return PathPositionsResult(
            False, f"path {route.index}: no position for pin(s) {', '.join(missing)} (not in pin_info)"
        )
    poses = tuple(model.pose(p, None, in_centroid=True)[0] for p in route.pins)
    info = model.cables.get(route.cable)
    return PathPositionsResult(
        True,
        _notes(model, f"path {route.index}: {len(route.pins)} pins in frame {CENTROID_FRAME}"),
        route.cable,
        route.index,
        CENTROID_FRAME,
        route.pins,
        poses,
        route.segment_lengths,
        route.total_length or 0.0,
        (info.length or 0.0) if info is not None else 0.0,
    )


def load_files(session: Session, paths: Sequence[str] | str) -> LoadFilesResult:
    """Replace the ELIMCO sources of the served graph with the files in ``paths`` (a list, or
    text with the files comma separated).

    Each file replaces the loaded source of its kind (cable list, pin_info, cable_info,
    path_info), keeping that source's graph name, or joins the graph when no source of
    its kind is loaded. Every file is read and checked against the others (and against
    the sources it does not replace) before anything changes: a bad file leaves the
    previous data serving. Relative paths are taken from the working directory.
    """
    kg = session.kg
    if kg is None or getattr(kg, "read_only", True) or not hasattr(kg, "replace_source"):
        return LoadFilesResult(
            False,
            "the served graph cannot be changed (a store opened read-only, or a remote endpoint); "
            "serve the manifest, or a store opened for writing",
        )
    try:
        names = paths.split(",") if isinstance(paths, str) else paths
        files = [_expanded(p.strip()) for p in names if p.strip()]
    except CadkgError as err:
        return LoadFilesResult(False, f"nothing loaded: {err}")
    if not files:
        return LoadFilesResult(False, "no file given: paths is a comma-separated list of files")
    try:
        plan = _plan(kg, files)
        _check(session, plan)
        base = _base_iri(kg)
        # replace_source reads each file again: every one has just been read without error,
        # so only a file changed in between can fail now. The files go in as one change: all
        # of them or none, even when the process is killed meanwhile.
        with kg.change() if hasattr(kg, "change") else contextlib.nullcontext():
            for path, kind, rel, _ in plan:
                kg.replace_source(path, rel, base, kind)
    except CadkgError as err:
        return LoadFilesResult(False, f"nothing loaded: {err}")
    finally:
        session.forget(_MODEL)
    rels = tuple(rel for _, _, rel, _ in plan)
    return LoadFilesResult(True, f"loaded {len(plan)} file(s) into {', '.join(rels)}", rels)


def _expanded(text: str) -> Path:
    try:
        return Path(text).expanduser()
    except RuntimeError:
        raise CadkgError(f"{text}: no home directory for the user its '~' names") from None


def _plan(kg: Any, files: list[Path]) -> list[tuple[Path, str, str, list[object]]]:
    """(file, kind, graph's source path, records) for each file; raises on a file that cannot go in."""
    loaded: dict[str, list[str]] = {}
    for source in kg.sources():
        loaded.setdefault(str(source["kind"]), []).append(str(source["path"]))
    taken = {path for paths in loaded.values() for path in paths}
    plan: list[tuple[Path, str, str, list[object]]] = []
    for path in files:
        kind = sniff_kind(path)
        if kind not in ELIMCO_KINDS:
            raise CadkgError(f"{path}: a {kind} file, not one of {', '.join(ELIMCO_KINDS)}")
        if any(kind == k for _, k, _, _ in plan):
            raise CadkgError(f"{path}: a second {kind} file in one load")
        current = loaded.get(kind, [])
        if len(current) == 1:
            rel = current[0]
        else:
            same = [c for c in current if Path(c).name == path.name]
            if len(current) > 1 and len(same) != 1:
                raise CadkgError(f"{path}: {len(current)} {kind} sources are loaded ({', '.join(current)})")
            rel = same[0] if same else path.name
            if not same and rel in taken:
                raise CadkgError(f"{path}: the graph already has a source {rel!r} of another kind")
        plan.append((path, kind, rel, list(read_limited(path, reader_for(kind).read, path))))
    return plan


def _check(session: Session, plan: list[tuple[Path, str, str, list[object]]]) -> None:
    """Raise when the files with the sources they keep would leave a route unservable."""
    current = session.profile_model(_MODEL, elimco_model)
    records = {kind: recs for _, kind, _, recs in plan}
    if "pin-info" in records:
        pins = {r.name for r in records["pin-info"] if isinstance(r, BenchPinSpec)}
    else:
        pins = set(current.pins)
    cables: dict[str, tuple[str, str]] | None
    if "cable-info" in records:
        cables = {r.name: (r.initial, r.final) for r in records["cable-info"] if isinstance(r, RouteCable)}
    else:
        cables = {c.name: (c.initial_connector, c.final_connector) for c in current.cables.values()} or None
    if "path-info" in records:
        routes = [(r.index, r.cable, r.pins) for r in records["path-info"] if isinstance(r, RoutePathSpec)]
    else:
        routes = [(r.index, r.cable, r.pins) for r in current.routes.values()]
    problems = consistency_problems(pins, cables, routes)
    if problems:
        raise CadkgError("; ".join(problems))


def _base_iri(kg: Any) -> str:
    rows = kg.query("SELECT ?cell WHERE { ?cell a ck:Cell } LIMIT 1").rows
    if not rows:
        raise CadkgError("the graph has no cell; build it from a manifest first")
    return str(rows[0]["cell"]).removesuffix("cell/this")


def model_of(session: Session) -> ElimcoModel:
    """The ELIMCO model of a session, built once (again after load_files)."""
    return session.profile_model(_MODEL, elimco_model)


_service = model_services("elimco", model_of)

SERVICES: tuple[Service, ...] = (
    Service(
        "load_files",
        "replace the ELIMCO files (pin_info, cable_info, path_info, cable list) online, atomically",
        {"paths": Paths},
        lambda s, paths, client="default": load_files(s, paths),
        effect=Effect.LOADS,
        profile="elimco",
    ),
    _service(
        "get_pin_positions",
        "bench pin poses, in the drawing frame or the pins' centroid frame",
        {"use_centroid": bool, "pin_connector_distance": float},
        get_pin_positions,
        optional={"pin_connector_distance"},
    ),
    _service(
        "pin_frames",
        "the centroid frame and one frame per pin (two more per double pin), to publish",
        {},
        pin_frames,
    ),
    _service(
        "get_cable_list",
        "the cables of the harness: connectors, length, path, cores",
        {},
        get_cable_list,
    ),
    _service(
        "get_path_positions",
        "the pin poses along the route of a cable (or path index), in the centroid frame",
        {"cable": str},
        get_path_positions,
    ),
)


def bench_frames(session: Session) -> list[Frame]:
    """``pins_centroid`` and a frame per bench pin, as the ``pin_frames`` service gives them."""
    return [Frame(f.parent, f.name, f.pose) for f in pin_frames(model_of(session)).frames]
