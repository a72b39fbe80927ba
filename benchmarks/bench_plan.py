"""``cadkg plan`` on synthetic cabinets: planning time against the build, the plan's tool
changes, travel and precedence against the connection list's own order and the lower bound,
and its times (the IEMA default time model): the robot's, the person's and the makespan of the
two side by side, unbalanced and balanced, against the robot's and the person's work one after
the other and against the whole cabinet by hand.

For each size a complete synthetic cabinet is written (``synthetic.write_cabinet``: DIN rails,
two-level terminal blocks, every fifth relay mounted upside down, wire ends with several
terminations: ``PUNTALINO_vite``, ``ELETTROSALDATO_molla``, ``CAPICORDA_vite``) and, in a fresh
process, built in memory and planned with the IEMA default rules
(``cadkg.plan.cell.plan_cell``: the tasks and their decisions, precedence from the pins'
approach corridors, the order). The baseline is the files' own order, measured in the same run
on the same tasks: its tool changes and travel are the ones a robot walking the list would
have. The lower bound is the fewest tool changes any order can have.

With ``--runs N`` each size is planned N times, each in a fresh process, and the last tables give
the medians with the lowest and highest, and the targets judged on them (1k wires planned, with
times, in at most 1 s; 10k wires in at most a quarter of the build of the same cell; the
balanced plan of 1k wires in at most 1 s).

Usage::

    python benchmarks/bench_plan.py [--sizes 1000,10000] [--runs 3]
    python benchmarks/bench_plan.py --quick    # a smoke test (its settings: --help)
"""

from __future__ import annotations

import argparse
import json
import platform
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
TURNED_EVERY = 5
# Planning time: at most this many seconds (1k) or this share of the build (10k); the balanced
# plan (tasks, order, timing and balance, from the built cell) at most BALANCE_SECONDS.
SECONDS = {1000: 1.0}
SHARE = {10_000: 0.25}
BALANCE_SECONDS = {1000: 1.0}


def child(manifest: str) -> dict[str, Any]:
    import cadkg
    from cadkg.plan.cell import plan_cell

    start = time.perf_counter()
    kg = cadkg.build(manifest)
    kg.cell_model()
    built = time.perf_counter()
    plan = plan_cell(kg)
    planned = time.perf_counter()
    balanced = plan_cell(kg, balance=True)
    done = time.perf_counter()
    from cadkg.plan.cell import rules_of, time_model
    from cadkg.plan.times import Lanes

    model = time_model(kg, rules_of(kg))
    timing, even = plan.timing, balanced.timing
    assert timing is not None and even is not None
    # What timing the plan costs by itself: the lanes of its order, timed once.
    started = time.perf_counter()
    Lanes([s.task for s in plan.steps], plan.precedence, model).run(
        [s.decision.performer == "robot" for s in plan.steps]
    )
    return {
        "timing": time.perf_counter() - started,
        "balance": done - planned,
        "robot_s": timing.robot_s,
        "person_s": timing.person_s,
        "makespan": timing.makespan_s,
        "by_hand": sum(model.person_work(s.task) for s in plan.steps),
        "balanced": even.makespan_s,
        "balanced_robot_s": even.robot_s,
        "balanced_person_s": even.person_s,
        "moved": sum(1 for s in balanced.steps if s.decision.rule == "balance"),
        "build": built - start,
        "plan": planned - built,
        "tasks": len(plan.steps),
        "robot": sum(1 for s in plan.steps if s.decision.performer == "robot"),
        "edges": len(plan.precedence),
        "dropped": len(plan.dropped),
        "changes": plan.measure.tool_changes,
        "files_changes": plan.files.tool_changes,
        "bound": plan.lower_bound,
        "travel": plan.measure.travel,
        "files_travel": plan.files.travel,
        "violations": plan.measure.violations,
        "files_violations": plan.files.violations,
        "rss": peak_rss_mib(),
    }


def measure(manifest: Path, wires: int) -> dict[str, Any]:
    out = subprocess.run(
        [sys.executable, __file__, CHILD_FLAG, str(manifest)], check=False, capture_output=True, text=True
    )
    if out.returncode != 0:
        raise SystemExit(f"{wires} wires: the planning process failed:\n{out.stderr}")
    result: dict[str, Any] = json.loads(out.stdout.strip().splitlines()[-1])
    return {"wires": wires, **result}


def _ratio(a: float, b: float) -> str:
    return f"{a / b:.2f}" if b else "—"


def row(r: dict[str, Any]) -> str:
    return (
        f"| {r['wires']:,} | {r['build']:.2f} | {r['plan']:.2f} | {r['plan'] / r['build']:.3f} "
        f"| {r['robot']:,}/{r['tasks']:,} | {r['edges']:,} ({r['dropped']}) "
        f"| {r['changes']:,} | {r['files_changes']:,} | {r['bound']:,} "
        f"| {_ratio(r['changes'], r['files_changes'])} "
        f"| {_ratio(r['changes'], r['bound'])} | {r['travel']:.1f} | {r['files_travel']:.1f} "
        f"| {_ratio(r['travel'], r['files_travel'])} | {r['files_violations']} | {r['violations']} "
        f"| {r['rss']:,.0f} |"
    )


def _h(seconds: float) -> str:
    return f"{seconds / 3600:,.2f}"


def time_row(r: dict[str, Any]) -> str:
    alone = r["robot_s"] + r["person_s"]
    return (
        f"| {r['wires']:,} | {_h(r['robot_s'])} | {_h(r['person_s'])} | {_h(r['makespan'])} "
        f"| {r['moved']:,} | {_h(r['balanced_robot_s'])} | {_h(r['balanced_person_s'])} "
        f"| {_h(r['balanced'])} | {_h(alone)} | {_h(r['by_hand'])} | {_ratio(r['balanced'], alone)} "
        f"| {_ratio(r['balanced'], r['makespan'])} | {_ratio(r['balanced'], r['by_hand'])} "
        f"| {r['balance']:.2f} | {r['timing']:.3f} |"
    )


TIME_HEADER = (
    "| wires | robot h | person h | makespan h | balance: moved | robot h | person h | makespan h "
    "| robot only (robot, then person) h | by hand h | balanced / robot only | balanced / unbalanced "
    "| balanced / by hand | balanced plan s | of the plan s: timing |\n"
    "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
)


def time_summary(runs: dict[int, list[dict[str, Any]]]) -> str:
    """Medians of the times (the same in every run: the plan is deterministic) and of the
    balanced plan's seconds, with the target."""
    lines = [
        "| runs | wires | makespan unbalanced h | balanced h | robot only h | balanced / robot only "
        "| balanced / unbalanced | balanced plan s | target | verdict |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for wires, rs in runs.items():
        alone = [r["robot_s"] + r["person_s"] for r in rs]
        if wires in BALANCE_SECONDS:
            target = f"≤ {BALANCE_SECONDS[wires]:g} s"
            judged = verdict([r["balance"] for r in rs], BALANCE_SECONDS[wires], at_most=True)
        else:
            target = judged = "—"
        lines.append(
            f"| {len(rs)} | {wires:,} | {spread([r['makespan'] / 3600 for r in rs])} "
            f"| {spread([r['balanced'] / 3600 for r in rs])} | {spread([a / 3600 for a in alone])} "
            f"| {spread([r['balanced'] / a for r, a in zip(rs, alone, strict=True)], 3)} "
            f"| {spread([r['balanced'] / r['makespan'] for r in rs], 3)} "
            f"| {spread([r['balance'] for r in rs])} | {target} | {judged} |"
        )
    return "\n".join(lines)


def summary(runs: dict[int, list[dict[str, Any]]]) -> str:
    """Medians of each size's runs, and the targets judged on them."""
    lines = [
        "| runs | wires | reference loop s | build s | plan s | plan / build | target | verdict "
        "| tool changes plan / files | plan / lower bound | travel plan / files |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for wires, rs in runs.items():
        shares = [r["plan"] / r["build"] for r in rs]
        if wires in SECONDS:
            target, judged = (
                f"≤ {SECONDS[wires]:g} s",
                verdict([r["plan"] for r in rs], SECONDS[wires], at_most=True),
            )
        elif wires in SHARE:
            target, judged = f"≤ {SHARE[wires]:g} × build", verdict(shares, SHARE[wires], at_most=True)
        else:
            target = judged = "—"
        lines.append(
            f"| {len(rs)} | {wires:,} | {spread([r['loop'] for r in rs])} "
            f"| {spread([r['build'] for r in rs])} "
            f"| {spread([r['plan'] for r in rs])} | {spread(shares, 3)} | {target} | {judged} "
            f"| {spread([r['changes'] / r['files_changes'] for r in rs if r['files_changes']])} "
            f"| {spread([r['changes'] / r['bound'] for r in rs if r['bound']])} "
            f"| {spread([r['travel'] / r['files_travel'] for r in rs if r['files_travel']], 3)} |"
        )
    return "\n".join(lines)


def main() -> int:
    if len(sys.argv) == 3 and sys.argv[1] == CHILD_FLAG:
        print(json.dumps(child(sys.argv[2])))
        return 0
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--sizes", default="1000,10000", help="wires per cabinet, comma separated")
    parser.add_argument("--runs", type=int, default=1, help="plan each size this many times")
    add_quick(parser, sizes="300")
    args = parse(parser)
    sizes = [int(size) for size in args.sizes.split(",")]
    import pyoxigraph

    import cadkg

    print(
        f"Python {platform.python_version()}, cadkg {cadkg.__version__}, "
        f"pyoxigraph {pyoxigraph.__version__}; "
        f"complete synthetic cabinet, every {TURNED_EVERY}th relay upside down, IEMA default rules\n"
    )
    print(
        "| wires | build s | plan s | plan / build | robot/tasks | precedence (dropped) "
        "| tool changes: plan | files' order | lower bound | plan / files | plan / bound "
        "| travel m: plan | files' order | plan / files | violations: files' order | plan | peak RSS MiB |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    runs: dict[int, list[dict[str, Any]]] = {}
    with tempfile.TemporaryDirectory(prefix="cadkg-plan-") as tmp:
        manifests = {
            wires: write_cabinet(Path(tmp) / str(wires), wires, turned_every=TURNED_EVERY) for wires in sizes
        }
        for _ in range(max(1, args.runs)):
            for wires in sizes:
                loop = reference_loop_seconds()
                r = measure(manifests[wires], wires)
                runs.setdefault(wires, []).append({**r, "loop": loop})
                print(row(r), flush=True)
    print("\nTimes (hours; the IEMA default time model), unbalanced and balanced:\n")
    print(TIME_HEADER)
    for rs in runs.values():
        print(time_row(rs[0]))
    print(f"\nMedians (lowest–highest) of {max(1, args.runs)} run(s) a size:\n")
    print(summary(runs))
    print()
    print(time_summary(runs))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
