"""What the KBL and VEC readers share beyond the records: the variants a thing is in, and routes.

A thing's modules are a set of module idents (in the variants choosing one of them) or None
(in every variant); :func:`union` joins them the way derived things need: a connector is in
wherever a wire ending in it is, a segment wherever a routing through it is, a node wherever a
segment at it or a connector on it is.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable, Mapping, Sequence

__all__ = ["Modules", "as_tuple", "topology_modules", "union", "walk"]

Modules = frozenset[str] | None
"""Module idents, or None for every variant."""


def union(values: Iterable[Modules]) -> Modules:
    """The variants any of ``values`` is in (None, every variant, absorbs)."""
    found: set[str] = set()
    for value in values:
        if value is None:
            return None
        found |= value
    return frozenset(found)


def as_tuple(modules: Modules) -> tuple[str, ...]:
    """The record's ``modules``: sorted idents, or () for every variant (or for none known)."""
    return tuple(sorted(modules)) if modules else ()


def topology_modules(
    segment_nodes: Mapping[str, tuple[str, str]],
    carriers: Iterable[tuple[Modules, Iterable[str]]],
    on_nodes: Mapping[str, Iterable[Modules]],
) -> tuple[dict[str, Modules], dict[str, Modules]]:
    """The modules of each segment (those of the routings, fixings and protections ``carriers``
    put on it) and each node (those of its segments and of the things ``on_nodes``); a segment or
    node nothing is on is in every variant."""
    on_segment: dict[str, list[Modules]] = defaultdict(list)
    for modules, segments in carriers:
        for segment in segments:
            on_segment[segment].append(modules)
    segments = {s: union(on_segment[s]) if s in on_segment else None for s in segment_nodes}
    at_node: dict[str, list[Modules]] = defaultdict(list)
    for segment, (start, end) in segment_nodes.items():
        at_node[start].append(segments[segment])
        at_node[end].append(segments[segment])
    for node, things in on_nodes.items():
        at_node[node].extend(things)
    nodes = {n: union(values) for n, values in at_node.items()}
    return segments, nodes


def walk(
    route: Sequence[str],
    segment_nodes: Mapping[str, tuple[str, str]],
    first: Iterable[str],
    *,
    reorder: bool = False,
) -> tuple[tuple[str, ...], int | None]:
    """The route as a walk from the wire's first end, and the index of the first segment that
    does not continue the walk (None when the whole route is a walk).

    ``first`` are the nodes the wire's first end may sit at. A route written from the other end
    is reversed; one whose every step continues is kept in its order otherwise. A segment may
    come again (a path through a loop and back). With ``reorder``, segments listed in no walk's
    order are put in one, when exactly one way leads on from the first end at every step.
    """
    if not route:
        return (), None
    starts = list(dict.fromkeys(segment_nodes[route[0]]))
    best: tuple[tuple[str, ...], int | None] | None = None
    first_nodes = set(first)
    for candidate in (tuple(route), tuple(reversed(route))):
        for start in dict.fromkeys(segment_nodes[candidate[0]]):
            broken = _break(candidate, segment_nodes, start)
            if broken is None and start in first_nodes:
                return candidate, None
            if broken is None and best is None:
                best = (candidate, None)
    if best is not None:
        return best
    for start in first_nodes if reorder else ():
        ordered = _greedy(route, segment_nodes, start)
        if ordered is not None:
            return ordered, None
    # Neither end starts a walk: the break is where the walk that goes further stops.
    return tuple(route), max(_break(tuple(route), segment_nodes, start) or 0 for start in starts)


def _break(route: Sequence[str], segment_nodes: Mapping[str, tuple[str, str]], start: str) -> int | None:
    at = start
    for index, segment in enumerate(route):
        a, b = segment_nodes[segment]
        if at == a:
            at = b
        elif at == b:
            at = a
        else:
            return index
    return None


def _greedy(
    route: Sequence[str], segment_nodes: Mapping[str, tuple[str, str]], start: str
) -> tuple[str, ...] | None:
    left = list(route)
    ordered: list[str] = []
    at = start
    while left:
        step = {s for s in left if at in segment_nodes[s]}
        if len(step) != 1:
            return None
        (segment,) = step
        left.remove(segment)
        ordered.append(segment)
        a, b = segment_nodes[segment]
        at = b if at == a else a
    return tuple(ordered)
