"""Bounded query memory: a query that would take gigabytes (generated: strings doubled, tripled or
joined to their upper case) is stopped at the memory limit with one line, and the endpoint goes on.

Memory is measured where it is spent: the server and its workers in their own process group
(sampled from ``/proc`` while the query runs), ``cadkg query`` in a child whose peak is read
from ``getrusage``. Unbounded, each of these queries takes 1.5 GiB or more.
"""

from __future__ import annotations

import json
import math
import subprocess
import sys
import threading
from collections.abc import Iterator
from pathlib import Path

import httpx
import pytest
from hypothesis import HealthCheck, Phase, given, settings
from hypothesis import strategies as st

import cadkg
from cadkg.errors import MemoryLimitError
from cadkg.query.workers import WorkerPool
from tests.conftest import IEMA, ROOT
from tests.server.serving import cadkg_serve_process

LIMIT = 400  # MiB a query may take in these tests
GIB = 1 << 30
SEED = "0123456789abcdef" * 2  # 32 bytes
WIRES = "SELECT (COUNT(DISTINCT ?w) AS ?n) WHERE { ?w a ck:Wire }"
SLOW = settings(
    max_examples=3,
    deadline=None,
    database=None,
    suppress_health_check=list(HealthCheck),
    phases=[Phase.generate],
)


@st.composite
def bombs(draw: st.DrawFn) -> str:
    """A query whose one string grows past 2 GiB: copies of itself concatenated (2, 3 or 4 at a
    level), or joined to its upper case at every level."""
    shape = draw(st.sampled_from(["concat-2", "concat-3", "concat-4", "upper"]))
    factor = 2 if shape == "upper" else int(shape[-1])
    levels = math.ceil(math.log(2 * GIB / len(SEED), factor))
    binds = []
    for i in range(levels):
        copies = ", ".join([f"?x{i}"] * factor)
        grown = f"CONCAT(?x{i}, UCASE(?x{i}))" if shape == "upper" else f"CONCAT({copies})"
        binds.append(f"BIND({grown} AS ?x{i + 1})")
    return f'SELECT (STRLEN(?x{levels}) AS ?n) WHERE {{ BIND("{SEED}" AS ?x0) {" ".join(binds)} }}'


def _rss(pid: int) -> int:
    """Resident bytes of a process, 0 once it is gone."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) << 10
    except OSError:
        pass
    return 0


def _group(group: int) -> list[int]:
    members = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                if int((entry / "stat").read_text().rsplit(")", 1)[1].split()[2]) == group:
                    members.append(int(entry.name))
            except (OSError, IndexError, ValueError):
                continue
    return members


class PeakSampler:
    """The largest resident size of each process of a process group, sampled until stopped."""

    def __init__(self, group: int) -> None:
        self.group = group
        self.peaks: dict[int, int] = {}
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        while not self._stop.wait(0.02):
            for pid in _group(self.group):
                self.peaks[pid] = max(self.peaks.get(pid, 0), _rss(pid))

    def __enter__(self) -> PeakSampler:
        self._thread.start()
        return self

    def __exit__(self, *exc: object) -> None:
        self._stop.set()
        self._thread.join(5)


@pytest.fixture(scope="module")
def store(tmp_path_factory: pytest.TempPathFactory) -> Path:
    target = tmp_path_factory.mktemp("memory") / "store"
    cadkg.KnowledgeGraph.build(IEMA, target).close()
    return target


@pytest.fixture(scope="module")
def server(store: Path) -> Iterator[tuple[str, int]]:
    args = (str(store), "--workers", "1", "--timeout", "120", "--max-query-memory", str(LIMIT))
    with cadkg_serve_process(*args) as (base, process):
        yield base, process.pid


@pytest.mark.slow
@SLOW
@given(bomb=bombs())
def test_the_endpoint_stops_the_query_and_answers_the_next(server: tuple[str, int], bomb: str) -> None:
    base, pid = server
    with PeakSampler(pid) as sampler:
        answer = httpx.get(f"{base}/sparql", params={"query": bomb}, timeout=300)
    assert answer.status_code == 400, answer.text
    assert answer.text.strip().splitlines() == [
        f"the query needed more than the {LIMIT} MiB of memory a query may take and was stopped "
        "(--max-query-memory)"
    ]
    after = httpx.get(f"{base}/sparql", params={"query": WIRES, "format": "json"}, timeout=300)
    assert after.status_code == 200, after.text
    assert json.loads(after.text)["results"]["bindings"][0]["n"]["value"] == "110"
    # The server's own memory stayed small (the query never ran in it); the worker's stayed near
    # its limit (its open graph and the limit), far from the gigabytes asked for.
    assert sampler.peaks[pid] < 400 << 20, sampler.peaks
    assert max(sampler.peaks.values()) < (LIMIT + 400) << 20, sampler.peaks


@settings(SLOW, max_examples=2)
@given(bomb=bombs())
def test_the_cli_stops_the_query_in_one_line(store: Path, bomb: str) -> None:
    measure = (
        "import resource, subprocess, sys; "
        "r = subprocess.run(sys.argv[1:], capture_output=True, text=True); "
        "sys.stderr.write(r.stderr); "
        "print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)"
    )
    command = [sys.executable, "-m", "cadkg.cli", "query", "--max-query-memory", "300", str(store), bomb]
    result = subprocess.run(
        [sys.executable, "-c", measure, *command],
        capture_output=True,
        text=True,
        cwd=ROOT,
        timeout=600,
        check=False,
    )
    code, peak_kib = map(int, result.stdout.split())
    assert code == 2
    assert result.stderr.strip().splitlines() == [
        "cadkg: error: the query needed more than the 300 MiB of memory a query may take and was stopped "
        "(--max-query-memory)"
    ]
    assert peak_kib << 10 < (300 + 400) << 20


def _concat(levels: int) -> str:
    binds = " ".join(f"BIND(CONCAT(?x{i}, ?x{i}) AS ?x{i + 1})" for i in range(levels))
    return f'SELECT (STRLEN(?x{levels}) AS ?n) WHERE {{ BIND("{SEED}" AS ?x0) {binds} }}'


def test_a_worker_pool_stops_the_query_and_answers_the_next(iema: cadkg.KnowledgeGraph) -> None:
    with WorkerPool(iema, 1, memory=LIMIT) as workers:
        with pytest.raises(MemoryLimitError, match=f"more than the {LIMIT} MiB"):
            workers.query(_concat(26), 300)
        assert workers.query(WIRES, 300).rows == iema.query(WIRES).rows
