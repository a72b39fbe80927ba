"""The derived cell model in a file, kept in an on-disk store so that reopening it skips the derivation.

Reading a store's source graphs back and deriving the geometry again takes seconds to
minutes for a large cabinet (7.8 s at 10k wires on disk); every ``cadkg call``, server
start and ROS node start would pay it. The file holds exactly the model the derivation
gave. Its structure is JSON; its numbers (a million at 10k wires) are one block of
little-endian doubles, base64 in the JSON, which reads back bit for bit and about ten
times faster than JSON numbers. Poses and vectors in the structure are offsets into that
block. The file is only a copy: one that does not read back cleanly (another format or
cadkg version, a damaged file) is ignored and the model derived again.
"""

from __future__ import annotations

import base64
import json
import sys
from array import array
from collections.abc import Sequence
from importlib.metadata import version
from typing import Any

from cadkg.geometry.poses import Pose, Vec3
from cadkg.plan.decision import Performer
from cadkg.usecases.iema.derive.cabinet import CadPin, CellModel, Cluster, ComponentGeometry, Rail, WireStep

# A kept model is read back only by the cadkg version that wrote it.
_VERSION = version("cadkg")

__all__ = ["dump_model", "load_model"]

_FORMAT = 2
_READ_ERRORS = (ValueError, TypeError, KeyError, IndexError, AttributeError, RecursionError)


class _Writer:
    def __init__(self) -> None:
        self.numbers = array("d")

    def put(self, values: Sequence[float] | None) -> int | None:
        if values is None:
            return None
        at = len(self.numbers)
        self.numbers.extend(values)
        return at

    def pose(self, pose: Pose | None) -> int | None:
        return None if pose is None else self.put((*pose.position, *pose.orientation))

    def pin(self, pin: CadPin) -> list[Any]:
        return [pin.label, pin.pin, self.pose(pin.screw), self.pose(pin.hole), pin.item, pin.iri]

    def block(self) -> str:
        numbers = self.numbers
        if sys.byteorder == "big":
            numbers = array("d", numbers)
            numbers.byteswap()
        return base64.b64encode(numbers.tobytes()).decode("ascii")


def dump_model(model: CellModel) -> bytes:
    """The model as bytes; :func:`load_model` gives an equal model back."""
    w = _Writer()
    where: dict[int, list[str]] = {}
    components = {}
    for label, g in model.components.items():
        for key, pin in g.pins.items():
            where[id(pin)] = [label, key]
        components[label] = [
            g.frame,
            list(g.items),
            w.pose(g.original),
            w.pose(g.corner),
            w.pose(g.target),
            w.put(g.dimensions),
            {key: w.pin(pin) for key, pin in g.pins.items()},
            g.terminal_block,
            w.pose(g.terminal_start),
            g.length,
            g.height,
            g.rail,
            g.rail_position,
        ]
    steps = [
        [
            step.position,
            step.source,
            step.wire,
            step.iri,
            # An end is one of its component's pins: written as where to find it.
            where.get(id(step.origin)) or w.pin(step.origin),
            where.get(id(step.destination)) or w.pin(step.destination),
            list(step.ducts),
            [w.pose(p) for p in step.keypoints],
            step.performer,
            list(step.terminations),
            step.path,
            step.reason,
        ]
        for step in model.steps
    ]
    clusters = {
        label: [[[c.axis, list(c.pins), [w.put(p) for p in c.points]] for c in side] for side in sides]
        for label, sides in model.clusters.items()
    }
    document = {
        "format": _FORMAT,
        "cadkg": _VERSION,
        "frame": model.frame,
        "approach_distance": model.approach_distance,
        "base": model.base,
        "performers": model.performers,
        "components": components,
        "rails": [[rail.label, w.pose(rail.start), list(rail.components)] for rail in model.rails],
        "steps": steps,
        "clusters": clusters,
        "numbers": w.block(),
    }
    return json.dumps(document, separators=(",", ":"), ensure_ascii=False).encode("utf-8")


def load_model(data: bytes) -> CellModel | None:
    """The model written by :func:`dump_model`, or None when ``data`` is anything else."""
    try:
        document = json.loads(data)
        if document["format"] != _FORMAT or document["cadkg"] != _VERSION:
            return None
        return _Reader(document).model()
    except _READ_ERRORS:
        return None


class _Reader:
    def __init__(self, document: dict[str, Any]) -> None:
        self.document = _typed(document, dict)
        raw = array("d")
        raw.frombytes(base64.b64decode(_typed(document["numbers"], str), validate=True))
        if sys.byteorder == "big":
            raw.byteswap()
        self.numbers: list[float] = raw.tolist()

    def floats(self, at: Any, count: int) -> list[float]:
        # An offset must be a plain index inside the block: -1 would read from its end.
        if type(at) is not int or at < 0 or at + count > len(self.numbers):
            raise ValueError("number offset outside the block")
        return self.numbers[at : at + count]

    def point(self, at: Any) -> Vec3:
        x, y, z = self.floats(at, 3)
        return (x, y, z)

    def vec(self, at: Any) -> Vec3 | None:
        return None if at is None else self.point(at)

    def pose(self, at: Any) -> Pose | None:
        if at is None:
            return None
        x, y, z, qx, qy, qz, qw = self.floats(at, 7)
        return Pose((x, y, z), (qx, qy, qz, qw))

    def required(self, at: Any) -> Pose:
        pose = self.pose(at)
        if pose is None:
            raise ValueError("expected a pose")
        return pose

    def pin(self, value: Any) -> CadPin:
        label, pin, screw, hole, item, iri = _typed(value, list)
        return CadPin(
            _typed(label, str), _typed(pin, str), self.pose(screw), self.pose(hole), _text(item), _text(iri)
        )

    def component(self, label: str, fields: Any) -> ComponentGeometry:
        frame, items, original, corner, target, dims, pins, block, start, length, height, rail, at = fields
        return ComponentGeometry(
            label=label,
            frame=_typed(frame, str),
            items=_strings(items),
            original=self.pose(original),
            corner=self.pose(corner),
            target=self.pose(target),
            dimensions=self.vec(dims),
            pins={_typed(key, str): self.pin(pin) for key, pin in _typed(pins, dict).items()},
            terminal_block=_typed(block, bool),
            terminal_start=self.pose(start),
            length=_number(length),
            height=_number(height),
            rail=_text(rail),
            rail_position=_number(at),
        )

    def cluster(self, value: Any) -> Cluster:
        axis, pins, points = _typed(value, list)
        return Cluster(_typed(axis, str), _strings(pins), tuple(self.point(p) for p in _typed(points, list)))

    def model(self) -> CellModel:
        doc = self.document
        components = {
            _typed(label, str): self.component(label, fields)
            for label, fields in _typed(doc["components"], dict).items()
        }

        def end(value: Any) -> CadPin:
            if len(_typed(value, list)) == 2:
                return components[value[0]].pins[value[1]]
            return self.pin(value)

        steps = []
        for fields in _typed(doc["steps"], list):
            position, source, wire, iri, origin, destination, ducts, keypoints, performer, ends, path, why = (
                fields
            )
            first, second = ends
            steps.append(
                WireStep(
                    position=_typed(position, int),
                    source=_typed(source, str),
                    wire=_typed(wire, str),
                    iri=_typed(iri, str),
                    origin=end(origin),
                    destination=end(destination),
                    ducts=_strings(ducts),
                    keypoints=tuple(self.required(p) for p in _typed(keypoints, list)),
                    performer=Performer(_typed(performer, str)),
                    terminations=(_text(first), _text(second)),
                    path=_typed(path, str),
                    reason=_typed(why, str),
                )
            )
        return CellModel(
            frame=_typed(doc["frame"], str),
            approach_distance=_typed(_number(doc["approach_distance"]), float),
            components=components,
            rails=[
                Rail(_typed(label, str), self.required(start), _strings(members))
                for label, start, members in _typed(doc["rails"], list)
            ],
            steps=steps,
            clusters={
                _typed(label, str): ([self.cluster(c) for c in across], [self.cluster(c) for c in down])
                for label, (across, down) in _typed(doc["clusters"], dict).items()
            },
            performers={_typed(k, str): _typed(v, str) for k, v in _typed(doc["performers"], dict).items()},
            base=_typed(doc["base"], str),
        )


def _typed(value: Any, kind: type) -> Any:
    if type(value) is not kind:
        raise TypeError(f"expected {kind.__name__}, found {type(value).__name__}")
    return value


def _text(value: Any) -> str | None:
    return None if value is None else _typed(value, str)


def _strings(values: Any) -> tuple[str, ...]:
    strings = tuple(_typed(values, list))
    if not all(type(s) is str for s in strings):
        raise TypeError("expected a list of strings")
    return strings


def _number(value: Any) -> float | None:
    if value is None:
        return None
    if type(value) is not float and type(value) is not int:
        raise TypeError(f"expected a number, found {type(value).__name__}")
    return float(value)
