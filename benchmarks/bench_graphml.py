"""GraphML export of a harness (both views) against networkx's writer, and against the build.

For each size (number of wires) a synthetic harness is written with
``benchmarks/synthetic_harness.py`` (a tree of branch points, ``wires / 8`` connectors with
positions, every wire routed) and, in this process:

1. **build**: ``KnowledgeGraph.build(manifest)`` in memory (reading, mapping, loading), wall
   clock; repeated ``--reps`` times, the last graph kept;
2. **export**: ``write_harness_graphml`` of the ``topology`` and the ``wires`` view to a file,
   as ``cadkg export --view`` does: the views' data read from the store by its queries, the
   GraphML written line by line; wall clock and CPU time (of every thread) per view;
3. **networkx baseline**: the same view made a networkx graph and written by
   ``networkx.write_graphml``, in the same run.

The table gives the median of the repetitions and their spread (min-max), per view and for
both views together, the ratio networkx / cadkg, and export / build. The targets are printed
beside the figures: both views of a 100k-wire harness in 5 s or less together, and the export
in at most half the build time of the same harness (medians). Nothing is asserted.

Usage::

    python benchmarks/bench_graphml.py [--sizes 10000,100000] [--reps 3] [--seed 0] [--no-networkx]
    python benchmarks/bench_graphml.py --quick    # a smoke test (its settings: --help)
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import networkx as nx

sys.path.insert(0, str(Path(__file__).resolve().parent))

from cadkg.graph import KnowledgeGraph
from cadkg.usecases.vw.graphml import VIEWS, harness_view, write_harness_graphml
from cadkg.usecases.vw.views import networkx_graph
from quick import add_quick, parse
from synthetic_harness import write_harness

TARGET_BOTH_SECONDS = 5.0
TARGET_RATIO = 0.5
TARGET_WIRES = 100_000


@dataclass
class Timing:
    wall: list[float] = field(default_factory=list)
    cpu: list[float] = field(default_factory=list)

    def add(self, run: Callable[[], object]) -> None:
        cpu, wall = time.process_time(), time.perf_counter()
        run()
        self.wall.append(time.perf_counter() - wall)
        self.cpu.append(time.process_time() - cpu)


@dataclass
class SizeResult:
    wires: int
    build: Timing
    views: dict[str, Timing]
    both: Timing
    networkx: dict[str, Timing]
    networkx_both: Timing
    bytes_written: dict[str, int]


def median(values: Sequence[float]) -> float:
    return statistics.median(values) if values else float("nan")


def spread(values: Sequence[float]) -> str:
    return f"{min(values):.2f}-{max(values):.2f}" if values else "-"


def measure(wires: int, reps: int, seed: int, workdir: Path, baseline: bool) -> SizeResult:
    written = write_harness(workdir / f"h{wires}", wires, seed)
    build = Timing()
    kg: KnowledgeGraph | None = None
    for _ in range(reps):
        kg = None
        started = time.perf_counter()
        cpu = time.process_time()
        kg = KnowledgeGraph.build(written.manifest)
        build.wall.append(time.perf_counter() - started)
        build.cpu.append(time.process_time() - cpu)
    assert kg is not None
    views = {view: Timing() for view in VIEWS}
    both = Timing()
    sizes = {}
    for _ in range(reps):
        for view in VIEWS:
            out = workdir / f"{view}.graphml"
            views[view].add(lambda view=view, out=out: write_harness_graphml(kg, out, view))
            sizes[view] = out.stat().st_size
        both.wall.append(sum(views[v].wall[-1] for v in VIEWS))
        both.cpu.append(sum(views[v].cpu[-1] for v in VIEWS))
    networkx = {view: Timing() for view in VIEWS}
    networkx_both = Timing()
    for _ in range(reps if baseline else 0):
        for view in VIEWS:
            out = workdir / f"{view}-networkx.graphml"

            def run(view: str = view, out: Path = out) -> None:
                nx.write_graphml(networkx_graph(harness_view(kg, view)), out)

            networkx[view].add(run)
        networkx_both.wall.append(sum(networkx[v].wall[-1] for v in VIEWS))
        networkx_both.cpu.append(sum(networkx[v].cpu[-1] for v in VIEWS))
    return SizeResult(wires, build, views, both, networkx, networkx_both, sizes)


def table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    widths = [max(len(str(r[i])) for r in [header, *rows]) for i in range(len(header))]
    line = "  ".join(f"{h:>{w}}" for h, w in zip(header, widths, strict=True))
    rule = "  ".join("-" * w for w in widths)
    body = ["  ".join(f"{c:>{w}}" for c, w in zip(row, widths, strict=True)) for row in rows]
    return "\n".join([line, rule, *body])


def report(results: Sequence[SizeResult]) -> str:
    rows = []
    for r in results:
        build = median(r.build.wall)
        for name, timing, baseline in (
            *((v, r.views[v], r.networkx[v]) for v in VIEWS),
            ("both", r.both, r.networkx_both),
        ):
            export = median(timing.wall)
            rows.append(
                [
                    f"{r.wires:,}",
                    name,
                    f"{build:.2f} ({spread(r.build.wall)})",
                    f"{export:.2f} ({spread(timing.wall)})",
                    f"{median(timing.cpu):.2f}",
                    f"{median(baseline.wall):.2f} ({spread(baseline.wall)})" if baseline.wall else "-",
                    f"{median(baseline.wall) / export:.1f}x" if baseline.wall else "-",
                    f"{export / build:.2f}",
                    f"{r.bytes_written[name] / 1e6:.1f}" if name in r.bytes_written else "",
                ]
            )
    text = table(
        [
            "wires",
            "view",
            "build s (min-max)",
            "export s (min-max)",
            "export cpu s",
            "networkx s (min-max)",
            "nx/cadkg",
            "export/build",
            "MB",
        ],
        rows,
    )
    for r in results:
        if r.wires != TARGET_WIRES:
            continue
        both, build = median(r.both.wall), median(r.build.wall)
        text += (
            f"\n\ntargets at {TARGET_WIRES:,} wires (medians of {len(r.both.wall)} runs):"
            f"\n  both views {both:.2f} s, target <= {TARGET_BOTH_SECONDS:.1f} s:"
            f" {'met' if both <= TARGET_BOTH_SECONDS else 'not met'}"
            f"\n  export / build {both / build:.2f}, target <= {TARGET_RATIO}:"
            f" {'met' if both / build <= TARGET_RATIO else 'not met'}"
        )
    return text


def environment() -> str:
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    return (
        f"{platform.python_implementation()} {platform.python_version()}, {os.cpu_count()} CPUs,"
        f" load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f} when the run ended"
    )


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="10000,100000", help="numbers of wires, comma separated")
    parser.add_argument("--reps", type=int, default=3, help="repetitions of each build and export (>= 3)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--no-networkx", action="store_true", help="leave out the networkx baseline")
    add_quick(parser, sizes="2000")
    args = parse(parser, argv)
    sizes = [int(s) for s in args.sizes.split(",") if s]
    reps = max(3, args.reps)
    results = []
    with tempfile.TemporaryDirectory(prefix="cadkg-graphml-") as tmp:
        for wires in sizes:
            results.append(measure(wires, reps, args.seed, Path(tmp), not args.no_networkx))
            print(f"measured {wires:,} wires", file=sys.stderr, flush=True)
    print(report(results))
    print(f"\n{environment()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
