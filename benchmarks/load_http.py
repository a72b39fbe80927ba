"""Load test of ``cadkg serve``: concurrent clients issuing the named queries, with a reload.

A synthetic cell (``benchmarks/synthetic.py``, two files, like ``bench_build.py``) is built
into a store directory, and a copy of its generation under another name is kept aside, both
before the clock starts. ``cadkg serve`` then serves the store on a free loopback port, in
its own process. Every named query the cell has parameter values for is asked once, all at
once (their cold times are reported; the answers fill the server's cache, as a day's first
users would). Then ``--clients`` clients (one keep-alive connection each, asyncio + httpx, in
this process) issue those queries in turn (``GET /api/queries/<name>?...``, SPARQL JSON),
each client starting at another query, for ``--seconds`` seconds, and on until an answer has
come from the new generation (at most four times ``--seconds`` in all). No request starts
after that; those in flight are awaited (each at most the server's time limit plus 30 s).

At ``--reload-at`` seconds the spare generation is moved into the served directory,
``CURRENT`` is switched to it by an atomic rename and the old generation's files are deleted,
exactly as the end of ``cadkg build`` does; the server's watch (``--watch 0.5``) opens it,
recomputes its recent answers on it, and swaps it in. Building the cell again during the load
would take longer than the run (40 s and more at 100k wires on two cores): only the switch
happens under load.

A request counts as an error unless it answers 200 with SPARQL JSON whose variables and row
count are those of the query's answer before the clock (both generations hold the same cell).
The script prints Markdown tables and exits 1 on any error, or when no answer came from the
new generation. Only loopback is used; the run is bounded in time.

Usage::

    python benchmarks/load_http.py [--wires 100000] [--clients 50] [--seconds 30] [--reload-at 15]
                                   [--workers 4] [--timeout 60] [--cache-mb 64 | --no-cache]
    python benchmarks/load_http.py --quick     # a smoke test (its settings: --help)
"""

from __future__ import annotations

import argparse
import asyncio
import hashlib
import json
import os
import platform
import shutil
import socket
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import httpx

sys.path.insert(0, str(Path(__file__).resolve().parent))

from bench_build import query_params
from cadkg.query.named import named_queries
from quick import add_quick, parse
from synthetic import write_cell_files

SRJ = "application/sparql-results+json"


@dataclass
class Sample:
    query: str
    started: float  # seconds since the load began
    seconds: float
    status: int
    generation: str
    error: str = ""


@dataclass
class Run:
    samples: list[Sample] = field(default_factory=list)
    rows: dict[str, int] = field(default_factory=dict)
    variables: dict[str, list[str]] = field(default_factory=dict)
    switched_at: float | None = None
    old: str = ""
    new: str = ""
    new_answered_at: float | None = None
    warmup: dict[str, float] = field(default_factory=dict)
    checked: dict[str, set[bytes]] = field(default_factory=dict)

    def check(self, name: str, body: bytes) -> str:
        """Why an answer is wrong ("" when right): its variables and row count must be those of the
        query's answer before the clock. A body seen before was checked then; parsing every
        answer again would make the clients, not the server, the bottleneck."""
        digest = hashlib.sha1(body).digest()
        if digest in self.checked.get(name, set()):
            return ""
        try:
            data = json.loads(body)
            rows, variables = len(data["results"]["bindings"]), data["head"]["vars"]
        except (ValueError, KeyError, TypeError) as err:
            return f"not SPARQL JSON: {err}"
        if variables != self.variables[name] or rows != self.rows[name]:
            return f"{rows} rows {variables}, expected {self.rows[name]} rows {self.variables[name]}"
        self.checked.setdefault(name, set()).add(digest)
        return ""

    def done(self, now: float, until: float, limit: float) -> bool:
        """Past ``until`` and the reload has shown, or past ``limit`` in any case."""
        if now >= limit:
            return True
        return now >= until and self.new_answered_at is not None


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


def build_store(manifest: Path, directory: Path) -> float:
    """``cadkg build`` the manifest into ``directory``; returns the seconds taken."""
    started = time.perf_counter()
    command = [sys.executable, "-m", "cadkg.cli", "build", str(manifest), "--store", str(directory)]
    done = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, check=False)
    if done.returncode != 0:
        raise SystemExit(f"cadkg build failed: {done.stderr[-2000:]}")
    return time.perf_counter() - started


def copy_store(source: Path, directory: Path) -> float:
    """A copy of the live generation of an existing store (built from the same cell); returns seconds."""
    started = time.perf_counter()
    current = (source / "CURRENT").read_text(encoding="utf-8").strip()
    directory.mkdir(parents=True)
    shutil.copytree(source / current, directory / current)
    (directory / "CURRENT").write_text(current + "\n", encoding="utf-8")
    return time.perf_counter() - started


def spare_generation(store: Path, spare: Path) -> Path:
    """A second generation for the reload: a copy of the built one under a new name."""
    current = (store / "CURRENT").read_text(encoding="utf-8").strip()
    target = spare / f"{current}-again"
    shutil.copytree(store / current, target)
    return target


def switch_generation(store: Path, generation: Path) -> tuple[str, str]:
    """Move ``generation`` into ``store`` and switch to it as the end of ``cadkg build`` does:
    ``CURRENT`` replaced by one atomic rename, then the old generation deleted."""
    old = (store / "CURRENT").read_text(encoding="utf-8").strip()
    new = generation.name
    generation.rename(store / new)
    pointer = store / f".CURRENT.{new}"
    pointer.write_text(new + "\n", encoding="utf-8")
    pointer.replace(store / "CURRENT")
    shutil.rmtree(store / old, ignore_errors=True)
    return old, new


def start_server(store: Path, port: int, args: argparse.Namespace) -> subprocess.Popen[str]:
    command = [
        sys.executable, "-m", "cadkg.cli", "serve", str(store), "--port", str(port),
        "--workers", str(args.workers), "--timeout", str(args.timeout), "--watch", "0.5",
        "--cache-mb", "0" if args.no_cache else str(args.cache_mb),
    ]  # fmt: skip
    return subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)


def wait_ready(base: str, process: subprocess.Popen[str], seconds: float = 120) -> dict[str, Any]:
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if process.poll() is not None:
            raise SystemExit(f"cadkg serve exited: {process.stderr.read() if process.stderr else ''}")
        try:
            response = httpx.get(f"{base}/api/info", timeout=60)
            if response.status_code == 200:
                info: dict[str, Any] = response.json()
                return info
        except httpx.TransportError:
            pass
        time.sleep(0.2)
    raise SystemExit("cadkg serve did not answer in time")


async def client(
    index: int,
    base: str,
    requests: Sequence[tuple[str, dict[str, str]]],
    run: Run,
    t0: float,
    until: float,
    limit: float,
    timeout: float,
) -> None:
    async with httpx.AsyncClient(
        base_url=base, timeout=timeout, limits=httpx.Limits(max_connections=1)
    ) as http:
        position = index
        while not run.done(time.perf_counter() - t0, until, limit):
            name, params = requests[position % len(requests)]
            position += 1
            started = time.perf_counter()
            status, generation, error = 0, "", ""
            try:
                response = await http.get(f"/api/queries/{name}", params=params, headers={"Accept": SRJ})
                status, generation = response.status_code, response.headers.get("x-cadkg-generation", "")
                if status != 200:
                    error = f"{status}: {response.text[:200]}"
                else:
                    error = run.check(name, response.content)
            except (httpx.HTTPError, ValueError, KeyError) as err:
                error = f"{type(err).__name__}: {err}"
            ended = time.perf_counter()
            run.samples.append(Sample(name, started - t0, ended - started, status, generation, error))
            if run.new and generation == run.new and run.new_answered_at is None:
                run.new_answered_at = ended - t0


async def reloader(store: Path, generation: Path, run: Run, t0: float, at: float) -> None:
    await asyncio.sleep(max(at - (time.perf_counter() - t0), 0))
    run.old, run.new = await asyncio.to_thread(switch_generation, store, generation)
    run.switched_at = time.perf_counter() - t0


async def warm_up(
    base: str, requests: Sequence[tuple[str, dict[str, str]]], run: Run, timeout: float
) -> None:
    """Each query once, all at once, before the clock: their cold times, and a warm cache."""

    async def one(name: str, params: dict[str, str]) -> None:
        async with httpx.AsyncClient(base_url=base, timeout=timeout) as http:
            started = time.perf_counter()
            response = await http.get(f"/api/queries/{name}", params=params, headers={"Accept": SRJ})
            if response.status_code != 200:
                raise SystemExit(f"warm-up: {name} answered {response.status_code}: {response.text[:300]}")
            data = response.json()
            run.warmup[name] = time.perf_counter() - started
            run.rows[name] = len(data["results"]["bindings"])
            run.variables[name] = data["head"]["vars"]

    await asyncio.gather(*(one(name, params) for name, params in requests))


async def load(
    base: str, store: Path, generation: Path, args: argparse.Namespace, params: dict[str, Any]
) -> Run:
    requests = [(name, {k: str(v) for k, v in params.get(name, {}).items()}) for name in issued(params)]
    run = Run()
    await warm_up(base, requests, run, args.timeout + 30)
    t0 = time.perf_counter()
    # Long enough for the reload to recompute every cached answer once (each within the time limit).
    limit = max(4 * args.seconds, args.reload_at + 2 * args.timeout + 30)
    tasks = [
        client(i, base, requests, run, t0, args.seconds, limit, args.timeout + 30)
        for i in range(args.clients)
    ]
    await asyncio.gather(*tasks, reloader(store, generation, run, t0, args.reload_at))
    return run


def issued(params: dict[str, Any]) -> list[str]:
    """The named queries a client issues: those without parameters, and those the cell gives values for."""
    return [
        name
        for name, query in named_queries().items()
        if all(p.name in params.get(name, {}) for p in query.params)
    ]


def percentile(values: Sequence[float], q: float) -> float:
    if not values:
        return float("nan")
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, max(0, round(q / 100 * len(ordered) + 0.5) - 1))]


def md_row(*cells: object) -> None:
    print("| " + " | ".join(str(c) for c in cells) + " |")


def ms(seconds: float) -> str:
    return f"{seconds * 1000:,.1f}"


def report(
    run: Run,
    args: argparse.Namespace,
    info: dict[str, Any],
    build_seconds: float,
    wall: float,
    params: dict[str, Any],
) -> int:
    samples = run.samples
    errors = [s for s in samples if s.error]
    latencies = [s.seconds for s in samples]
    span = max((s.started + s.seconds for s in samples), default=0.0)
    print("#### Setup\n")
    print(f"- {platform.python_implementation()} {platform.python_version()} on {platform.system()} "
          f"{platform.machine()}, {os.cpu_count()} CPU cores")  # fmt: skip
    made = "copied from --store" if args.store is not None else "built"
    print(f"- synthetic cell: {args.wires:,} wires, {info['triples']:,} triples; store {made} in "
          f"{build_seconds:.1f} s, before the clock")  # fmt: skip
    cache = "off" if args.no_cache else f"{args.cache_mb} MiB"
    print(f"- `cadkg serve`: {args.workers} query workers, time limit {args.timeout:g} s, "
          f"10,000-row cap, answer cache {cache}, watch 0.5 s")  # fmt: skip
    print(f"- {args.clients} clients for {args.seconds:g} s (and on until the new generation answers), "
          f"each issuing the {len(issued(params))} named queries in turn; generation switched at "
          f"{args.reload_at:g} s")  # fmt: skip
    skipped = sorted(set(named_queries()) - set(issued(params)))
    if skipped:
        print(f"- not issued (a parameter this cell has no value for): {', '.join(skipped)}")
    print()
    print("#### Before the clock: each query once, all at once (cold)\n")
    print("| query | rows | first answer ms |")
    print("|:---|---:|---:|")
    for name in issued(params):
        md_row(name, run.rows.get(name, "—"), ms(run.warmup.get(name, float("nan"))))
    print()
    print("#### Overall\n")
    print("| requests | errors | throughput req/s | p50 ms | p90 ms | p99 ms | max ms | last answer at s |")
    print("|---:|---:|---:|---:|---:|---:|---:|---:|")
    throughput = len(samples) / span if span else 0.0
    md_row(
        f"{len(samples):,}",
        len(errors),
        f"{throughput:,.1f}",
        ms(percentile(latencies, 50)),
        ms(percentile(latencies, 90)),
        ms(percentile(latencies, 99)),
        ms(max(latencies, default=0)),
        f"{span:.1f}",
    )
    print()
    print("#### Per named query\n")
    print("| query | parameters | rows | requests | p50 ms | p99 ms | max ms |")
    print("|:---|:---|---:|---:|---:|---:|---:|")
    for name in issued(params):
        mine = [s.seconds for s in samples if s.query == name]
        shown = ", ".join(f"{k}={v}" for k, v in params.get(name, {}).items())
        md_row(
            name,
            shown,
            run.rows.get(name, "—"),
            f"{len(mine):,}",
            ms(percentile(mine, 50)),
            ms(percentile(mine, 99)),
            ms(max(mine, default=0)),
        )
    print()
    print("#### Reload under load\n")
    switched = run.switched_at if run.switched_at is not None else float("nan")
    by_old = [s for s in samples if s.generation == run.old]
    by_new = [s for s in samples if s.generation == run.new]
    first_new = run.new_answered_at if run.new_answered_at is not None else float("nan")
    after = [s for s in by_old if s.started >= switched]
    print("| generation switched at s | first answer from the new one at s | answered by the old | "
          "by the new | by the old, sent after the switch | errors |")  # fmt: skip
    print("|---:|---:|---:|---:|---:|---:|")
    md_row(f"{switched:.2f}", f"{first_new:.2f}", f"{len(by_old):,}", f"{len(by_new):,}", f"{len(after):,}",
           len(errors))  # fmt: skip
    print()
    print(f"Generations: `{run.old}` → `{run.new}`. Wall time of the load phase: {wall:.1f} s.\n")
    for error in errors[:10]:
        print(f"- error: {error.query} at {error.started:.2f} s: {error.error}")
    if errors:
        print(f"\nFAILED: {len(errors)} of {len(samples)} requests failed")
        return 1
    if not by_new:
        print("\nFAILED: no answer came from the new generation")
        return 1
    print(f"OK: {len(samples):,} requests, 0 errors")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--wires", type=int, default=100_000)
    parser.add_argument("--clients", type=int, default=50)
    parser.add_argument("--seconds", type=float, default=30.0)
    parser.add_argument("--reload-at", type=float, default=None, help="default: half of --seconds")
    parser.add_argument("--workers", type=int, default=4)
    parser.add_argument("--timeout", type=float, default=60.0, help="the server's time limit")
    parser.add_argument("--cache-mb", type=int, default=64)
    parser.add_argument("--no-cache", action="store_true", help="serve without the answer cache")
    add_quick(parser, wires=1000, clients=10, seconds=4.0)
    parser.add_argument(
        "--store",
        type=Path,
        default=None,
        help="copy this store (built from the synthetic cell of --wires, seed 0) instead of building",
    )
    args = parse(parser, argv)
    if args.reload_at is None:
        args.reload_at = args.seconds / 2
    if not 0 < args.reload_at < args.seconds or args.clients < 1 or args.wires < 10:
        parser.error("need 0 < --reload-at < --seconds, --clients ≥ 1, --wires ≥ 10")
    with tempfile.TemporaryDirectory(prefix="cadkg-load-") as scratch:
        root = Path(scratch)
        files = write_cell_files(root / "cell", args.wires)
        params = query_params(files.connection_list, args.wires)
        store, spare = root / "store", root / "spare"
        if args.store is not None:
            build_seconds = copy_store(args.store, store)
        else:
            build_seconds = build_store(files.manifest, store)
        spare.mkdir()
        generation = spare_generation(store, spare)
        port = free_port()
        base = f"http://127.0.0.1:{port}"
        server = start_server(store, port, args)
        try:
            info = wait_ready(base, server)
            started = time.perf_counter()
            run = asyncio.run(load(base, store, generation, args, params))
            wall = time.perf_counter() - started
        finally:
            server.terminate()
            try:
                server.wait(30)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait(10)
        if server.stderr is not None:
            log = server.stderr.read().strip()
            if log:
                print("Server log:\n\n```\n" + log + "\n```\n")
        return report(run, args, info, build_seconds, wall, params)


if __name__ == "__main__":
    raise SystemExit(main())
