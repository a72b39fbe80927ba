"""Matching the things of two revisions by what identifies them, and comparing each pair.

Never by IRI: IRIs are minted from file positions and XML ids, which another export renumbers.
Things are matched by their kind's key first, then by each ``match`` alternative in turn where
it is unique on both sides; what is left is added or removed.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass
from typing import Any

from cadkg.changes.changeset import Change, ChangeSet
from cadkg.changes.kinds import ThingKind, kinds_for
from cadkg.changes.things import Thing, cell_profiles, read_things
from cadkg.geometry.poses import Pose
from cadkg.loading import paused_gc

__all__ = ["Tolerances", "diff_graphs", "diff_things", "pair_things", "profiles_of"]


@dataclass(frozen=True)
class Tolerances:
    """How far a thing may move (metres) or turn (degrees) and still be where it was."""

    move: float = 0.001
    turn: float = 0.5


def profiles_of(graph: Any) -> list[str]:
    """The use-case profiles of the cells a graph holds."""
    return sorted(set(cell_profiles(graph)))


def diff_graphs(
    old: Any,
    new: Any,
    *,
    tolerances: Tolerances = Tolerances(),
    names: tuple[str, str] = ("", ""),
    kinds: Iterable[ThingKind] | None = None,
) -> ChangeSet:
    """What changed from graph ``old`` to graph ``new``, with the kinds of both cells' use cases.

    The cyclic garbage collector is paused for the comparison (as for a build,
    :func:`cadkg.loading.paused_gc`), and only here: the things read make no cycles, and every
    full collection their allocations trigger walks every object of the process, which after
    building two manifests in it (``cadkg diff OLD.toml NEW.toml``, the benchmark) is millions
    (a quarter more CPU without the pause, docs/changes.md). The change feed, which reads a
    graph in a served store's thread, never pauses it.

    Raises
    ------
    QueryError
        When a kind's query fails on either graph.
    """
    cells = cell_profiles(old), cell_profiles(new)
    if kinds is None:
        kinds = kinds_for(sorted({*cells[0], *cells[1]}))
    changes = ChangeSet(*names)
    with paused_gc():
        for kind in kinds:
            before, after = read_things(old, kind, cells[0]), read_things(new, kind, cells[1])
            for change in diff_things(kind, before, after, tolerances):
                changes.of(change)
    return changes


def _sig(thing: Thing) -> str:
    return repr(sorted(thing.attributes.items(), key=lambda item: item[0]))


def _pair_by(
    names: tuple[str, ...], old: list[Thing], new: list[Thing], *, unique: bool
) -> list[tuple[Thing, Thing]]:
    """Pairs of things with equal values of ``names``; with ``unique``, only where one thing on
    each side has them."""
    by_old: dict[Any, list[Thing]] = defaultdict(list)
    by_new: dict[Any, list[Thing]] = defaultdict(list)
    for bucket, things in ((by_old, old), (by_new, new)):
        for thing in things:
            key = thing.key(names)
            if key is not None:
                bucket[key].append(thing)
    pairs: list[tuple[Thing, Thing]] = []
    for key, olds in by_old.items():
        news = by_new.get(key)
        if not news or (unique and (len(olds) > 1 or len(news) > 1)):
            continue
        if len(olds) == 1 and len(news) == 1:
            pairs.append((olds[0], news[0]))
            continue
        # Several things under one key (two wires 0V between the same terminals): the alike first.
        olds, news = sorted(olds, key=_sig), sorted(news, key=_sig)
        pairs.extend(zip(olds, news, strict=False))
    return pairs


def pair_things(
    kind: ThingKind, old: list[Thing], new: list[Thing]
) -> tuple[list[tuple[Thing, Thing]], list[Thing], list[Thing]]:
    """The things of two revisions that are the same thing (by the kind's key, then by each
    ``match`` alternative where it is unique on both sides), and those left over in each."""
    matched: list[tuple[Thing, Thing]] = []
    left_old, left_new = list(old), list(new)
    for number, names in enumerate((kind.key, *kind.match)):
        pairs = _pair_by(names, left_old, left_new, unique=number > 0)
        matched_old = {id(a) for a, _ in pairs}
        matched_new = {id(b) for _, b in pairs}
        left_old = [t for t in left_old if id(t) not in matched_old]
        left_new = [t for t in left_new if id(t) not in matched_new]
        matched.extend(pairs)
    return matched, left_old, left_new


def diff_things(kind: ThingKind, old: list[Thing], new: list[Thing], tolerances: Tolerances) -> list[Change]:
    """The changes of one kind: things matched, compared, and the rest added or removed."""
    pairs, left_old, left_new = pair_things(kind, old, new)
    changes = [change for a, b in pairs if (change := _compare(a, b, tolerances)) is not None]
    changes.extend(Change("removed", kind.name, t.id, old_iri=t.iri) for t in left_old)
    changes.extend(Change("added", kind.name, t.id, new_iri=t.iri) for t in left_new)
    return sorted(changes, key=_order)


def _order(change: Change) -> tuple[str, str]:
    return (change.change, change.id)


def _compare(a: Thing, b: Thing, tolerances: Tolerances) -> Change | None:
    if a.attributes == b.attributes and a.pose == b.pose:
        return None  # most things of a revision: nothing to work out
    attributes: dict[str, tuple[Any, Any]] = {}
    for name in sorted({*a.attributes, *b.attributes}):
        before, after = a.attributes.get(name), b.attributes.get(name)
        if before != after:
            attributes[name] = (_plain(before), _plain(after))
    offset = _moved(a.pose, b.pose, tolerances, attributes)
    if not attributes:
        return None
    return Change("changed", a.kind, b.id, a.iri, b.iri, attributes, offset)


def _plain(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value


def _round(values: Iterable[float]) -> list[float]:
    return [round(v, 6) + 0.0 for v in values]


def _moved(
    a: Pose | None, b: Pose | None, tolerances: Tolerances, attributes: dict[str, tuple[Any, Any]]
) -> dict[str, Any] | None:
    """Record a move or turn beyond the tolerances in ``attributes``; give its offset."""
    if a is None or b is None:
        if a is not None or b is not None:
            attributes["position"] = (_position(a), _position(b))
        return None
    translation = [q - p for p, q in zip(a.position, b.position, strict=True)]
    distance = math.sqrt(sum(d * d for d in translation))
    dot = abs(sum(p * q for p, q in zip(a.orientation, b.orientation, strict=True)))
    angle = math.degrees(2 * math.acos(min(1.0, dot)))
    if distance <= tolerances.move and angle <= tolerances.turn:
        return None
    if distance > tolerances.move:
        attributes["position"] = (_round(a.position), _round(b.position))
    if angle > tolerances.turn:
        attributes["orientation"] = (_round(a.orientation), _round(b.orientation))
    return {
        "translation": _round(translation),
        "distance": round(distance, 6),
        "rotation_deg": round(angle, 3),
    }


def _position(pose: Pose | None) -> list[float] | None:
    return None if pose is None else _round(pose.position)
