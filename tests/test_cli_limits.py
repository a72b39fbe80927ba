"""``cadkg`` as an attacker would use it: runaway queries, federated queries, inputs whose
libraries answer in paragraphs. Every refusal is one line on stderr and exit code 2."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import time
import zipfile
from pathlib import Path

from tests.cli import CADKG, run
from tests.conftest import EXAMPLES, IEMA, ROOT
from tests.server.listener import Listener

CUBE = "SELECT (COUNT(*) AS ?n) WHERE { ?a ?b ?c . ?d ?e ?f . ?g ?h ?i }"


def _group_alive(group: int) -> list[int]:
    alive = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[2]) == group and fields[0] != "Z":
                alive.append(int(entry.name))
    return alive


def _one_line_error(result: subprocess.CompletedProcess[str]) -> str:
    assert result.returncode == 2, (result.returncode, result.stdout, result.stderr)
    # The example's own warnings (its files carry what real exports add) come first, one line each.
    lines = [line for line in result.stderr.strip().splitlines() if not line.startswith("cadkg: warning: ")]
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith("cadkg: error: ")
    return lines[0]


def test_timeout_stops_a_runaway_query_and_leaves_no_process() -> None:
    started = time.monotonic()
    process = subprocess.Popen(
        [*CADKG, "query", str(IEMA), CUBE, "--timeout", "2"],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        out, err = process.communicate(timeout=180)
    finally:
        with_group = process.pid
    result = subprocess.CompletedProcess(process.args, process.returncode, out, err)
    line = _one_line_error(result)
    assert "ran past the time limit of 2 s and was stopped" in line
    # The manifest is built and copied for the worker first: bounded, but not 2 s on a loaded box.
    assert time.monotonic() - started < 120
    deadline = time.monotonic() + 20
    while _group_alive(with_group) and time.monotonic() < deadline:
        time.sleep(0.2)
    left = _group_alive(with_group)
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    assert left == [], "processes of the query were left running"


def test_timeout_answers_a_query_that_ends_in_time() -> None:
    result = run("query", IEMA, "SELECT (COUNT(*) AS ?n) WHERE { ?w a ck:Wire }", "--timeout", "60")
    assert result.returncode == 0, result.stderr
    assert "110" in result.stdout


def test_service_is_refused_without_a_connection() -> None:
    with Listener() as listener:
        for query in (
            f"SELECT * WHERE {{ SERVICE <{listener.url}> {{ ?s ?p ?o }} }}",
            "SELECT * WHERE { SERVICE ?e { ?s ?p ?o } }",
            f"SELECT * WHERE {{ service silent <{listener.url}> {{ ?s ?p ?o }} }}",
        ):
            line = _one_line_error(run("query", IEMA, query))
            assert "is refused: cadkg makes no outbound requests" in line, line
        time.sleep(0.3)
        assert listener.connections == 0


def test_an_allowed_service_is_reached() -> None:
    with Listener() as listener:
        query = f"SELECT ?s WHERE {{ SERVICE <{listener.url}> {{ ?s ?p ?o }} }}"
        result = run("query", IEMA, query, "--allow-service", listener.url, "--format", "csv")
        assert result.returncode == 0, result.stderr
        assert result.stdout.splitlines() == ["s", "urn:remote:1"]
        other = run("query", IEMA, query.replace("/sparql", "/elsewhere"), "--allow-service", listener.url)
        assert "not one of the allowed endpoints" in _one_line_error(other)
        assert listener.connections == 1


def test_a_failing_allowed_service_is_one_line() -> None:
    with Listener(fail=True) as failing:
        query = f"SELECT ?s WHERE {{ SERVICE <{failing.url}> {{ ?s ?p ?o }} }}"
        line = _one_line_error(run("query", IEMA, query, "--allow-service", failing.url))
        assert "the query failed" in line


def test_a_workbook_with_a_document_type_is_one_line(tmp_path: Path) -> None:
    bench = tmp_path / "bench"
    shutil.copytree(EXAMPLES / "elimco-bench", bench)
    workbook = bench / "cable-list.xlsx"
    with zipfile.ZipFile(EXAMPLES / "elimco-bench" / "cable-list.xlsx") as source:
        parts = {name: source.read(name) for name in source.namelist()}
    sheet = "xl/worksheets/sheet1.xml"
    doctype = b'<?xml version="1.0"?><!DOCTYPE w [<!ENTITY a "aaaa">]>'
    parts[sheet] = doctype + parts[sheet].split(b"?>", 1)[-1]
    with zipfile.ZipFile(workbook, "w") as target:
        for name, data in parts.items():
            target.writestr(name, data)
    line = _one_line_error(run("build", bench / "manifest.toml", "--store", tmp_path / "store"))
    assert str(workbook) in line
