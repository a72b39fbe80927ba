"""The cabinet's derived geometry: component poses, pin frames, rails, clusters, keypoints.

Conventions (docs/derived-geometry.md): every pose is expressed in the root frame
of the scene that placed the items (``cabinet`` in the examples: x right, y up, z
out of the mounting plate). A component's frame is its root item's frame. Its
box is the union of its items' boxes (scene geometry, else the model's
``[0, dims]`` box). The corner is the box's minimum corner; the target is the
front face's centre moved along the component's z by the approach distance and
turned a half turn about x (z into the plate), as the cell's software computes both.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field

import cadkg.usecases.iema.robot_scope as scope
from cadkg.geometry.poses import IDENTITY, Pose, Vec3, bounds, box_corners, closest_point_on_segment
from cadkg.plan.decision import Assignments, Performer
from cadkg.usecases.iema.derive.extract import CellInputs, ModelInfo, PinInfo, WireInfo
from cadkg.usecases.iema.derive.strip_items import items_along

__all__ = ["CadPin", "CellModel", "Cluster", "ComponentGeometry", "Rail", "WireStep", "derive_cell"]

_ROOT = "root"
_HALF_TURN_X = Pose((0.0, 0.0, 0.0), (1.0, 0.0, 0.0, 0.0))


@dataclass(frozen=True)
class CadPin:
    """A connection point: where its screw and hole are, in the cell's frame."""

    label: str
    pin: str
    screw: Pose | None
    hole: Pose | None
    item: str | None
    iri: str | None = None
    # Set by group_connection_provider: the component's target pose, as the node's cad_pins.
    component_pose: Pose | None = None

    @property
    def missing(self) -> bool:
        return self.screw is None and self.hole is None


@dataclass
class ComponentGeometry:
    label: str
    frame: str
    items: tuple[str, ...]
    original: Pose | None = None
    corner: Pose | None = None
    target: Pose | None = None
    dimensions: Vec3 | None = None
    pins: dict[str, CadPin] = field(default_factory=dict)
    terminal_block: bool = False
    terminal_start: Pose | None = None
    length: float | None = None
    height: float | None = None
    rail: str | None = None
    rail_position: float | None = None


@dataclass(frozen=True)
class Rail:
    label: str
    start: Pose
    components: tuple[str, ...]


@dataclass(frozen=True)
class Cluster:
    axis: str
    pins: tuple[str, ...]
    points: tuple[Vec3, ...]


@dataclass(frozen=True)
class WireStep:
    """One connection to make, in list order, with both ends resolved."""

    position: int
    source: str
    wire: str
    iri: str
    origin: CadPin
    destination: CadPin
    ducts: tuple[str, ...]
    keypoints: tuple[Pose, ...]
    performer: Performer
    terminations: tuple[str | None, str | None] = (None, None)
    # The duct path as the list writes it; why a rule gave the wire to a person (robot_scope).
    path: str = ""
    reason: str = ""

    @property
    def missing(self) -> tuple[str, ...]:
        return tuple(f"{p.label}:{p.pin}" for p in (self.origin, self.destination) if p.missing)


@dataclass
class CellModel:
    frame: str
    approach_distance: float
    components: dict[str, ComponentGeometry]
    rails: list[Rail]
    steps: list[WireStep]
    clusters: dict[str, tuple[list[Cluster], list[Cluster]]]
    performers: dict[str, str]
    base: str = ""

    _steps_of: dict[str, list[WireStep]] | None = None

    def steps_of(self, label: str) -> list[WireStep]:
        """The connections a component takes part in, in list order."""
        if self._steps_of is None:
            index: dict[str, list[WireStep]] = {}
            for step in self.steps:
                index.setdefault(step.origin.label, []).append(step)
                if step.destination.label != step.origin.label:
                    index.setdefault(step.destination.label, []).append(step)
            self._steps_of = index
        return self._steps_of.get(label, [])

    def ends_of(self, label: str) -> dict[str, tuple[str, str | None]]:
        """Pin → (wire number, termination) of the first wire ending on it."""
        ends: dict[str, tuple[str, str | None]] = {}
        for step in self.steps_of(label):
            for end, termination in zip((step.origin, step.destination), step.terminations, strict=True):
                if end.label == label:
                    ends.setdefault(end.pin, (step.wire, termination))
        return ends


def pin_key(info: PinInfo) -> str:
    return info.name if info.level is None else f"{info.name}:{info.level}"


class _Deriver:
    def __init__(self, cell: CellInputs) -> None:
        self.cell = cell
        self.item_pose: dict[str, Pose] = {}
        self.item_root: dict[str, str] = {}
        self.item_block: dict[str, str] = {}
        # Strips a terminal diagram describes take their items from the WRI table in order.
        items = cell.items_of
        along = {label: items_along(rows, items.get(label, ())) for label, rows in cell.diagrams.items()}
        self.blocks = {**along, **cell.blocks}
        for block, slots in self.blocks.items():
            for _, item, _ in slots:
                self.item_block[item] = block

    # -- frames ---------------------------------------------------------------
    def chain(self, name: str) -> tuple[str, Pose] | None:
        """The pose of frame ``name`` in the root frame of its scene (a frame that is no item)."""
        pose = IDENTITY
        seen = set()
        node = name
        while node in self.cell.frames and node not in seen:
            seen.add(node)
            parent, local = self.cell.frames[node]
            pose = local * pose
            if parent not in self.cell.frames or not self._is_item(parent):
                return parent, pose
            node = parent
        return None

    def _is_item(self, name: str) -> bool:
        return name in self.cell.item_model or name in self.cell.bboxes or name in self.item_block

    def box(self, item: str) -> tuple[Vec3, Vec3] | None:
        if item in self.cell.bboxes:
            return self.cell.bboxes[item]
        model = self.cell.models.get(self.cell.item_model.get(item, ""))
        if model is not None and model.dimensions is not None:
            return (0.0, 0.0, 0.0), model.dimensions
        return None

    # -- components -------------------------------------------------------------
    def component(self, label: str, items: list[str], default_frame: str) -> ComponentGeometry:
        block = self.blocks.get(label)
        if block:
            ordered = [item for _, item, _ in block]
            items = ordered + [i for i in items if i not in ordered]
        root = self._root_item(items) if not block else items[0]
        geometry = ComponentGeometry(label=label, frame=default_frame, items=tuple(items))
        placed = self.chain(root) if root else None
        if root is None or placed is None:
            return geometry
        frame, origin = placed
        geometry.frame, geometry.original = frame, origin
        self.item_pose[root] = origin
        root_model = self.cell.models.get(self.cell.item_model.get(root, ""))
        for item in items:
            if item == root:
                continue
            chained = self.chain(item)
            if chained is not None:
                self.item_pose[item] = chained[1]
            elif root_model is not None and self.cell.item_model.get(item) in root_model.children:
                self.item_pose[item] = origin * root_model.children[self.cell.item_model[item]]
            elif (mounted := self.cell.models.get(self.cell.item_model.get(item, ""))) is not None and (
                mounted.mounting is not None
            ):
                self.item_pose[item] = origin * mounted.mounting
        inverse = origin.inverse()
        corners: list[Vec3] = []
        for item in items:
            box = self.box(item)
            if box is None or item not in self.item_pose:
                continue
            local = inverse * self.item_pose[item]
            corners.extend(local.apply(c) for c in box_corners(*box))
        if not corners:
            return geometry
        lo, hi = bounds(corners)
        geometry.dimensions = (hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2])
        centre = ((lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, (lo[2] + hi[2]) / 2)
        # As the cell's software: the target is an approach pose over the front face's centre, its z
        # turned into the plate; the corner is the box's minimum corner.
        front = origin.at((centre[0], centre[1], hi[2] + self.cell.approach_distance))
        geometry.target = front * _HALF_TURN_X
        geometry.corner = origin.at(lo)
        # A model's own corner frame replaces the computed one, as the cell's software does.
        if root_model is not None and "corner" in root_model.items:
            geometry.corner = origin * root_model.items["corner"]
        if block:
            geometry.terminal_block = True
            first_box = self.box(root)
            if first_box is not None:
                geometry.terminal_start = geometry.corner = origin.at(first_box[0])
            widths = [self._size(item, 0) for item in items]
            heights = [self._size(item, 1) for item in items]
            geometry.length = sum(w for w in widths if w is not None)
            geometry.height = max((h for h in heights if h is not None), default=None)
        return geometry

    def _size(self, item: str, axis: int) -> float | None:
        box = self.box(item)
        return None if box is None else box[1][axis] - box[0][axis]

    def _root_item(self, items: list[str]) -> str | None:
        for item in items:
            model = self.cell.models.get(self.cell.item_model.get(item, ""))
            if model is not None and model.role == _ROOT:
                return item
        return items[0] if items else None

    # -- pins ---------------------------------------------------------------------
    def pins_of(self, geometry: ComponentGeometry, wired: Iterable[PinInfo]) -> None:
        for item in geometry.items:
            model = self.cell.models.get(self.cell.item_model.get(item, ""))
            if model is None:
                continue
            terminal = self._terminal_name(geometry.label, item)
            for couple in model.couples:
                name = couple if terminal is None else f"{terminal}:{couple}"
                if name not in geometry.pins:
                    geometry.pins[name] = self._pin(geometry.label, name, item, couple)
        # The items whose model places pins by name; most components have none at all.
        modelled = [
            (item, model)
            for item in geometry.items
            if (model := self.cell.models.get(self.cell.item_model.get(item, ""))) is not None
            and (model.screws or model.holes or model.points)
        ]
        for info in wired:
            key = pin_key(info)
            if key in geometry.pins:
                geometry.pins[key] = _with_iri(geometry.pins[key], info.iri)
                continue
            geometry.pins[key] = self._resolve(geometry, info, modelled)

    def _terminal_name(self, label: str, item: str) -> str | None:
        for _, slot_item, terminal in self.blocks.get(label, ()):
            if slot_item == item:
                return terminal or f"#{item}"
        return None

    def _pin(self, label: str, name: str, item: str, couple: str, iri: str | None = None) -> CadPin:
        model = self.cell.models.get(self.cell.item_model.get(item, ""))
        pose = self.item_pose.get(item)
        if model is None or pose is None:
            return CadPin(label, name, None, None, item, iri)
        screw, hole = model.frames(couple)
        return CadPin(
            label,
            name,
            pose * screw if screw is not None else None,
            pose * hole if hole is not None else None,
            item,
            iri,
        )

    def _resolve(
        self, geometry: ComponentGeometry, info: PinInfo, modelled: list[tuple[str, ModelInfo]]
    ) -> CadPin:
        """The frames of a pin a wire names, from its item's model; with the pin's IRI."""
        key, iri = pin_key(info), info.iri
        if geometry.terminal_block:
            for _, item, terminal in self.blocks.get(geometry.label, ()):
                if terminal == info.name:
                    model = self.cell.models.get(self.cell.item_model.get(item, ""))
                    couples = model.couples if model else []
                    couple = (
                        info.level if info.level is not None else (couples[0] if len(couples) == 1 else "")
                    )
                    return self._pin(geometry.label, key, item, couple, iri)
        if info.item is not None:
            return self._pin(geometry.label, key, info.item, info.level or info.name, iri)
        for item, model in modelled:
            if key in model.screws or key in model.holes:
                return self._pin(geometry.label, key, item, key, iri)
        for item, model in modelled:
            if key in model.points:
                return self._pin(geometry.label, key, item, key, iri)
        return CadPin(geometry.label, key, None, None, None, iri)


def _with_iri(pin: CadPin, iri: str) -> CadPin:
    return CadPin(pin.label, pin.pin, pin.screw, pin.hole, pin.item, iri)


def _clusters(pins: Iterable[CadPin], tolerance: float) -> tuple[list[Cluster], list[Cluster]]:
    points = [(p.pin, (p.hole or p.screw).position) for p in pins if (p.hole or p.screw) is not None]  # type: ignore[union-attr]

    def group(axis: int, along: int, name: str) -> list[Cluster]:
        ordered = sorted(points, key=lambda item: item[1][axis])
        groups: list[list[tuple[str, Vec3]]] = []
        for point in ordered:
            if groups and point[1][axis] - groups[-1][-1][1][axis] <= tolerance:
                groups[-1].append(point)
            else:
                groups.append([point])
        return [
            Cluster(name, tuple(p[0] for p in g), tuple(p[1] for p in g))
            for g in (sorted(g, key=lambda item: item[1][along]) for g in groups)
            if len(g) >= 2
        ]

    return group(1, 0, "horizontal"), group(0, 1, "vertical")


def _duct_axis(deriver: _Deriver, geometry: ComponentGeometry) -> tuple[Vec3, Vec3] | None:
    if geometry.original is None or not geometry.items:
        return None
    box = deriver.box(geometry.items[0])
    pose = deriver.item_pose.get(geometry.items[0])
    if box is None or pose is None:
        return None
    lo, hi = box
    sizes = [hi[i] - lo[i] for i in range(3)]
    axis = sizes.index(max(sizes))
    centre = [(lo[i] + hi[i]) / 2 for i in range(3)]
    a, b = list(centre), list(centre)
    a[axis], b[axis] = lo[axis], hi[axis]
    return pose.apply(a), pose.apply(b)


def _keypoints(start: CadPin, end: CadPin, axes: list[tuple[Vec3, Vec3]]) -> tuple[Pose, ...]:
    first = start.hole or start.screw
    last = end.hole or end.screw
    if first is None or last is None:
        return ()
    points: list[Vec3] = [first.position]
    for i, (a, b) in enumerate(axes):
        entry = closest_point_on_segment(a, b, points[-1])
        if i + 1 < len(axes):
            na, nb = axes[i + 1]
            towards = ((na[0] + nb[0]) / 2, (na[1] + nb[1]) / 2, (na[2] + nb[2]) / 2)
        else:
            towards = last.position
        exit_ = closest_point_on_segment(a, b, towards)
        points.append(entry)
        if sum((p - q) ** 2 for p, q in zip(entry, exit_, strict=True)) > 1e-6:
            points.append(exit_)
    points.append(last.position)
    return tuple(Pose(p) for p in points)


def derive_cell(cell: CellInputs) -> CellModel:
    """Compute the cabinet's derived geometry from the inputs read out of the graph."""
    deriver = _Deriver(cell)
    labels = dict.fromkeys([*cell.items_of, *deriver.blocks])
    default_frame = "cabinet"
    wired: dict[str, list[PinInfo]] = {}
    for info in cell.pins.values():
        wired.setdefault(info.label, []).append(info)
    components: dict[str, ComponentGeometry] = {}
    for label in labels:
        geometry = deriver.component(label, list(cell.items_of.get(label, [])), default_frame)
        components[label] = geometry
    for label in {*wired} - components.keys():
        components[label] = ComponentGeometry(label=label, frame=default_frame, items=())
    for geometry in components.values():
        deriver.pins_of(geometry, wired.get(geometry.label, ()))
    frames = [g.frame for g in components.values() if g.original is not None]
    frame = max(set(frames), key=frames.count) if frames else default_frame

    rails = _rails(deriver, components, cell.rail_pattern)
    clusters = {
        label: _clusters(g.pins.values(), cell.cluster_tolerance)
        for label, g in components.items()
        if g.pins and not re.match(cell.rail_pattern, label)
    }
    performers = scope.performers_of(cell.assignments, cell.base)
    assigned = scope.assignments_of(
        performers, cell.base, ((w.number, w.position) for w in cell.wires), components
    )
    cabinet = scope.CabinetRule(cell.robot_zones, cell.items_of)
    axes = {
        label: axis
        for label in cell.duct_labels
        if label in components and (axis := _duct_axis(deriver, components[label])) is not None
    }
    steps = [_step(cell, components, axes, (assigned, cabinet), wire) for wire in cell.wires]
    return CellModel(frame, cell.approach_distance, components, rails, steps, clusters, performers, cell.base)


def _rails(deriver: _Deriver, components: dict[str, ComponentGeometry], pattern: str) -> list[Rail]:
    regex = re.compile(pattern)
    rails = {label: g for label, g in components.items() if regex.match(label) and g.original is not None}
    rail_of_item = {g.items[0]: label for label, g in rails.items()}
    members: dict[str, list[tuple[float, str]]] = {label: [] for label in rails}
    for label, geometry in components.items():
        if label in rails or geometry.original is None or label in deriver.cell.duct_labels:
            continue
        rail = _ancestor_rail(deriver, geometry.items[0], rail_of_item) or _nearest_rail(
            deriver, geometry, rails
        )
        if rail is None:
            continue
        local = rails[rail].original.inverse() * geometry.original  # type: ignore[union-attr]
        geometry.rail, geometry.rail_position = rail, local.position[0]
        members[rail].append((local.position[0], label))
    ordered = sorted(rails.items(), key=lambda kv: (-kv[1].original.position[1], kv[0]))  # type: ignore[union-attr]
    return [
        Rail(label, g.original, tuple(name for _, name in sorted(members[label])))  # type: ignore[arg-type]
        for label, g in ordered
    ]


def _ancestor_rail(deriver: _Deriver, item: str, rail_of_item: dict[str, str]) -> str | None:
    node = item
    seen = set()
    while node in deriver.cell.frames and node not in seen:
        seen.add(node)
        node = deriver.cell.frames[node][0]
        if node in rail_of_item:
            return rail_of_item[node]
    return None


def _nearest_rail(
    deriver: _Deriver, geometry: ComponentGeometry, rails: dict[str, ComponentGeometry]
) -> str | None:
    # A component placed flat in the scene is on the rail whose box (grown by 2 cm
    # in height) holds its origin: DIN mounting puts the origin on the rail.
    for label, rail in rails.items():
        box = deriver.box(rail.items[0])
        if box is None or rail.original is None or geometry.original is None:
            continue
        x, y, _ = (rail.original.inverse() * geometry.original).position
        if box[0][0] - 1e-6 <= x <= box[1][0] + 1e-6 and box[0][1] - 0.02 <= y <= box[1][1] + 0.02:
            return label
    return None


def _step(
    cell: CellInputs,
    components: dict[str, ComponentGeometry],
    axes: dict[str, tuple[Vec3, Vec3]],
    decision_by: tuple[Assignments, scope.CabinetRule],
    wire: WireInfo,
) -> WireStep:
    ends = []
    for iri in (wire.origin, wire.destination):
        info = cell.pins[iri]
        ends.append(components[info.label].pins[pin_key(info)])
    origin, destination = ends
    facts = scope.WireFacts(
        wire.number, wire.position, (wire.zone, wire.destination_zone), (origin.label, destination.label)
    )
    performer, reason = scope.cell_decision(facts, *decision_by)
    return WireStep(
        position=wire.position,
        source=wire.source,
        wire=wire.number,
        iri=wire.iri,
        origin=origin,
        destination=destination,
        ducts=wire.ducts,
        keypoints=_keypoints(origin, destination, [axes[d] for d in wire.ducts if d in axes]),
        performer=performer,
        terminations=wire.terminations,
        path=wire.path,
        reason=reason,
    )
