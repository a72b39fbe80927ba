"""What evaluating the endpoint's queries in worker processes costs a query that does not run away.

For each size a synthetic cell (``synthetic.write_cell``, as ``bench_build.py``) is built into a
store directory and opened read-only, as ``cadkg serve STORE`` opens it. Each query the endpoint
answers is then answered twice, alternately, ``--reps`` times each:

- **in process** (the baseline): :func:`cadkg.server.evaluation.answer` in this process, on the
  opened store: what the endpoint did before queries moved to workers (a thread evaluating
  the query and writing SPARQL JSON);
- **in a worker**: the same call through :class:`cadkg.query.workers.WorkerPool` (one warm
  worker on a snapshot of the store): the request pickled to the worker, evaluated there, the
  answer's bytes pickled back.

The queries are the named queries with parameters (as ``bench_build.py`` picks them), a
SELECT of 10,000 rows (the endpoint's row cap: the largest answer it sends) and an ASK. Figures
are medians with the spread (min–max) in milliseconds; the overhead is worker − in process,
the ratio worker / in process. Also timed: taking the snapshot, starting the workers (the
first time: the fork server too), and a runaway's kill until a fresh worker answers.

Usage::

    python benchmarks/bench_isolation.py [--sizes 1000,10000] [--reps 15]
"""

from __future__ import annotations

import argparse
import contextlib
import platform
import statistics
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_build import query_params
from synthetic import write_cell

ROW_CAP = 10_000
EXTRA = {
    "select-10000-rows": "SELECT ?w ?n WHERE { ?w ck:wireNumber ?n }",
    "ask": "ASK { ?w a ck:Wire }",
}
RUNAWAY = "SELECT (COUNT(*) AS ?n) WHERE { ?a ?b ?c . ?d ?e ?f . ?g ?h ?i }"


def _spread(values: Sequence[float]) -> str:
    return f"{statistics.median(values) * 1000:,.1f} ({min(values) * 1000:,.1f}–{max(values) * 1000:,.1f})"


def _timed(call: Callable[[], Any]) -> float:
    start = time.perf_counter()
    call()
    return time.perf_counter() - start


def measure(wires: int, reps: int, workdir: Path) -> None:
    import cadkg
    from cadkg.query.named import coerce_params, named_queries
    from cadkg.query.workers import WorkerPool
    from cadkg.server.evaluation import GRACE, QuerySpec, answer
    from cadkg.server.results import RESULT_FORMATS, NotAcceptableError

    manifest = write_cell(workdir / f"cell-{wires}", wires)
    store = workdir / f"store-{wires}"
    started = time.perf_counter()
    cadkg.build(manifest, store).close()
    built = time.perf_counter() - started
    kg = cadkg.open_store(store)
    params: dict[str, Any] = query_params(Path(manifest).parent / "lista-cablaggio.csv", wires)
    results, not_graph = RESULT_FORMATS["json"], NotAcceptableError("results only")
    specs: dict[str, QuerySpec] = {}
    for name, query in named_queries().items():
        if any(p.name not in params.get(name, {}) for p in query.params):
            continue  # a parameter this cell has no value for
        bindings = coerce_params(query, params.get(name, {}))
        specs[name] = QuerySpec(query.text, results, not_graph, ROW_CAP, bindings)
    for name, text in EXTRA.items():
        specs[name] = QuerySpec(text, results, not_graph, ROW_CAP)

    started = time.perf_counter()
    pool = WorkerPool(kg, 1, preload=("cadkg.server.evaluation",))
    snapshot = time.perf_counter() - started
    started = time.perf_counter()
    pool.prestart()
    start_workers = time.perf_counter() - started

    def in_process(spec: QuerySpec) -> Any:
        return answer(kg, spec, 300.0, time.monotonic() + 300)

    def in_worker(spec: QuerySpec) -> Any:
        args = (spec, 300.0, time.monotonic() + 300)
        return pool.call("cadkg.server.evaluation:answer", args, seconds=300.0)

    print(f"\n### {wires:,} wires ({len(kg):,} triples; built in {built:.1f} s)\n")
    print(f"- snapshot of the store for the workers: {snapshot * 1000:,.1f} ms")
    print(f"- starting the worker and waiting until it is ready: {start_workers * 1000:,.1f} ms\n")
    print("| query | answer KB | in process ms | in a worker ms | overhead ms | ratio |")
    print("|:---|---:|---:|---:|---:|---:|")
    for name, spec in specs.items():
        body = in_process(spec).body
        assert in_worker(spec).body == body, f"{name}: the worker answered otherwise"
        here: list[float] = []
        there: list[float] = []
        for _ in range(reps):
            here.append(_timed(lambda spec=spec: in_process(spec)))  # type: ignore[misc]
            there.append(_timed(lambda spec=spec: in_worker(spec)))  # type: ignore[misc]
        base, isolated = statistics.median(here), statistics.median(there)
        print(
            f"| {name} | {len(body) / 1024:,.1f} | {_spread(here)} | {_spread(there)} "
            f"| {(isolated - base) * 1000:,.1f} | {isolated / base:.2f} |"
        )
    started = time.perf_counter()
    at = time.monotonic() + 1.0
    with contextlib.suppress(cadkg.CadkgError):  # the TimeLimitError the endpoint answers 503
        runaway = (QuerySpec(RUNAWAY, results, not_graph, 1), 1.0, at)
        pool.call("cadkg.server.evaluation:answer", runaway, seconds=1.0, at=at, grace=GRACE)
    stopped = time.perf_counter() - started
    started = time.perf_counter()
    in_worker(specs["ask"])
    replaced = time.perf_counter() - started
    print(f"\n- a runaway with a 1 s limit: stopped and its worker killed after {stopped:.2f} s;")
    print(f"  the next query, on the fresh worker, answered in {replaced * 1000:,.1f} ms")
    pool.close()
    kg.close()


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="1000,10000", help="wires, comma separated")
    parser.add_argument("--reps", type=int, default=15)
    args = parser.parse_args(argv)
    print("## Queries in worker processes against in process\n")
    print(f"- CPython {platform.python_version()} on {platform.system()} {platform.machine()}")
    print(f"- {args.reps} runs of each, alternating; medians (min–max)")
    with tempfile.TemporaryDirectory(prefix="cadkg-bench-isolation-") as scratch:
        for wires in (int(s) for s in args.sizes.split(",")):
            measure(wires, args.reps, Path(scratch))
    return 0


if __name__ == "__main__":
    sys.exit(main())
