"""``cadkg diff`` on two synthetic cabinets that differ in 1 % of their wires and components.

For each run a fresh process builds the complete cabinet of ``synthetic.write_cabinet`` in
memory (the baseline, measured in the same run), builds a copy in which every hundredth wire
is renumbered, recoloured or given another cross-section and every hundredth device (relay,
contactor, fuse) is moved 5 mm along its rail, then diffs the two
(``cadkg.changes.diff_graphs``: every kind's queries on both graphs, matching, comparing). The
ratio is diff / build of one cabinet; the target is at most 0.25 at 10k wires. The changes
found must be those planted: the wires and the moved devices (whose pins move with them and
are not reported), and the two files edited. Peak RSS is the process's ``VmHWM`` after the
two builds and after the diff.

With ``--runs N`` each size runs N times, each in a fresh process, and a last table gives the
medians with the lowest and highest, and the verdict on the median.

Usage::

    python benchmarks/bench_diff.py [--wires 10000] [--runs 3]
    python benchmarks/bench_diff.py --quick    # a smoke test (its settings: --help)
"""

from __future__ import annotations

import argparse
import json
import platform
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_build import peak_rss_mib, reference_loop_seconds
from medians import spread, verdict
from quick import add_quick, parse
from synthetic import write_cabinet

CHILD_FLAG = "--child-job"
TARGET = 0.25  # diff / build at 10k wires
EVERY = 100  # one wire and one component in a hundred


def plant_changes(cell: Path, changed: Path) -> dict[str, int]:
    """Copy the cabinet ``cell`` to ``changed`` with 1 % of its wires and components changed;
    how many of each."""
    shutil.copytree(cell, changed)
    lists = changed / "lista-cablaggio.csv"
    lines = lists.read_bytes().decode("utf-8").split("\r\n")
    wires = 0
    for i, line in enumerate(lines):
        cells = line.split("\t")
        if len(cells) < 15 or not cells[6][:1].isdigit() or i % EVERY:
            continue
        change = wires % 3
        if change == 0:
            cells[6] += "R"  # renumbered: same ends, new number
        elif change == 1:
            cells[8] = "RD" if cells[8] != "RD" else "BK"
        else:
            cells[7] = "1,5 mm²" if cells[7] != "1,5 mm²" else "2,5 mm²"
        lines[i] = "\t".join(cells)
        wires += 1
    lists.write_bytes("\r\n".join(lines).encode("utf-8"))
    # Every hundredth device of one CAD item (a relay, a contactor, a fuse): not a rail, which
    # carries its components along, nor a terminal of a block, whose pins move inside it.
    firsts: dict[str, str] = {}
    for row in (changed / "ids.wri").read_bytes().decode("utf-8").splitlines():
        item, label, *_ = row.split("\t")
        if label.startswith(("=-K", "=-Q", "=-F")):
            firsts.setdefault(label, item)
    chosen = set(list(firsts.values())[::EVERY])
    scene = changed / "scene.x3d"
    moved = 0

    def move(match: re.Match[str]) -> str:
        nonlocal moved
        if match.group(1) not in chosen:
            return match.group(0)
        x, rest = match.group(2).split(" ", 1)
        moved += 1
        return f'<Transform DEF="{match.group(1)}" translation="{float(x) + 0.005:g} {rest}"'

    text = re.sub(r'<Transform DEF="(ID\d+)" translation="([^"]+)"', move, scene.read_text(encoding="utf-8"))
    scene.write_text(text, encoding="utf-8")
    return {"wires": wires, "components": moved}


def child(old: str, new: str) -> dict[str, Any]:
    import cadkg
    from cadkg.changes import diff_graphs

    started = time.perf_counter()
    a = cadkg.build(old)
    built = time.perf_counter()
    b = cadkg.build(new)
    rss_built = peak_rss_mib()
    start = time.perf_counter()
    changes = diff_graphs(a, b)
    done = time.perf_counter()
    found: dict[str, dict[str, int]] = {}
    for change in changes:
        found.setdefault(change.change, {}).setdefault(change.kind, 0)
        found[change.change][change.kind] += 1
    return {
        "triples": len(a),
        "build": built - started,
        "diff": done - start,
        "rss_built": rss_built,
        "rss_diff": peak_rss_mib(),
        "found": found,
    }


def run_once(old: Path, new: Path) -> dict[str, Any]:
    result = subprocess.run(
        [sys.executable, __file__, CHILD_FLAG, str(old), str(new)],
        capture_output=True,
        text=True,
        check=False,
    )
    if result.returncode != 0:
        raise SystemExit(f"bench_diff: the run failed:\n{result.stderr[-3000:]}")
    data: dict[str, Any] = json.loads(result.stdout.strip().splitlines()[-1])
    return data


def _found(found: dict[str, dict[str, int]]) -> str:
    return "; ".join(
        f"{change} " + ", ".join(f"{n} {kind}" for kind, n in sorted(kinds.items()))
        for change, kinds in sorted(found.items())
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--wires", type=int, default=10_000)
    parser.add_argument("--runs", type=int, default=1)
    add_quick(parser, wires=300, runs=1)
    args = parse(parser, argv)
    wires, runs = args.wires, args.runs
    reference = reference_loop_seconds()
    with tempfile.TemporaryDirectory(prefix="cadkg-bench-diff-") as folder:
        old = Path(write_cabinet(Path(folder) / "old", wires))
        planted = plant_changes(old.parent, Path(folder) / "new")
        results = [run_once(old, Path(folder) / "new" / old.name) for _ in range(runs)]
    ref = f"{reference:.2f} s"
    print("#### Environment\n")
    print(f"- Python {platform.python_version()} on {platform.system()} {platform.machine()}")
    print(f"- reference loop (20 M Python integer additions), timed as this report is written: {ref}\n")
    what = f"{planted['wires']} wires and {planted['components']} components changed"
    print(f"#### Diff of two {wires:,}-wire cabinets ({what})\n")
    columns = ("wires", "run", "triples", "build s", "diff s", "diff/build", "peak RSS built MiB")
    print("| " + " | ".join(columns) + " | peak RSS after diff MiB | found |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---|")
    for number, r in enumerate(results, start=1):
        ratio = r["diff"] / r["build"]
        print(
            f"| {wires} | {number} | {r['triples']:,} | {r['build']:.2f} | {r['diff']:.2f} | {ratio:.2f}× | "
            f"{r['rss_built']:,.0f} | {r['rss_diff']:,.0f} | {_found(r['found'])} |"
        )
    ratios = [r["diff"] / r["build"] for r in results]
    builds = spread([r["build"] for r in results])
    diffs = spread([r["diff"] for r in results])
    print("\n#### Medians\n")
    print("| wires | runs | build s | diff s | diff/build | target | verdict |")
    print("|---:|---:|---:|---:|---:|---:|---|")
    print(
        f"| {wires} | {runs} | {builds} | {diffs} | {spread(ratios, suffix='×')} | ≤ {TARGET}× | "
        f"{verdict(ratios, TARGET, at_most=True)} |"
    )
    return 0


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == CHILD_FLAG:
        print(json.dumps(child(sys.argv[2], sys.argv[3])))
        sys.exit(0)
    sys.exit(main())
