"""Reopening a store directory: the kept cell model against deriving it from the graph again.

For each size a complete synthetic cabinet (``synthetic.write_cabinet``) is built into a
store directory, and then, each in a fresh process (so nothing is warm in Python; the
operating system's file cache is warm for every row alike), the median of ``--reps`` runs
with the lowest and highest:

- **kept**: ``cadkg.open(store).cell_model()``, which reads ``gen-*/cell-model.json``;
- **from the graph** (the baseline): ``derive_cell(extract(kg))`` on the same opened store,
  what every reopening cost before the model was kept, split into its two parts;
- **placements**: ``cadkg.query.placements.placements(kg)``, the frames and meshes alone, which is what the
  ROS node reads from the graph beside the kept model;
- **``cadkg call``**: the command line end to end (``cad_service`` of one component), with
  the kept model, and with the file moved aside for the run.

The ratio is baseline / kept. Nothing is asserted.

Usage::

    python benchmarks/bench_reopen.py [--sizes 1000,10000] [--reps 3]
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_build import reference_loop_seconds
from medians import spread
from synthetic import write_cabinet

CHILD_FLAG = "--child-job"


def child(job: str, store: str) -> dict[str, Any]:
    import cadkg
    from cadkg.query.placements import placements
    from cadkg.usecases.iema.derive.cabinet import derive_cell
    from cadkg.usecases.iema.derive.extract import extract

    start = time.perf_counter()
    kg = cadkg.open(store)
    if job == "kept":
        model = kg.cell_model()
        return {"seconds": time.perf_counter() - start, "steps": len(model.steps)}
    if job == "placements":
        placed = placements(kg)
        return {"seconds": time.perf_counter() - start, "frames": len(placed.frames)}
    inputs = extract(kg)
    extracted = time.perf_counter()
    model = derive_cell(inputs)
    done = time.perf_counter()
    return {"extract": extracted - start, "derive": done - extracted, "steps": len(model.steps)}


def run_child(job: str, store: Path) -> dict[str, Any]:
    out = subprocess.run(
        [sys.executable, __file__, CHILD_FLAG, job, str(store)], check=True, capture_output=True, text=True
    )
    result: dict[str, Any] = json.loads(out.stdout)
    return result


def run_call(store: Path, label: str) -> float:
    start = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "cadkg.cli", "call", str(store), "cad_service", f"label={label}"],
        check=True,
        capture_output=True,
    )
    return time.perf_counter() - start


def measure(wires: int, reps: int, workdir: Path) -> dict[str, Any]:
    import cadkg

    manifest = write_cabinet(workdir / "cell", wires)
    store = workdir / "store"
    start = time.perf_counter()
    with cadkg.build(manifest, store) as kg:
        build = time.perf_counter() - start
        triples = len(kg)
        label = next(iter(kg.cell_model().components))
    (kept_file,) = store.glob("gen-*/cell-model.json")
    kept = [run_child("kept", store) for _ in range(reps)]
    graph = [run_child("graph", store) for _ in range(reps)]
    placed = [run_child("placements", store) for _ in range(reps)]
    assert {r["steps"] for r in kept + graph} == {wires}
    assert min(r["frames"] for r in placed) > 0
    call_kept = [run_call(store, label) for _ in range(reps)]
    aside = kept_file.with_name("aside.json")
    kept_file.replace(aside)
    try:
        call_without = [run_call(store, label) for _ in range(reps)]
    finally:
        aside.replace(kept_file)
    extract_s = statistics.median(r["extract"] for r in graph)
    derive_s = statistics.median(r["derive"] for r in graph)
    kept_s = statistics.median(r["seconds"] for r in kept)
    return {
        "wires": wires,
        "triples": triples,
        "build": build,
        "mib": kept_file.stat().st_size / 2**20,
        "kept": [r["seconds"] for r in kept],
        "extract": [r["extract"] for r in graph],
        "derive": [r["derive"] for r in graph],
        "ratio": (extract_s + derive_s) / kept_s,
        "placements": [r["seconds"] for r in placed],
        "call_kept": call_kept,
        "call_without": call_without,
    }


def main() -> int:
    if len(sys.argv) == 4 and sys.argv[1] == CHILD_FLAG:
        print(json.dumps(child(sys.argv[2], sys.argv[3])))
        return 0
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--sizes", default="1000,10000", help="wires per cabinet, comma separated")
    parser.add_argument("--reps", type=int, default=3, help="fresh processes per figure (median)")
    args = parser.parse_args()
    import pyoxigraph

    import cadkg

    print(
        f"Python {platform.python_version()}, cadkg {cadkg.__version__}, "
        f"pyoxigraph {pyoxigraph.__version__}, median (lowest–highest) of {args.reps} fresh processes "
        f"per figure; reference loop {reference_loop_seconds():.2f} s\n"
    )
    print(
        "| wires | triples | build on disk s | kept model MiB | kept s | from the graph: extract s "
        "| derive s | ratio | placements s | `cadkg call` kept s | `cadkg call` without s |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for wires in (int(size) for size in args.sizes.split(",")):
        with tempfile.TemporaryDirectory(prefix="cadkg-reopen-") as tmp:
            r = measure(wires, args.reps, Path(tmp))
        print(
            f"| {r['wires']:,} | {r['triples']:,} | {r['build']:.1f} | {r['mib']:.1f} | {spread(r['kept'])} "
            f"| {spread(r['extract'])} | {spread(r['derive'])} | {r['ratio']:.1f}× "
            f"| {spread(r['placements'])} | {spread(r['call_kept'])} | {spread(r['call_without'])} |",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
