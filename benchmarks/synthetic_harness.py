"""A synthetic wire harness of any size, in cadkg's harness text format.

``write_harness(directory, wires)`` writes ``harness.harness`` and ``manifest.toml`` (profile
``vw``): one harness ``SYN`` whose topology is a tree, the way a vehicle harness branches
from its trunk:

* a root node ``R`` (a grommet), ``BRANCHES`` first-level branch points ``B1`` ...,
  ``BRANCHES`` second-level branch points under each (``B1_1`` ...), and the connectors
  ``X00001`` ... shared out evenly under the second-level points, each connector on a node of
  its own name;
* every node with a position (``position=X,Y,Z`` in mm: the trunk along x, the branches
  spread around it), every segment with its length (the distance between its nodes) and a
  bundle diameter, a clip on every tenth segment, tape on every fifth;
* ``wires`` wires, each from a free cavity of one connector to a free cavity of another (half
  of them under the same branch point, the others anywhere), with section, colour, length
  (the route's length plus 5 %) and its route from the first end (``route=``, at most six
  segments); every tenth pair of wires are the two cores of a cable.

There are ``wires / 8`` connectors of ``CAVITIES`` cavities each, so most cavities hold a
wire end. The output depends only on ``wires`` and ``seed``; 100k wires (7 MB) are written in
a few seconds.

Usage: ``python benchmarks/synthetic_harness.py OUTDIR --wires 100000 [--seed 0]``
"""

from __future__ import annotations

import argparse
import math
import random
from dataclasses import dataclass, field
from pathlib import Path

__all__ = ["HARNESS", "SyntheticHarness", "write_harness"]

HARNESS = "SYN"
BRANCHES = 12
CAVITIES = 20
SECTIONS = ("0.35", "0.5", "0.75", "1.0", "1.5", "2.5", "4.0")
COLOURS = ("BK", "RD", "BU", "GN", "YE", "BN", "WH", "GY", "VT", "OG", "RD/WH", "BK/YE", "GN/YE")


@dataclass
class SyntheticHarness:
    """What the generator wrote: the manifest, and counts to check a build against."""

    manifest: Path
    connectors: int
    nodes: int
    segments: int
    wires: int
    cables: int
    positions: dict[str, tuple[float, float, float]] = field(default_factory=dict)


def _position(angle: float, radius: float, x: float, z: float) -> tuple[float, float, float]:
    return (round(x, 1), round(radius * math.cos(angle), 1), round(z + radius * math.sin(angle), 1))


def write_harness(directory: str | Path, wires: int, seed: int = 0) -> SyntheticHarness:
    """Write a harness of ``wires`` wires (``harness.harness``) and its manifest into ``directory``."""
    if wires < 2:
        raise ValueError("a synthetic harness needs at least 2 wires")
    rng = random.Random(seed)
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    connectors = max(2, wires // 8)
    positions: dict[str, tuple[float, float, float]] = {"R": (0.0, 0.0, 0.0)}
    parent: dict[str, str] = {}
    seconds: list[str] = []
    for i in range(1, BRANCHES + 1):
        first = f"B{i}"
        angle = 2 * math.pi * i / BRANCHES
        positions[first] = _position(angle, 300.0, 400.0 * i, 200.0)
        parent[first] = "R"
        for j in range(1, BRANCHES + 1):
            second = f"B{i}_{j}"
            positions[second] = _position(angle + 0.05 * j, 600.0, 400.0 * i + 25.0 * j, 200.0)
            parent[second] = first
            seconds.append(second)
    names = [f"X{n:05d}" for n in range(1, connectors + 1)]
    under: dict[str, list[str]] = {s: [] for s in seconds}
    for n, name in enumerate(names):
        second = seconds[n % len(seconds)]
        x, y, z = positions[second]
        positions[name] = (
            round(x + rng.uniform(-80, 80), 1),
            round(y * 1.3, 1),
            round(z + rng.uniform(-150, 150), 1),
        )
        parent[name] = second
        under[second].append(name)
    segment_of: dict[str, str] = {}
    lines = [f'harness {HARNESS} description="synthetic harness, {wires} wires (seed {seed})"']
    for name in names:
        x, y, z = positions[name]
        lines.append(f"connector {name} cavities=1-{CAVITIES} position={x}mm,{y}mm,{z}mm")
    connector_names = set(names)
    for node in ["R", *(p for p in parent if p not in connector_names)]:
        x, y, z = positions[node]
        lines.append(f"node {node} position={x}mm,{y}mm,{z}mm")
    length: dict[str, float] = {}
    for n, (child, up) in enumerate(parent.items(), start=1):
        segment = f"S{n}"
        segment_of[child] = segment
        length[segment] = max(1.0, round(math.dist(positions[child], positions[up]), 1))
        diameter = 4 + (n % 7) * 2
        lines.append(f"segment {segment} {up} {child} length={length[segment]}mm diameter={diameter}mm")

    def chain(node: str) -> list[str]:
        """The nodes from ``node`` up to the root."""
        nodes = [node]
        while nodes[-1] in parent:
            nodes.append(parent[nodes[-1]])
        return nodes

    def route(a: str, b: str) -> list[str]:
        up, down = chain(a), chain(b)
        while len(up) > 1 and len(down) > 1 and up[-2] == down[-2]:
            up.pop()
            down.pop()
        return [segment_of[n] for n in up[:-1]] + [segment_of[n] for n in reversed(down[:-1])]

    free = {name: list(range(1, CAVITIES + 1)) for name in names}
    open_names = list(names)
    cables = 0
    body: list[str] = []
    n = 0
    while n < wires:
        a = rng.choice(open_names)
        # Half the wires stay under one branch point, the others run anywhere.
        b = rng.choice(under[parent[a]]) if rng.random() < 0.5 else rng.choice(open_names)
        pair = 2 if n + 2 <= wires and n % 20 == 0 else 1
        if a == b or len(free[a]) < pair or len(free[b]) < pair:
            if all(len(free[c]) < 2 for c in open_names):
                raise ValueError("no free cavities left")
            open_names = [c for c in open_names if len(free[c]) >= 2] or open_names
            continue
        path = route(a, b)
        metres = sum(length[s] for s in path) * 1.05
        cable = None
        if pair == 2:
            cables += 1
            cable = f"C{cables:05d}"
            body.append(f"cable {cable} length={round(metres, 1)}mm diameter=6mm")
        for _ in range(pair):
            n += 1
            section, colour = rng.choice(SECTIONS), rng.choice(COLOURS)
            options = f"section={section} colour={colour} length={round(metres, 1)}mm route={','.join(path)}"
            if cable is not None:
                options += f" cable={cable}"
            body.append(f"wire W{n:06d} {a}:{free[a].pop(0)} {b}:{free[b].pop(0)} {options}")
    lines.extend(body)
    for n, segment in enumerate(segment_of.values(), start=1):
        if n % 10 == 0:
            lines.append(f"fixing F{n} on={segment}")
        if n % 5 == 0:
            lines.append(f"protection P{n} on={segment} description=tape")
    (directory / "harness.harness").write_text("\n".join(lines) + "\n", encoding="utf-8")
    manifest = directory / "manifest.toml"
    manifest.write_text(
        '[cell]\nname = "synthetic harness"\nprofile = "vw"\nbase_iri = "https://example.org/cell/syn/"\n'
        '[[source]]\npath = "harness.harness"\nkind = "harness-text"\n',
        encoding="utf-8",
    )
    return SyntheticHarness(
        manifest, connectors, len(positions), len(parent), wires, cables, positions=positions
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("outdir", type=Path)
    parser.add_argument("--wires", type=int, default=10_000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    written = write_harness(args.outdir, args.wires, args.seed)
    print(
        f"{written.manifest}: {written.wires} wires, {written.connectors} connectors,"
        f" {written.segments} segments"
    )


if __name__ == "__main__":
    main()
