"""Build and query benchmark of cadkg on synthetic cabinets, against an rdflib baseline.

For each size (number of wires) a synthetic cell is written with
``benchmarks/synthetic.py`` (a WRI ID table and a 15-column "Lista cablaggio"; with
``--cabinet`` the complete cabinet, whose build also reads component models, a
terminal schema and an X3D scene and derives the geometry), and the script prints
Markdown tables of:

1. **cadkg build from the source files**: ``cadkg.build(manifest)`` in memory and
   ``cadkg.build(manifest, store_dir)`` on disk (flush, optimize and reopen
   included), wall-clock seconds, triples per second and peak RSS, with the part
   of the in-memory build spent reading and mapping the files, and the *overlap
   floor*: the shortest build that overlapping its Python side with the store's
   load could give on this machine (see ``overlap_floor``).
2. **Same triples, pyoxigraph vs rdflib**: the build's Python side alone
   (``cadkg.building.write_graphs``: readers, mapping, ``derive_cell`` and the
   derived graph) turns the files into N-Triples per named graph once (timed:
   "read+map+derive"); those bytes are then loaded, each in its own process,
   into a pyoxigraph store the way the in-memory build does (``Store.load`` per
   named graph) and into an ``rdflib.Dataset(default_union=True)`` (Memory store,
   ``graph.parse(data=..., format="nt")`` per named graph). Both also load the
   cadkg ontology into its graph. Build = read+map+derive + load for both; the
   ratio is rdflib build / cadkg build. The baseline therefore measures only the
   store: the Python side costs the same for both. rdflib's fastest in-process path is
   measured too (``baselines.job_rdflib_terms``: the same quads as rdflib terms added in
   bulk), and its ratio printed beside the parser's.
3. **The build against a bare bulk load of its quads**: ``cadkg.build(manifest, store_dir)``
   against pyoxigraph bulk-loading the same quads into a fresh on-disk store
   (``baselines.job_bulk_load``), in the same run.
4. **Named queries**: p50/p95 latency of every named query of cadkg, with
   parameters taken from the generated data, run through ``kg.named_query`` on
   the in-memory build and through ``ds.query(text, initBindings=...)`` on the
   rdflib dataset; every run fetches all rows into Python. A query whose first
   run exceeds the timeout (30 s) is stopped, not repeated, and shows "—": rdflib
   by SIGALRM, cadkg by killing the forked copy of the process that ran it.

With ``--runs N`` every size is measured N times (named queries in the first run only), and
a table gives the median of each figure with its lowest and highest; the targets are judged on
the medians.

Every build runs in its own process and reports its own peak resident set
(``VmHWM`` of ``/proc/self/status``; ``ru_maxrss`` where that is missing, which
on Linux also counts the parent's pages at exec), so one build does not inflate another.

Usage::

    python benchmarks/bench_build.py [--sizes 1000,10000,100000] [--reps 50] [--no-rdflib] [--runs 3]
    python benchmarks/bench_build.py --quick       # a smoke test (its settings: --help)
    python benchmarks/bench_build.py --cabinet     # the complete cabinet, derived graph included
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import select
import shutil
import signal
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from types import FrameType
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))

from baselines import job_bulk_load, job_rdflib_terms
from medians import spread, verdict
from quick import add_quick, parse
from synthetic import write_cabinet, write_cell

CHILD_FLAG = "--child-job"
TARGET_RATIO = 5.0
TARGET_BULK_RATIO = 1.0  # the goal of issue 43; 1.5 before, when the build was far inside it
TARGET_MEMORY_MIB = 24 * 1024
# "100k wires built in ≤ 10 s" was withdrawn: the build is within a few tenths of its store's
# own bulk load of the same quads, and that ratio is what is kept (benchmarks/README.md).
TARGETS = (
    f"≥ {TARGET_RATIO:g}× faster than the rdflib baseline, its fastest path (100k wires)",
    "1M wires build within 24 GiB",
    f"the build costs at most {TARGET_BULK_RATIO:g}× a bulk load of its own quads",
)

Json = dict[str, Any]


# -- measuring, in the child processes ------------------------------------------------


def peak_rss_mib() -> float:
    """Peak resident set of this process in MiB (VmHWM; ru_maxrss as a fallback)."""
    try:
        with Path("/proc/self/status").open(encoding="ascii") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024


class QueryTimeoutError(Exception):
    """A query ran past its time limit."""


@dataclass(frozen=True)
class QueryPlan:
    """How long to measure one query on one engine."""

    reps: int  # at most this many samples
    budget: float  # seconds of repetitions after the first run
    timeout: float  # the first run may take this long, else the query is not measured


@contextmanager
def time_limit(seconds: float) -> Iterator[None]:
    """Raise :class:`QueryTimeoutError` in the main thread after ``seconds`` (SIGALRM).

    Only interrupts Python code: used for rdflib, which is pure Python.
    """

    def expire(signum: int, frame: FrameType | None) -> None:
        raise QueryTimeoutError

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def first_run(run: Callable[[], int]) -> tuple[int, float]:
    """(rows, seconds) of one run of ``run``, which returns its row count."""
    started = time.perf_counter()
    rows = run()
    return rows, time.perf_counter() - started


def repeat(run: Callable[[], int], plan: QueryPlan, first_seconds: float) -> list[float]:
    """Latency samples in ms after a first run of ``first_seconds``.

    The first run is a warm-up, kept as a sample only when it took more than a second.
    Repetitions stop after ``plan.reps`` samples or ``plan.budget`` seconds.
    """
    samples = [first_seconds * 1000] if first_seconds > 1.0 else []
    budget_end = time.perf_counter() + plan.budget
    while len(samples) < plan.reps and time.perf_counter() < budget_end:
        started = time.perf_counter()
        run()
        samples.append((time.perf_counter() - started) * 1000)
    return samples


def measure_in_process(run: Callable[[], int], plan: QueryPlan) -> Json:
    """Samples of a pure-Python ``run``; the first run is cut off by SIGALRM at the timeout."""
    try:
        with time_limit(plan.timeout):
            rows, first = first_run(run)
    except QueryTimeoutError:
        return {"timeout": plan.timeout}
    return {"rows": rows, "samples": repeat(run, plan, first)}


def measure_forked(run: Callable[[], int], plan: QueryPlan) -> Json:
    """Samples of ``run`` in a forked copy of this process, killed if its first run times out.

    pyoxigraph evaluates a query in native code that a signal cannot interrupt, so the
    query runs in a child sharing the built store (copy on write) and the child is
    killed when its first run passes the timeout.
    """
    read_fd, write_fd = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: measure, report on the pipe, leave without cleanup
        os.close(read_fd)
        try:
            with os.fdopen(write_fd, "w") as pipe:
                rows, first = first_run(run)
                pipe.write(json.dumps({"rows": rows}) + "\n")
                pipe.flush()
                pipe.write(json.dumps({"samples": repeat(run, plan, first)}) + "\n")
        finally:
            os._exit(0)
    os.close(write_fd)
    with os.fdopen(read_fd) as pipe:
        ready, _, _ = select.select([pipe], [], [], plan.timeout)
        if not ready:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            return {"timeout": plan.timeout}
        head, tail = pipe.readline(), pipe.readline()
    os.waitpid(pid, 0)
    if not tail:
        raise RuntimeError("a forked query measurement died")
    return {**json.loads(head), **json.loads(tail)}


def runnable(queries: dict[str, Any], spec: Json) -> list[str]:
    """The named queries this cell has a value for every parameter of (the other profiles'
    queries, about guides or harnesses, have none in a synthetic cabinet)."""
    return [
        name
        for name, query in queries.items()
        if all(p.name in spec["params"].get(name, {}) for p in query.params)
    ]


def plan_of(spec: Json) -> QueryPlan:
    return QueryPlan(spec["reps"], spec["budget"], spec["timeout"])


def load_graph_files(workdir: Path) -> list[tuple[str, bytes]]:
    """The N-Triples per named graph written by the ``readmap`` job."""
    index = json.loads((workdir / "graphs.json").read_text(encoding="utf-8"))
    return [(entry["graph"], (workdir / entry["file"]).read_bytes()) for entry in index]


def job_cadkg_memory(spec: Json) -> Json:
    """``cadkg.build(manifest)`` in memory, then the named queries on it."""
    import cadkg
    from cadkg.query.named import named_queries

    started = time.perf_counter()
    kg = cadkg.build(spec["manifest"])
    seconds = time.perf_counter() - started
    result: Json = {
        "seconds": seconds,
        "triples": len(kg),
        "read_map_seconds": sum(r.seconds for r in kg.reports),
        "peak_mib": peak_rss_mib(),
        "queries": {},
    }
    for name in runnable(named_queries(), spec) if spec["queries"] else ():
        params = spec["params"].get(name, {})

        def run(name: str = name, params: Json = params) -> int:
            return len(kg.named_query(name, **params))

        result["queries"][name] = measure_forked(run, plan_of(spec))
    return result


def job_cadkg_disk(spec: Json) -> Json:
    """``cadkg.build(manifest, store_dir)``: an on-disk store, built atomically."""
    import cadkg

    store_dir = Path(spec["workdir"]) / "store"
    started = time.perf_counter()
    kg = cadkg.build(spec["manifest"], store_dir)
    seconds = time.perf_counter() - started
    result = {"seconds": seconds, "triples": len(kg), "peak_mib": peak_rss_mib()}
    kg.close()
    shutil.rmtree(store_dir, ignore_errors=True)
    return result


def job_readmap(spec: Json) -> Json:
    """The in-memory build's Python side alone (``cadkg.building.write_graphs``, streamed as the
    build streams it): files → N-Triples per named graph, the derived graph included, handed
    to a list instead of the loader and written out for the load jobs."""
    from cadkg.building import write_graphs
    from cadkg.ingest.manifest import load_manifest
    from cadkg.loading import paused_gc

    workdir = Path(spec["workdir"])
    manifest = load_manifest(spec["manifest"])
    chunks: dict[str, list[bytes]] = {}

    def sink(graph: str, chunk: bytes) -> None:
        chunks.setdefault(graph, []).append(chunk)

    started = time.perf_counter()
    with paused_gc():  # as the build runs
        write_graphs(manifest, sink, stream=True)
    seconds = time.perf_counter() - started
    graphs = [(graph, b"".join(parts)) for graph, parts in chunks.items()]
    index = []
    for number, (graph, ntriples) in enumerate(graphs):
        name = f"graph-{number}.nt"
        (workdir / name).write_bytes(ntriples)
        index.append({"graph": graph, "file": name})
    (workdir / "graphs.json").write_text(json.dumps(index), encoding="utf-8")
    return {
        "seconds": seconds,
        "triples": sum(data.count(b"\n") for _, data in graphs),
        "bytes": sum(len(data) for _, data in graphs),
        "peak_mib": peak_rss_mib(),
    }


def job_oxigraph_load(spec: Json) -> Json:
    """Load the N-Triples into a pyoxigraph store as the in-memory build does."""
    import pyoxigraph as ox

    from cadkg.ontology.terms import ONTOLOGY_IRI, ontology_path

    graphs = load_graph_files(Path(spec["workdir"]))
    started = time.perf_counter()
    store = ox.Store()
    store.load(path=ontology_path(), format=ox.RdfFormat.TURTLE, to_graph=ox.NamedNode(ONTOLOGY_IRI))
    for graph, data in graphs:
        store.load(data, ox.RdfFormat.N_TRIPLES, to_graph=ox.NamedNode(graph), lenient=True)
    seconds = time.perf_counter() - started
    return {"seconds": seconds, "triples": len(store), "peak_mib": peak_rss_mib()}


def job_rdflib(spec: Json) -> Json:
    """Load the N-Triples into an rdflib Dataset (Memory store), then the named queries."""
    from rdflib import Dataset, Literal, URIRef

    from cadkg.loading import paused_gc
    from cadkg.ontology.terms import ONTOLOGY_IRI, ontology_path
    from cadkg.query.named import named_queries

    graphs = load_graph_files(Path(spec["workdir"]))
    started = time.perf_counter()
    with paused_gc():  # as cadkg's build runs, so that neither pays for the collector
        ds = Dataset(default_union=True)
        ds.graph(URIRef(ONTOLOGY_IRI)).parse(str(ontology_path()), format="turtle")
        for graph, data in graphs:
            ds.graph(URIRef(graph)).parse(data=data, format="nt")
    seconds = time.perf_counter() - started
    names = [ONTOLOGY_IRI, *(graph for graph, _ in graphs)]
    triples = sum(len(ds.graph(URIRef(name))) for name in names)
    result: Json = {"seconds": seconds, "triples": triples, "peak_mib": peak_rss_mib(), "queries": {}}
    for name, query in named_queries().items() if spec["queries"] else ():
        if name not in runnable(named_queries(), spec):
            continue
        bindings = {k: Literal(v) for k, v in spec["params"].get(name, {}).items()}

        def run(text: str = query.text, bindings: Json = bindings) -> int:
            return len(list(ds.query(text, initBindings=bindings)))

        result["queries"][name] = measure_in_process(run, plan_of(spec))
    return result


def job_reference_loop(spec: Json) -> Json:
    """The reference loop alone, so that several processes can run it at once."""
    return {"seconds": reference_loop_seconds()}


JOBS: dict[str, Callable[[Json], Json]] = {
    "reference-loop": job_reference_loop,
    "cadkg-memory": job_cadkg_memory,
    "cadkg-disk": job_cadkg_disk,
    "readmap": job_readmap,
    "oxigraph-load": job_oxigraph_load,
    "rdflib": job_rdflib,
    "rdflib-terms": job_rdflib_terms,
    "bulk-load": job_bulk_load,
}


def child_main(job: str, spec_json: str) -> int:
    """Run one job and print its result as JSON on the last line of stdout."""
    result = JOBS[job](json.loads(spec_json))
    print(json.dumps(result))
    return 0


# -- orchestrating, in the parent process ------------------------------------------------


def run_jobs(job: str, spec: Json, copies: int = 1) -> list[Json]:
    """Run ``copies`` of ``job`` at once, each in a fresh Python process; their JSON results."""
    print(f"  {job}{f' ×{copies}' if copies > 1 else ''} ...", file=sys.stderr, flush=True)
    command = [sys.executable, str(Path(__file__).resolve()), CHILD_FLAG, job, json.dumps(spec)]
    running = [
        subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        for _ in range(copies)
    ]
    results = []
    for process in running:
        out, err = process.communicate()
        if process.returncode != 0:
            raise RuntimeError(f"benchmark job {job} failed ({process.returncode}):\n{err[-4000:]}")
        results.append(json.loads(out.strip().splitlines()[-1]))
    return results


def run_job(job: str, spec: Json) -> Json:
    """Run ``job`` in a fresh Python process and return its JSON result."""
    return run_jobs(job, spec)[0]


def parallel_throughput(rounds: int = 3) -> float:
    """How many times one core's work this machine does with two busy processes.

    A build maps on one core while pyoxigraph loads on another; where the two cores share
    their execution units, or other tenants share the machine, the pair does less than twice
    the work of one, and that bounds how much the overlap can save. The median of
    ``rounds`` alternating measurements, since both vary from minute to minute."""
    ratios = []
    for _ in range(rounds):
        alone = float(run_job("reference-loop", {})["seconds"])
        together = max(float(r["seconds"]) for r in run_jobs("reference-loop", {}, copies=2))
        ratios.append(2 * alone / together)
    return statistics.median(ratios)


def query_params(csv_path: Path, wires: int) -> dict[str, Json]:
    """Parameters of the named queries, from the middle data row of the connection list."""
    middle = 5 + wires // 2  # 4 preamble rows and the header come first
    cells: list[str] = []
    with csv_path.open(encoding="utf-8", newline="") as handle:
        for number, line in enumerate(handle):
            if number == middle:
                cells = line.rstrip("\r\n").split("\t")
                break
    label = cells[2].split(":")[0].lstrip("=+-")
    return {
        "pins-of-component": {"label": label},
        "wires-of-component": {"label": label},
        "wire-endpoints": {"wireNumber": cells[6]},
    }


@dataclass
class SizeResult:
    """Everything measured for one size."""

    wires: int
    generate_seconds: float
    params: dict[str, Json]
    memory: Json
    disk: Json
    readmap: Json | None = None
    oxigraph: Json | None = None
    rdflib: Json | None = None
    rdflib_terms: Json | None = None
    bulk: Json | None = None
    reference_loop: float | None = None
    notes: list[str] = field(default_factory=list)


@dataclass(frozen=True)
class Options:
    """What a run measures, from the command line."""

    sizes: tuple[int, ...]
    plan: QueryPlan
    with_rdflib: bool
    rdflib_max_wires: int
    cabinet: bool = False
    runs: int = 1

    @property
    def cell(self) -> str:
        """What is built, for the report's first line."""
        if self.cabinet:
            return (
                "the complete synthetic cabinet (`synthetic.py --cabinet`: ID table, component models, "
                "terminal schema, X3D scene, connection list, assignments; the derived graph included)"
            )
        return "the synthetic cell (`synthetic.py`: an ID table and a connection list)"


def measure_size(wires: int, workdir: Path, options: Options, queries: bool = True) -> SizeResult:
    """Generate the cell of ``wires`` wires and run every job on it (the named queries if ``queries``)."""
    print(f"{wires} wires:", file=sys.stderr, flush=True)
    celldir = workdir / f"cell-{wires}"
    started = time.perf_counter()
    manifest = (write_cabinet if options.cabinet else write_cell)(celldir, wires)
    generate_seconds = time.perf_counter() - started
    params = query_params(celldir / "lista-cablaggio.csv", wires)
    plan = options.plan
    spec = {
        "manifest": str(manifest),
        "workdir": str(celldir),
        "params": params,
        "reps": plan.reps,
        "budget": plan.budget,
        "timeout": plan.timeout,
        "queries": queries,
    }
    reference_loop = float(run_job("reference-loop", {})["seconds"])
    memory = run_job("cadkg-memory", spec)
    # Read+map and the load alone are what the build overlaps: the targets table needs them.
    readmap = run_job("readmap", spec)
    # The on-disk build and the bare bulk load of its quads one after the other: this
    # machine's speed drifts within minutes, and their ratio is a target.
    result = SizeResult(wires, generate_seconds, params, memory, run_job("cadkg-disk", spec))
    result.bulk = run_job("bulk-load", spec)
    result.reference_loop = reference_loop
    result.readmap = readmap
    result.oxigraph = run_job("oxigraph-load", spec)
    if not options.with_rdflib:
        result.notes.append("rdflib baseline not run (--no-rdflib)")
    elif wires > options.rdflib_max_wires:
        result.notes.append(
            f"rdflib baseline not run above {options.rdflib_max_wires} wires (--rdflib-max-wires)"
        )
    else:
        result.rdflib = run_job("rdflib", spec)
        result.rdflib_terms = run_job("rdflib-terms", spec)
    shutil.rmtree(celldir, ignore_errors=True)
    return result


# -- reporting ------------------------------------------------------------------------------


def table(header: Sequence[str], rows: Sequence[Sequence[str]], left: int = 0) -> str:
    """A Markdown table; the first ``left`` columns after the first are text (left aligned)."""
    align = ["---:" if i == 0 or i > left else ":---" for i in range(len(header))]
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(align) + "|"]
    lines += ["| " + " | ".join(row) + " |" for row in rows]
    return "\n".join(lines)


def fmt(value: float, digits: int = 2) -> str:
    return f"{value:,.{digits}f}"


def percentile(samples: Sequence[float], q: float) -> float:
    """The ``q`` percentile (0-100) of ``samples``, by linear interpolation."""
    ordered = sorted(samples)
    if len(ordered) == 1:
        return ordered[0]
    return statistics.quantiles(ordered, n=100, method="inclusive")[int(q) - 1]


def mem_total_mib() -> float | None:
    try:
        with Path("/proc/meminfo").open(encoding="ascii") as meminfo:
            return int(meminfo.readline().split()[1]) / 1024
    except (OSError, ValueError, IndexError):
        return None


def reference_loop_seconds(count: int = 20_000_000) -> float:
    """Seconds this interpreter takes for ``count`` integer additions in a loop.

    Printed with every report: a shared machine's speed differs from day to day, and build
    times of two runs compare only together with it."""
    started = time.perf_counter()
    total = 0
    for i in range(count):
        total += i
    return time.perf_counter() - started


def environment(throughput: float) -> str:
    """The machine, its speed today and library versions, as a Markdown list."""
    import pyoxigraph
    import rdflib

    import cadkg

    memory = mem_total_mib()
    return "\n".join(
        [
            f"- Python {platform.python_version()} on {platform.system()} {platform.machine()}, "
            f"{os.cpu_count()} CPU cores, " + (f"{memory / 1024:.1f} GiB RAM" if memory else "RAM unknown"),
            f"- cadkg {cadkg.__version__}, pyoxigraph {pyoxigraph.__version__}, rdflib {rdflib.__version__}",
            f"- reference loop (20 M Python integer additions), timed as this report is written: "
            f"{reference_loop_seconds():.2f} s",
            f"- two processes running the reference loop at once do {throughput:.2f}× the work of one",
        ]
    )


def overlap_floor(r: SizeResult, throughput: float) -> float | None:
    """The shortest in-memory build that overlapping the Python side with the load could give here.

    Both halves are measured alone, each on one core; run at once, two cores do
    ``throughput`` times the work of one, and neither half can finish before its own time."""
    if r.readmap is None or r.oxigraph is None:
        return None
    read_map, load = float(r.readmap["seconds"]), float(r.oxigraph["seconds"])
    # Above 2× the lone run was the one held up: two cores do at most twice one's work.
    return max((read_map + load) / min(throughput, 2.0), read_map, load)


def build_table(results: Sequence[SizeResult], throughput: float) -> str:
    """Table 1: cadkg.build from the source files, in memory and on disk."""
    rows = []
    for r in results:
        triples = r.memory["triples"]
        mem_s, disk_s = r.memory["seconds"], r.disk["seconds"]
        floor = overlap_floor(r, throughput)
        rows.append(
            [
                f"{r.wires:,}",
                f"{triples:,}",
                fmt(r.memory["read_map_seconds"]),
                fmt(mem_s),
                "—" if floor is None else fmt(floor),
                f"{triples / mem_s:,.0f}",
                fmt(r.memory["peak_mib"], 0),
                fmt(disk_s),
                f"{triples / disk_s:,.0f}",
                fmt(r.disk["peak_mib"], 0),
                fmt(r.generate_seconds),
            ]
        )
    header = [
        "wires",
        "triples",
        "of which read+map s",
        "in-memory s",
        "overlap floor s",
        "triples/s",
        "peak RSS MiB",
        "on-disk s",
        "triples/s",
        "peak RSS MiB",
        "(generate files s)",
    ]
    return table(header, rows)


def _ratio(numerator: float | None, denominator: float) -> str:
    return "—" if numerator is None else f"{numerator / denominator:.1f}×"


def baseline_table(results: Sequence[SizeResult]) -> str:
    """Table 2: the same N-Triples loaded into pyoxigraph and into rdflib (parsed, and as terms)."""
    header = [
        "wires",
        "triples",
        "N-Triples MiB",
        "read+map+derive s",
        "pyoxigraph load s",
        "rdflib parse s",
        "rdflib terms s",
        "cadkg build s",
        "rdflib build (parse) s",
        "rdflib build (terms) s",
        "build ratio rdflib/cadkg (parse)",
        "build ratio (terms)",
        "load ratio (parse)",
        "load ratio (terms)",
        "pyoxigraph peak RSS MiB",
        "rdflib peak RSS MiB (parse)",
        "rdflib peak RSS MiB (terms)",
    ]
    rows = []
    for r in results:
        if r.readmap is None or r.oxigraph is None:
            rows.append([f"{r.wires:,}", *["—"] * (len(header) - 1)])
            continue
        read_map, load = r.readmap["seconds"], r.oxigraph["seconds"]
        cadkg_build = read_map + load
        parse = r.rdflib["seconds"] if r.rdflib else None
        terms = r.rdflib_terms["seconds"] if r.rdflib_terms else None
        triples = f"{r.oxigraph['triples']:,}"
        for name, other in (("rdflib", r.rdflib), ("rdflib terms", r.rdflib_terms)):
            if other is not None and other["triples"] != r.oxigraph["triples"]:
                triples += f" ({name} {other['triples']:,})"
        rows.append(
            [
                f"{r.wires:,}",
                triples,
                fmt(r.readmap["bytes"] / 2**20, 0),
                fmt(read_map),
                fmt(load),
                "—" if parse is None else fmt(parse),
                "—" if terms is None else fmt(terms),
                fmt(cadkg_build),
                "—" if parse is None else fmt(read_map + parse),
                "—" if terms is None else fmt(read_map + terms),
                _ratio(None if parse is None else read_map + parse, cadkg_build),
                _ratio(None if terms is None else read_map + terms, cadkg_build),
                _ratio(parse, load),
                _ratio(terms, load),
                fmt(r.oxigraph["peak_mib"], 0),
                "—" if r.rdflib is None else fmt(r.rdflib["peak_mib"], 0),
                "—" if r.rdflib_terms is None else fmt(r.rdflib_terms["peak_mib"], 0),
            ]
        )
    return table(header, rows)


def bulk_table(results: Sequence[SizeResult]) -> str:
    """Table 3: the on-disk build against a bare bulk load of the same quads."""
    rows = []
    for r in results:
        if r.bulk is None:
            continue
        quads = f"{r.bulk['triples']:,}"
        if r.bulk["triples"] != r.disk["triples"]:
            quads += f" (the build {r.disk['triples']:,})"
        rows.append(
            [
                f"{r.wires:,}",
                fmt(r.disk["seconds"]),
                fmt(r.bulk["seconds"]),
                f"{r.disk['seconds'] / r.bulk['seconds']:.2f}×",
                quads,
                fmt(r.bulk["peak_mib"], 0),
            ]
        )
    header = [
        "wires",
        "on-disk build s",
        "bulk load s",
        "build / bulk load",
        "quads",
        "bulk load peak RSS MiB",
    ]
    return table(header, rows)


def _fastest_rdflib_ratio(r: SizeResult) -> float | None:
    """rdflib's build over cadkg's, rdflib taking its faster path (parse or terms)."""
    if r.readmap is None or r.oxigraph is None:
        return None
    loads = [j["seconds"] for j in (r.rdflib, r.rdflib_terms) if j is not None]
    if not loads:
        return None
    read_map = r.readmap["seconds"]
    return (read_map + min(loads)) / (read_map + r.oxigraph["seconds"])


def _by_size(runs: Sequence[Sequence[SizeResult]]) -> dict[int, list[SizeResult]]:
    sizes: dict[int, list[SizeResult]] = {}
    for run in runs:
        for r in run:
            sizes.setdefault(r.wires, []).append(r)
    return sizes


def medians_table(runs: Sequence[Sequence[SizeResult]]) -> str:
    """The key figures of every run of each size: median (lowest–highest)."""
    rows = []
    for wires, rs in _by_size(runs).items():

        def of(
            pick: Callable[[SizeResult], float | None],
            digits: int = 2,
            suffix: str = "",
            rs: list[SizeResult] = rs,
        ) -> str:
            values = [v for v in map(pick, rs) if v is not None]
            return spread(values, digits, suffix)

        def rdflib_ratio(r: SizeResult, job: Json | None) -> float | None:
            if job is None or r.readmap is None or r.oxigraph is None:
                return None
            read_map = r.readmap["seconds"]
            return float((read_map + job["seconds"]) / (read_map + r.oxigraph["seconds"]))

        rows.append(
            [
                f"{wires:,}",
                str(len(rs)),
                of(lambda r: r.reference_loop),
                of(lambda r: r.memory["seconds"]),
                of(lambda r: r.disk["seconds"]),
                of(lambda r: r.bulk["seconds"] if r.bulk else None),
                of(lambda r: r.disk["seconds"] / r.bulk["seconds"] if r.bulk else None, 2, "×"),
                of(lambda r: r.readmap["seconds"] if r.readmap else None),
                of(lambda r: r.oxigraph["seconds"] if r.oxigraph else None),
                of(lambda r: rdflib_ratio(r, r.rdflib), 1, "×"),
                of(lambda r: rdflib_ratio(r, r.rdflib_terms), 1, "×"),
            ]
        )
    header = [
        "wires",
        "runs",
        "reference loop s",
        "in-memory build s",
        "on-disk build s",
        "bare bulk load s",
        "on-disk build / bulk load",
        "read+map+derive s",
        "pyoxigraph load s",
        "rdflib build ratio (parse)",
        "rdflib build ratio (terms)",
    ]
    return table(header, rows)


def latency_cells(measured: Json | None) -> tuple[str, str, str, float | None]:
    """(n, p50, p95, p50 value) of one query on one engine."""
    if measured is None:
        return "", "—", "—", None
    if "timeout" in measured:
        return "0", "—", "—", None
    samples = measured["samples"]
    if not samples:
        return "0", "—", "—", None
    p50 = percentile(samples, 50)
    return str(len(samples)), fmt(p50), fmt(percentile(samples, 95)), p50


def rows_cell(ours: Json, theirs: Json | None) -> str:
    """The row count of cadkg's result, and rdflib's when it differs."""
    cell = str(ours["rows"]) if "rows" in ours else "—"
    if theirs is not None and "rows" in theirs and theirs["rows"] != ours.get("rows"):
        cell += f" (rdflib {theirs['rows']})"
    return cell


def query_table(results: Sequence[SizeResult]) -> str:
    """Table 3: named query latency, cadkg vs rdflib."""
    rows = []
    for r in results:
        for name, ours in r.memory["queries"].items():
            theirs = r.rdflib["queries"][name] if r.rdflib else None
            n1, p50a, p95a, ours_p50 = latency_cells(ours)
            n2, p50b, p95b, theirs_p50 = latency_cells(theirs)
            ratio = f"{theirs_p50 / ours_p50:.0f}×" if ours_p50 and theirs_p50 else "—"
            params = ", ".join(f"{k}={v}" for k, v in r.params.get(name, {}).items())
            rows.append(
                [
                    f"{r.wires:,}",
                    name,
                    params,
                    rows_cell(ours, theirs),
                    n1,
                    p50a,
                    p95a,
                    n2 or "—",
                    p50b,
                    p95b,
                    ratio,
                ]
            )
    header = [
        "wires",
        "query",
        "parameters",
        "rows",
        "n",
        "cadkg p50 ms",
        "cadkg p95 ms",
        "n",
        "rdflib p50 ms",
        "rdflib p95 ms",
        "ratio p50",
    ]
    return table(header, rows, left=2)


def timeout_notes(results: Sequence[SizeResult]) -> list[str]:
    """Why a query shows "—": its first run passed the timeout."""
    notes = []
    for r in results:
        for engine, measured in (("cadkg", r.memory), ("rdflib", r.rdflib)):
            for name, query in (measured or {}).get("queries", {}).items():
                if "timeout" in query:
                    notes.append(
                        f"{r.wires:,} wires: {engine} `{name}` not measured: its first "
                        f"run took over {query['timeout']:g} s and was stopped"
                    )
    return notes


def targets_table(runs: Sequence[Sequence[SizeResult]]) -> str:
    """The targets, decided by the medians of the runs."""
    sizes = _by_size(runs)
    rows = []
    r100k = sizes.get(100_000, [])
    ratios = [x for x in map(_fastest_rdflib_ratio, r100k) if x is not None]
    if not r100k:
        rows.append([TARGETS[0], "not measured (no 100000 size in this run)", "—"])
    elif not ratios:
        rows.append([TARGETS[0], "rdflib baseline not run", "—"])
    else:
        rows.append(
            [
                TARGETS[0],
                f"build ratio {spread(ratios, 1, '×')} against rdflib's faster path, of {len(ratios)} run(s)",
                verdict(ratios, TARGET_RATIO, at_most=False),
            ]
        )
    r1m = sizes.get(1_000_000, [])
    if not r1m:
        rows.append([TARGETS[1], "not measured (no 1000000 size in this run)", "—"])
    else:
        peaks = [max(r.memory["peak_mib"], r.disk["peak_mib"]) / 1024 for r in r1m]
        figure = f"peak RSS {spread(peaks, 2, ' GiB')}, the larger of in memory and on disk"
        rows.append([TARGETS[1], figure, verdict(peaks, TARGET_MEMORY_MIB / 1024, at_most=True)])
    for wires, rs in sizes.items():
        bulk = [r.disk["seconds"] / r.bulk["seconds"] for r in rs if r.bulk]
        if bulk:
            figure = f"{wires:,} wires: on-disk build / bare bulk load {spread(bulk, 2, '×')}"
            figure += f", of {len(bulk)} run(s)"
            rows.append([TARGETS[2], figure, verdict(bulk, TARGET_BULK_RATIO, at_most=True)])
    return table(["target", "measured: median (lowest–highest)", "verdict"], rows, left=3)


def report(runs: Sequence[Sequence[SizeResult]], plan: QueryPlan, throughput: float, cell: str) -> str:
    """The whole Markdown report of the runs on ``cell`` (tables of the first run, then the
    medians of all); ``throughput`` is :func:`parallel_throughput`'s."""
    results = runs[0]
    notes = [f"- {r.wires:,} wires: {n}" for r in results for n in r.notes]
    notes += [f"- {n}" for n in timeout_notes(results)]
    first = " (the first run)" if len(runs) > 1 else ""
    parts = [
        f"Built: {cell}.",
        "## Environment",
        environment(throughput),
        f"## Build from the source files (cadkg.build){first}",
        build_method(throughput),
        build_table(results, throughput),
        f"## Same triples: pyoxigraph vs rdflib (read, map and derive once, then load){first}",
        baseline_table(results),
        f"## The build against a bare bulk load of its quads (on disk){first}",
        bulk_table(results),
        "## Named queries (the first run)" if first else "## Named queries",
        query_method(plan),
        query_table(results),
        f"## Medians of {len(runs)} run(s): median (lowest–highest)",
        medians_table(runs),
        "## Targets",
        targets_table(runs),
    ]
    if notes:
        parts += ["## Notes", "\n".join(notes)]
    return "\n\n".join(parts) + "\n"


def build_method(throughput: float) -> str:
    return (
        "*overlap floor*: the in-memory build maps the files on one core while pyoxigraph loads "
        "on the other, so it cannot finish before either half measured alone (table 2), nor before "
        f"their sum divided by what two busy cores do here ({throughput:.2f}× one)."
    )


def query_method(plan: QueryPlan) -> str:
    return (
        f"Up to {plan.reps} timed runs per query and engine after a warm-up run, stopped after "
        f"{plan.budget:g} s; a query whose first run takes over {plan.timeout:g} s is not measured "
        '(n = 0, "—"). cadkg: `kg.named_query(name, **params)` on the in-memory build, rows '
        "converted to Python values. rdflib: `ds.query(text, initBindings={var: Literal(value)})`, "
        "all rows fetched. *rows* is the number of result rows (cadkg; rdflib's in brackets when "
        "it differs)."
    )


def parse_args(argv: Sequence[str] | None) -> Options:
    parser = argparse.ArgumentParser(description="Build and query benchmark of cadkg vs rdflib.")
    parser.add_argument(
        "--sizes",
        default="1000,10000,100000",
        help="comma-separated numbers of wires (default 1000,10000,100000)",
    )
    parser.add_argument("--reps", type=int, default=50, help="repetitions per query (default 50)")
    parser.add_argument("--no-rdflib", action="store_true", help="skip the rdflib baseline")
    parser.add_argument(
        "--cabinet",
        action="store_true",
        help="build the complete cabinet (synthetic.py --cabinet) instead of the plain cell",
    )
    parser.add_argument(
        "--rdflib-max-wires",
        type=int,
        default=None,
        help="skip the rdflib baseline above this size (default 200000; 10000 with --cabinet, "
        "whose 100k-wire graph of 21 M triples rdflib cannot hold in 24 GiB)",
    )
    parser.add_argument(
        "--timeout", type=float, default=30.0, help="seconds a query's first run may take (default 30)"
    )
    parser.add_argument(
        "--budget", type=float, default=15.0, help="seconds of repetitions per query and engine (default 15)"
    )
    parser.add_argument(
        "--runs", type=int, default=1, help="measure each size this many times (queries in the first only)"
    )
    add_quick(parser, sizes="1000", reps=2, timeout=1.0, budget=0.5)
    args = parse(parser, argv)
    return Options(
        sizes=tuple(int(s.replace("_", "")) for s in args.sizes.split(",") if s.strip()),
        plan=QueryPlan(max(1, args.reps), args.budget, args.timeout),
        with_rdflib=not args.no_rdflib,
        rdflib_max_wires=args.rdflib_max_wires
        if args.rdflib_max_wires is not None
        else 10_000
        if args.cabinet
        else 200_000,
        cabinet=args.cabinet,
        runs=max(1, args.runs),
    )


def main(argv: Sequence[str] | None = None) -> int:
    options = parse_args(argv)
    workdir = Path(tempfile.mkdtemp(prefix="cadkg-bench-"))
    started = time.perf_counter()
    try:
        throughput = parallel_throughput()
        runs = [
            [measure_size(wires, workdir, options, queries=run == 0) for wires in options.sizes]
            for run in range(options.runs)
        ]
    finally:
        shutil.rmtree(workdir, ignore_errors=True)
    print(report(runs, options.plan, throughput, options.cell))
    print(f"(run took {time.perf_counter() - started:.0f} s)")
    return 0


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == CHILD_FLAG:
        raise SystemExit(child_main(sys.argv[2], sys.argv[3]))
    raise SystemExit(main())
