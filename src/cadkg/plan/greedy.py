"""The greedy order (docs/plan.md, In which order): people's tasks as soon as they are ready;
else a robot's ready task that keeps the tool in hand (or needs none), else one of the tool with
most ready tasks; among those the one starting nearest the previous task's end, ties to the
files' order.

The robot's tasks are kept in one group per first tool, each with its start positions in one
array and a mask of the ready ones, so finding the nearest is one pass over the group with no
copying, and the ready count of each group is kept as tasks become ready and are done.
"""

from __future__ import annotations

import math
from collections import defaultdict

import numpy as np

from cadkg.geometry.poses import Vec3
from cadkg.plan.decision import Decision, Performer
from cadkg.plan.tasks import Task

__all__ = ["PERSON", "greedy_order"]

_CELL = 0.1  # m: the side of a square of the grid of ready starts
_RINGS = 6  # rings of squares looked at before every ready task is
PERSON = "a person's task, placed as soon as what comes before it is done"


class _Group:
    """The robot's tasks whose first tool is one tool (or none), in the files' order.

    The ready ones with a known start are also filed in a grid of ``_CELL`` squares (x, y), so
    the nearest is found by looking at the squares around a point, ring by ring, until no
    farther ring can hold a nearer start; past ``_RINGS`` rings every ready task is looked at.
    """

    def __init__(self, members: list[int], starts: np.ndarray) -> None:
        self.members = members
        self.starts = starts[np.array(members, dtype=np.int64)]
        self.known = ~np.isnan(self.starts).any(axis=1)
        self.points: list[list[float]] = self.starts.tolist()
        self.cells = [
            (math.floor(x / _CELL), math.floor(y / _CELL)) if known else None
            for (x, y, _), known in zip(self.points, self.known.tolist(), strict=True)
        ]
        self.grid: dict[tuple[int, int], set[int]] = defaultdict(set)
        # One byte a task, set and read as plain ints; numpy sees the same memory when it scans all.
        self.ready = bytearray(len(members))
        self.count = 0
        self.located = 0  # ready tasks with a known start

    def set_ready(self, k: int, ready: bool) -> None:
        self.ready[k] = ready
        self.count += 1 if ready else -1
        cell = self.cells[k]
        if cell is not None:
            (self.grid[cell].add if ready else self.grid[cell].discard)(k)
            self.located += 1 if ready else -1

    def nearest(self, here: Vec3 | None) -> tuple[float, int]:
        """(squared distance, task) of the ready task starting nearest ``here``; the first ready
        one, at infinity, when no distance is known."""
        if here is None or not self.located:
            return math.inf, self.members[self.ready.index(1)]
        hx, hy, hz = here
        cx, cy = math.floor(hx / _CELL), math.floor(hy / _CELL)
        grid, points = self.grid, self.points
        best, chosen = math.inf, -1
        # Plain floats: a ring holds a handful of starts, too few for numpy to pay.
        for ring, offsets in enumerate(_OFFSETS):
            for dx, dy in offsets:
                for k in grid.get((cx + dx, cy + dy), ()):
                    x, y, z = points[k]
                    d = (x - hx) * (x - hx) + (y - hy) * (y - hy) + (z - hz) * (z - hz)
                    if d < best or (d == best and k < chosen):
                        best, chosen = d, k
            # Every start of a farther ring is at least ``ring`` squares away.
            if chosen >= 0 and best < (ring * _CELL) ** 2:
                return best, self.members[chosen]
        gap = self.starts - np.array(here)
        squared = np.einsum("ij,ij->i", gap, gap)
        squared[~(np.frombuffer(self.ready, dtype=np.uint8).astype(bool) & self.known)] = np.inf
        k = int(np.argmin(squared))
        return float(squared[k]), self.members[k]


def _ring(ring: int) -> list[tuple[int, int]]:
    """The offsets of the grid squares at Chebyshev distance ``ring`` from a square."""
    if ring == 0:
        return [(0, 0)]
    side = range(-ring, ring + 1)
    return (
        [(d, -ring) for d in side]
        + [(d, ring) for d in side]
        + [(-ring, d) for d in side[1:-1]]
        + [(ring, d) for d in side[1:-1]]
    )


_OFFSETS = [_ring(ring) for ring in range(_RINGS)]


def greedy_order(
    tasks: list[Task],
    decisions: dict[str, Decision],
    after: list[list[int]],
    waiting: np.ndarray,
    then: dict[int, tuple[int, str]],
) -> list[tuple[int, str]]:
    """The greedy order of ``tasks`` (in the files' order): task indices with why each is there.
    ``after`` lists each task's successors, ``waiting`` its unfinished predecessors, ``then``
    the task that must come right after it."""
    count = len(tasks)
    robot = [decisions[t.key].performer == Performer.ROBOT for t in tasks]
    first_tool = [t.tools[0] if t.tools and robot[i] else "" for i, t in enumerate(tasks)]
    names = sorted({n for n in first_tool if n})
    number = {name: k for k, name in enumerate(names)}
    starts = np.array([t.start if t.start is not None else (np.nan,) * 3 for t in tasks], dtype=float)
    starts = starts.reshape(count, 3)
    members: dict[int, list[int]] = {}
    for i, name in enumerate(first_tool):
        if robot[i]:
            members.setdefault(number.get(name, -1), []).append(i)
    groups = {g: _Group(m, starts) for g, m in members.items()}
    slot: dict[int, tuple[_Group, int]] = {}
    for group in groups.values():
        for k, i in enumerate(group.members):
            slot[i] = (group, k)
    people: list[int] = []
    done = np.zeros(count, dtype=bool)

    def become_ready(j: int) -> None:
        if robot[j]:
            group, k = slot[j]
            group.set_ready(k, True)
        else:
            people.append(j)

    for j in np.flatnonzero(waiting == 0).tolist():
        become_ready(j)
    order: list[tuple[int, str]] = []
    tool = ""
    here: Vec3 | None = None

    def finish(i: int, why: str) -> None:
        nonlocal tool, here
        done[i] = True
        if robot[i]:
            group, k = slot[i]
            group.set_ready(k, False)
        order.append((i, why))
        for j in after[i]:
            waiting[j] -= 1
            if waiting[j] == 0:
                become_ready(j)
        task = tasks[i]
        if robot[i]:
            tool = task.tools[-1] if task.tools else tool
            here = task.end if task.end is not None else here

    while len(order) < count:
        forced = then.get(order[-1][0]) if order else None
        if forced is not None and not done[forced[0]] and waiting[forced[0]] == 0:
            finish(*forced)
            continue
        if people:
            ready_people, people[:] = sorted(people), []
            for person in ready_people:
                if not done[person]:
                    finish(person, PERSON)
            continue
        keeping = [g for g in (number.get(tool, -2), -1) if g in groups and groups[g].count]
        if keeping:
            best = min((groups[g].nearest(here) for g in keeping), key=lambda found: (found[0], found[1]))
            i = best[1]
            why = f"keeps the tool {tool}" if tool and tasks[i].tools else "needs no tool"
        else:
            counts = {g: group.count for g, group in groups.items() if group.count}
            if not counts:
                raise AssertionError("precedence left with a cycle")  # cycles are broken before
            g = min(counts, key=lambda k: (-counts[k], k))  # most ready tasks; ties to the first by name
            i = groups[g].nearest(here)[1]
            verb = "tool change to" if tool else "starts with"
            why = f"{verb} {names[g]} ({counts[g]} ready tasks use it)"
        start = tasks[i].start
        if here is not None and start is not None:
            why += f", {1000 * math.dist(start, here):.0f} mm from the previous end"
        finish(i, why)
    return order
