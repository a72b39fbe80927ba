"""``cadkg validate`` on synthetic cells: the build, the semantic checks and the SHACL shapes.

For each size a synthetic cell (``synthetic.write_cell``; with ``--cabinet``, the complete
cabinet of ``synthetic.write_cabinet``) is validated in a fresh process the way
``cadkg validate MANIFEST`` does it: built in memory, then ``validate(kg, shacl=False)`` (the
semantic checks, SPARQL on the store: unknown labels, duplicate wire numbers, pins without
model data) and ``validate(kg)`` (the same, then the SHACL shapes, compiled to SPARQL and run
by pyoxigraph on the store). The SHACL column is the difference of the two, and the
validation's cost against the build of the same run is their sum over the build.

Two baselines, in the same process: rdflib runs the semantic checks' three queries on an
rdflib ``Dataset`` that holds the same quads (the store's N-Quads), against the same queries
on the store (the ratio is rdflib / cadkg; both must return the same number of rows; left out
above ``--rdflib-max-wires``, default 1,000, since rdflib's time grows with the square of the
cell); and pySHACL checks the same shapes on an rdflib copy of the same graphs, as
``cadkg validate`` did before (the copy included in its time; left out above
``--pyshacl-max-wires``, default 10,000), and must report the same results. A cell generated
by ``synthetic.py`` has no findings but the ones it plants; the findings column would show any
other. Peak RSS is the process's ``VmHWM``.

With ``--runs N`` each size is validated N times, each in a fresh process, and a last table
gives the medians with the lowest and highest; with ``--cabinet`` it judges the targets
(validation at most half the build at 10k wires, at most the build at 100k) on the medians.

Usage::

    python benchmarks/bench_validate.py [--sizes 1000,5000,10000] [--cabinet] [--runs 3]
                                        [--rdflib-max-wires 1000] [--pyshacl-max-wires 10000]
    python benchmarks/bench_validate.py --quick    # a smoke test (its settings: --help)
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
from synthetic import write_cabinet, write_cell

ROOT = Path(__file__).resolve().parents[1]
CHILD_FLAG = "--child-job"
# The validation of a cabinet against its build, in one run: (checks + shapes) / build.
TARGETS = {10_000: 0.5, 100_000: 1.0}


def child(manifest: str, baseline: bool, reference: bool) -> dict[str, Any]:
    import rdflib

    import cadkg
    from cadkg.query.shacl_shapes import cadkg_shapes
    from cadkg.query.shacl_sparql import check_shapes
    from cadkg.query.validate import _PINS_WITHOUT_DATA, _UNKNOWN_LABELS, _WIRE_ENDS, _shacl, validate
    from cadkg.store import PREFIXES

    start = time.perf_counter()
    kg = cadkg.build(manifest)
    built = time.perf_counter()
    semantic = validate(kg, shacl=False)
    checked = time.perf_counter()
    # The shapes timed by themselves, as validate runs them: a difference of two whole runs
    # went below zero on a loaded machine.
    shapes = _shacl(kg)
    validated = time.perf_counter()
    findings = sorted({*semantic, *shapes})
    queries = (_UNKNOWN_LABELS, _WIRE_ENDS, _PINS_WITHOUT_DATA)
    started = time.perf_counter()
    rows = [len(kg.query(query)) for query in queries]
    cadkg_queries = time.perf_counter() - started
    rdflib_rows: list[int] | None = None
    rdflib_queries: float | None = None
    if baseline:
        dataset = rdflib.Dataset(default_union=True)
        dataset.parse(data=kg.serialize("nq"), format="nquads")
        started = time.perf_counter()
        rdflib_rows = [len(list(dataset.query(query, initNs=PREFIXES))) for query in queries]
        rdflib_queries = time.perf_counter() - started
    pyshacl: float | None = None
    same: bool | None = None
    if reference:
        sys.path.insert(0, str(ROOT))  # pySHACL, as the tests run it
        from tests.query.shacl_reference import pyshacl_results, result_keys

        graphs = kg.source_graphs()
        ours = check_shapes(kg, graphs, cadkg_shapes())
        started = time.perf_counter()
        theirs = pyshacl_results(kg, graphs)
        pyshacl = time.perf_counter() - started
        same = result_keys(ours) == result_keys(theirs)
    return {
        "triples": len(kg),
        "build": built - start,
        "semantic": checked - built,
        "shacl": validated - checked,
        "findings": len(findings),
        "semantic_findings": len(semantic),
        "rows": rows,
        "rdflib_rows": rdflib_rows,
        "cadkg_queries": cadkg_queries,
        "rdflib_queries": rdflib_queries,
        "pyshacl": pyshacl,
        "same": same,
        "rss": peak_rss_mib(),
    }


def measure(manifest: Path, wires: int, baseline: bool, reference: bool) -> dict[str, Any]:
    flags = ["baseline" if baseline else "alone", "reference" if reference else "alone"]
    command = [sys.executable, __file__, CHILD_FLAG, str(manifest), *flags]
    out = subprocess.run(command, check=False, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"{wires} wires: the validating process failed:\n{out.stderr}")
    result: dict[str, Any] = json.loads(out.stdout.strip().splitlines()[-1])
    return {"wires": wires, **result}


def row(r: dict[str, Any]) -> str:
    rows = "/".join(map(str, r["rows"]))
    rdflib_s = ratio = "—"
    if r["rdflib_queries"] is not None:
        rdflib_s = f"{r['rdflib_queries']:.3f}"
        ratio = f"{r['rdflib_queries'] / r['cadkg_queries']:.0f}×"
        if r["rdflib_rows"] != r["rows"]:
            rows += f" (rdflib {'/'.join(map(str, r['rdflib_rows']))})"
    total = r["build"] + r["semantic"] + r["shacl"]
    pyshacl = same = against = "—"
    if r["pyshacl"] is not None:
        pyshacl, against = f"{r['pyshacl']:.2f}", f"{r['pyshacl'] / r['shacl']:.0f}×"
        same = "yes" if r["same"] else "**no**"
    return (
        f"| {r['wires']:,} | {r['triples']:,} | {r['build']:.2f} | {r['semantic']:.2f} | {r['shacl']:.2f} "
        f"| {total:.2f} | {r['findings']} | {r['rss']:,.0f} | {r['cadkg_queries']:.3f} "
        f"| {rdflib_s} | {ratio} | {rows} | {(r['semantic'] + r['shacl']) / r['build']:.2f} "
        f"| {pyshacl} | {against} | {same} |"
    )


def summary(runs: dict[int, list[dict[str, Any]]], cabinet: bool) -> str:
    """Medians of each size's runs, and the targets (for the cabinet) judged on them."""
    lines = [
        "| runs | wires | reference loop s | build s | checks + shapes s | (checks + shapes) / build "
        "| target | verdict | SHACL s | pySHACL s |",
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for wires, rs in runs.items():
        ratios = [(r["semantic"] + r["shacl"]) / r["build"] for r in rs]
        target = TARGETS.get(wires) if cabinet else None
        bound = "—" if target is None else f"≤ {target:g}"
        lines.append(
            f"| {len(rs)} | {wires:,} | {spread([r['loop'] for r in rs])} "
            f"| {spread([r['build'] for r in rs])} "
            f"| {spread([r['semantic'] + r['shacl'] for r in rs])} | {spread(ratios)} "
            f"| {bound} "
            f"| {'—' if target is None else verdict(ratios, target, at_most=True)} "
            f"| {spread([r['shacl'] for r in rs])} "
            f"| {spread([r['pyshacl'] for r in rs if r['pyshacl'] is not None])} |"
        )
    return "\n".join(lines)


def main() -> int:
    if len(sys.argv) == 5 and sys.argv[1] == CHILD_FLAG:
        print(json.dumps(child(sys.argv[2], sys.argv[3] == "baseline", sys.argv[4] == "reference")))
        return 0
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--sizes", default="1000,5000,10000", help="wires per cell, comma separated")
    parser.add_argument("--cabinet", action="store_true", help="the complete cabinet, not the plain cell")
    parser.add_argument("--runs", type=int, default=1, help="validate each size this many times")
    parser.add_argument(
        "--rdflib-max-wires", type=int, default=1000, help="leave the rdflib baseline out above this size"
    )
    parser.add_argument(
        "--pyshacl-max-wires", type=int, default=10_000, help="leave pySHACL out above this size"
    )
    add_quick(parser, sizes="300")
    args = parse(parser)
    sizes = [int(size) for size in args.sizes.split(",")]
    import pyoxigraph
    import pyshacl
    import rdflib

    import cadkg

    print(
        f"Python {platform.python_version()}, cadkg {cadkg.__version__}, pyoxigraph "
        f"{pyoxigraph.__version__}, pySHACL {pyshacl.__version__}, rdflib {rdflib.__version__}; "
        f"{'complete cabinet' if args.cabinet else 'plain cell (ID table and connection list)'}\n"
    )
    print(
        "| wires | triples | build s | semantic checks s | SHACL s | validate s | findings "
        "| peak RSS MiB | check queries: cadkg s | rdflib s | ratio | rows "
        "| (checks + shapes) / build | pySHACL s | pySHACL / SHACL | same results |"
    )
    print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    runs: dict[int, list[dict[str, Any]]] = {}
    with tempfile.TemporaryDirectory(prefix="cadkg-validate-") as tmp:
        manifests = {
            wires: (write_cabinet if args.cabinet else write_cell)(Path(tmp) / str(wires), wires)
            for wires in sizes
        }
        for _ in range(max(1, args.runs)):
            for wires in sizes:
                loop = reference_loop_seconds()
                r = measure(
                    manifests[wires], wires, wires <= args.rdflib_max_wires, wires <= args.pyshacl_max_wires
                )
                runs.setdefault(wires, []).append({**r, "loop": loop})
                print(row(r), flush=True)
    print(f"\nMedians (lowest–highest) of {max(1, args.runs)} run(s) a size:\n")
    print(summary(runs, args.cabinet))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
