"""Runaway queries against ``cadkg serve``: stopped at the time limit, the cores idle again, the
endpoint answering at once. The server runs in its own process group (its query workers with it),
whose CPU time is read from ``/proc``."""

from __future__ import annotations

import os
import threading
import time
from pathlib import Path

import httpx
import pytest

from tests.conftest import IEMA
from tests.server.serving import cadkg_serve_process

TICK = os.sysconf("SC_CLK_TCK")
# Every triple × every triple × every triple, counted: no solution streams, nothing to stop at.
CUBE = "SELECT (COUNT(*) AS ?n) WHERE {{ ?a ?b ?c . ?d ?e ?f . ?g ?h ?i }} # client {}"
OFFSET = "SELECT * WHERE { ?a ?b ?c . ?d ?e ?f } OFFSET 100000000000000"
WIRES = "SELECT (COUNT(DISTINCT ?w) AS ?n) WHERE { ?w a ck:Wire }"


def cpu_seconds(group: int) -> float:
    """User and system CPU seconds of the live processes of a process group."""
    total = 0
    for entry in Path("/proc").iterdir():
        if not entry.name.isdigit():
            continue
        try:
            stat = (entry / "stat").read_text()
        except OSError:
            continue
        fields = stat.rsplit(")", 1)[1].split()
        if int(fields[2]) == group:  # pgrp, then utime and stime at 12 and 13
            total += int(fields[11]) + int(fields[12])
    return total / TICK


@pytest.mark.slow
def test_runaway_queries_are_stopped_and_the_endpoint_answers() -> None:
    with cadkg_serve_process(str(IEMA), "--timeout", "3", "--workers", "4") as (base, process):
        answers: list[tuple[int, float, str]] = []

        def ask(query: str) -> None:
            response = httpx.get(f"{base}/sparql", params={"query": query}, timeout=120)
            answers.append((response.status_code, response.elapsed.total_seconds(), response.text))

        runaways = [CUBE.format(n) for n in range(4)] + [OFFSET]
        clients = [threading.Thread(target=ask, args=(query,)) for query in runaways]
        for client in clients:
            client.start()
        for client in clients:
            client.join(120)
        assert [status for status, _, _ in answers] == [503] * 5, answers
        assert all(seconds < 20 for _, seconds, _ in answers), answers
        assert all("time limit of 3 s" in text for _, _, text in answers)

        # Killed half a second after their deadline: from then on nothing of the server computes.
        time.sleep(1.5)
        before = cpu_seconds(process.pid)
        time.sleep(3)
        used = cpu_seconds(process.pid) - before
        assert used < 0.5, f"the server's processes used {used:.2f} CPU seconds in 3 s after the time-outs"

        for path, params in (
            ("/sparql", {"query": WIRES}),
            ("/api/cad_service", {"label": "F1500.1"}),
            ("/api/info", {}),
        ):
            response = httpx.get(f"{base}{path}", params=params, timeout=30)
            assert response.status_code == 200, (path, response.text)
            assert response.elapsed.total_seconds() < 5, (path, response.elapsed)
        workers = httpx.get(f"{base}/api/info").json()["workers"]
        assert workers["killed"] == 4  # the fifth runaway waited for a worker and never started
