"""Platform elements and their points of interest, in any frame of the cell.

Three files describe a platform (D3.1 section 4.3, Figure 24): the X3D assembly gives each
element's pose relative to its parent element, the element models give each model's points
of interest relative to the model's origin, and the WRI table joins the two (CAD ID → label
and model number). This module reads what they put in the graph and merges it into one frame
tree (Figure 25): cell corner → platform → element → ... → key frames, with the robot base
hanging from the cell corner as the manifest places it. Any frame's pose in any other frame is
then a walk up the tree.

Frame ids: a platform element's origin frame is its CAD ID (``ID000005``, as the scene names
it); a point of interest ``key`` of element ``G4`` is the frame ``G4_key``.
"""

from __future__ import annotations

import re
from collections import defaultdict
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from cadkg.errors import NotFound, QueryError
from cadkg.geometry.poses import IDENTITY, Pose, Vec3

if TYPE_CHECKING:
    from cadkg.graph import KnowledgeGraph

__all__ = [
    "ELEMENT_TYPES",
    "ROBOT_BASE",
    "FrameTree",
    "KeyFrame",
    "PlatformElement",
    "PlatformModel",
    "element_type",
    "platform_model",
]

ROBOT_BASE = "robot_base"
"""The frame the services answer in unless told otherwise (placed by the manifest)."""

ELEMENT_TYPES: dict[str, str] = {
    "G": "guide",
    "H": "guide",
    "CH": "connector_holder",
    "ATC": "atc_slot",
    "FS": "flat_surface",
}
"""Element type by the letters that start its label (``G4`` → guide); add a line for a new type."""

_PREFIX = re.compile(r"^[A-Za-z]+")
_POSE = "?pose ck:tx ?tx ; ck:ty ?ty ; ck:tz ?tz ; ck:qx ?qx ; ck:qy ?qy ; ck:qz ?qz ; ck:qw ?qw ."


def element_type(label: str) -> str:
    """The type of a platform element from its label's letter prefix; ``element`` when unknown.

    >>> element_type("G4"), element_type("ATC2"), element_type("X9")
    ('guide', 'atc_slot', 'element')
    """
    match = _PREFIX.match(label)
    return ELEMENT_TYPES.get(match.group(0).upper(), "element") if match else "element"


def _pose(row: Mapping[str, Any]) -> Pose:
    return Pose(
        (float(row["tx"]), float(row["ty"]), float(row["tz"])),
        (float(row["qx"]), float(row["qy"]), float(row["qz"]), float(row["qw"])),
    )


class FrameTree:
    """Frames with a parent and a pose in it; poses of any frame in any other of the same tree."""

    def __init__(self, parents: Mapping[str, tuple[str, Pose]]) -> None:
        self._parents = dict(parents)
        self._rooted: dict[str, tuple[str, Pose]] = {}

    def __contains__(self, name: object) -> bool:
        return name in self._parents or any(parent == name for parent, _ in self._parents.values())

    def parent(self, name: str) -> str | None:
        entry = self._parents.get(name)
        return entry[0] if entry else None

    def local(self, name: str) -> Pose | None:
        """The pose of ``name`` in its parent frame."""
        entry = self._parents.get(name)
        return entry[1] if entry else None

    def rooted(self, name: str) -> tuple[str, Pose]:
        """The root of ``name``'s tree and the pose of ``name`` in it.

        Raises
        ------
        NotFound
            When no frame is called ``name``.
        QueryError
            When the frames above ``name`` form a cycle.
        """
        if name in self._rooted:
            return self._rooted[name]
        if name not in self:
            raise NotFound(f"no frame {name!r}")
        chain: list[str] = []
        node = name
        while node in self._parents and node not in self._rooted:
            if node in chain:
                raise QueryError(f"the frames above {name!r} form a cycle: {' → '.join([*chain, node])}")
            chain.append(node)
            node = self._parents[node][0]
        root, pose = self._rooted.get(node, (node, IDENTITY))
        for child in reversed(chain):
            pose = pose * self._parents[child][1]
            self._rooted[child] = (root, pose)
        return self._rooted.get(name, (name, IDENTITY))

    def pose(self, frame: str, reference: str) -> Pose:
        """The pose of ``frame`` expressed in ``reference``.

        Raises
        ------
        NotFound
            When either frame is unknown.
        QueryError
            When the two frames are not in one tree (nothing places one relative to the other).
        """
        root, pose = self.rooted(frame)
        reference_root, reference_pose = self.rooted(reference)
        if root != reference_root:
            raise QueryError(
                f"frame {frame!r} (under {root!r}) and frame {reference!r} (under {reference_root!r}) "
                "are not connected; place one tree in the other with a [[frame]] of the manifest"
            )
        return reference_pose.inverse() * pose

    def transforms(self) -> Iterator[tuple[str, str, Pose]]:
        """Every ``(parent, child, pose of child in parent)``, as /tf_static would publish them."""
        for child, (parent, pose) in self._parents.items():
            yield parent, child, pose


@dataclass(frozen=True)
class KeyFrame:
    """A point of interest of an element: frame id and pose in the element's origin frame."""

    name: str
    frame: str
    local: Pose


@dataclass(frozen=True)
class PlatformElement:
    """A labelled element of a platform, as the WRI, the scene and its model describe it."""

    label: str
    cad_id: str
    kind: str
    model: str | None
    platform: str
    parent: str
    dimensions: Vec3 | None = None
    keyframes: Mapping[str, KeyFrame] = field(default_factory=dict)
    key_length: float | None = None
    key_gap: float | None = None
    key_height: float | None = None
    mesh: str | None = None

    @property
    def frame(self) -> str:
        """The element's origin frame: its CAD ID, as the scene names it."""
        return self.cad_id


@dataclass
class PlatformModel:
    """Every platform element with its points of interest, and the frame tree joining them."""

    tree: FrameTree
    elements: dict[str, PlatformElement]
    robot_base: str = ROBOT_BASE

    def pose(self, frame: str, reference: str | None = None) -> Pose:
        """The pose of ``frame`` in ``reference`` (the robot base when None); see FrameTree.pose."""
        return self.tree.pose(frame, reference or self.robot_base)

    def of_kind(self, kind: str) -> list[PlatformElement]:
        return [e for e in self.elements.values() if e.kind == kind]


@dataclass
class _Model:
    dimensions: Vec3 | None = None
    key: tuple[float, float, float] | None = None
    mesh: str | None = None
    frames: dict[str, Pose] = field(default_factory=dict)


def _frames(kg: KnowledgeGraph) -> dict[str, tuple[str, Pose]]:
    found: dict[str, set[tuple[str, Pose]]] = defaultdict(set)
    for row in kg.query(
        f"""SELECT DISTINCT ?name ?parent ?tx ?ty ?tz ?qx ?qy ?qz ?qw WHERE {{
              ?f a ck:Frame ; ck:label ?name ; ck:hasPose ?pose .
              ?pose ck:parentFrame/ck:label ?parent . {_POSE} }}"""
    ):
        found[row["name"]].add((row["parent"], _pose(row)))
    doubled = sorted(name for name, entries in found.items() if len(entries) > 1)
    if doubled:
        raise QueryError(
            f"frame {doubled[0]!r} is placed more than once"
            + (f" (and {len(doubled) - 1} more frames)" if len(doubled) > 1 else "")
            + ": CAD IDs and frame names must be unique across the cell's scenes and manifest"
        )
    return {name: next(iter(entries)) for name, entries in found.items()}


def _models(kg: KnowledgeGraph) -> dict[str, _Model]:
    models: dict[str, _Model] = defaultdict(_Model)
    for row in kg.query(
        """SELECT DISTINCT ?code ?x ?y ?z ?length ?gap ?height ?mesh WHERE { ?m ck:commercialCode ?code .
             OPTIONAL { ?m ck:xDim ?x ; ck:yDim ?y ; ck:zDim ?z }
             OPTIONAL { ?m ck:keyLength ?length ; ck:keyGap ?gap ; ck:keyHeight ?height }
             OPTIONAL { ?m ck:hasMesh/ck:meshUri ?mesh } }"""
    ):
        model = models[row["code"]]
        if row["x"] is not None:
            model.dimensions = (float(row["x"]), float(row["y"]), float(row["z"]))
        if row["length"] is not None:
            model.key = (float(row["length"]), float(row["gap"]), float(row["height"]))
        model.mesh = model.mesh or row["mesh"]
    for row in kg.query(
        f"""SELECT DISTINCT ?code ?name ?tx ?ty ?tz ?qx ?qy ?qz ?qw WHERE {{
              ?m ck:commercialCode ?code ; ck:definesKeypoint ?k . ?k ck:label ?name ; ck:hasPose ?pose .
              {_POSE} }}"""
    ):
        models[row["code"]].frames[row["name"]] = _pose(row)
    return dict(models)


def platform_model(kg: KnowledgeGraph, robot_base: str = ROBOT_BASE) -> PlatformModel:
    """Merge the scenes, element models and WRI tables in the graph into a :class:`PlatformModel`.

    Only labels whose CAD item has a frame in the graph (a scene placed it) are elements.

    Raises
    ------
    QueryError
        When a frame has two different poses (CAD IDs repeated across platform scenes), or a
        point-of-interest frame id clashes with another frame.
    """
    parents = _frames(kg)
    models = _models(kg)
    items: dict[str, tuple[int, str, str | None]] = {}
    for row in kg.query(
        """SELECT DISTINCT ?label ?id ?code ?line WHERE { ?c ck:label ?label ; ck:hasItem ?item .
             ?item ck:cadId ?id . OPTIONAL { ?item ck:instanceOf/ck:commercialCode ?code }
             OPTIONAL { ?item ck:sourceLine ?line } }"""
    ):
        if row["id"] not in parents:
            continue
        entry = (int(row["line"]) if row["line"] is not None else 1 << 30, row["id"], row["code"])
        # A label drawn as several items is placed by its first item in the WRI table.
        if row["label"] not in items or entry < items[row["label"]]:
            items[row["label"]] = entry
    element_frames = {cad_id for _, cad_id, _ in items.values()}
    elements: dict[str, PlatformElement] = {}
    for label, (_, cad_id, code) in sorted(items.items()):
        parent = parents[cad_id][0]
        platform = parent
        seen = {cad_id}
        while platform in element_frames and platform in parents and platform not in seen:
            seen.add(platform)
            platform = parents[platform][0]
        model = models.get(code or "", _Model())
        keyframes: dict[str, KeyFrame] = {}
        for name, local in model.frames.items():
            frame = f"{label}_{name}"
            if frame in parents:
                raise QueryError(
                    f"point of interest {name!r} of {label} would be frame {frame!r}, which already exists"
                )
            parents[frame] = (cad_id, local)
            keyframes[name] = KeyFrame(name, frame, local)
        elements[label] = PlatformElement(
            label=label,
            cad_id=cad_id,
            kind=element_type(label),
            model=code,
            platform=platform,
            parent=parent,
            dimensions=model.dimensions,
            keyframes=keyframes,
            key_length=model.key[0] if model.key else None,
            key_gap=model.key[1] if model.key else None,
            key_height=model.key[2] if model.key else None,
            mesh=model.mesh,
        )
    return PlatformModel(FrameTree(parents), elements, robot_base)
