"""scripts/jobs.sh: the set-up's background builds end with the script, however it ends.

Each case runs a small script that sources jobs.sh, starts two jobs that each start a child
of their own (as a build starts cmake and make), and then ends one way or another. Nothing of
the jobs may be left running.
"""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

JOBS = Path(__file__).resolve().parents[1] / "scripts" / "jobs.sh"

_SCRIPT = """set -euo pipefail
source {jobs}
nap() {{ sleep 300 & echo "$!" >>{pids}; wait; }}
background nap
background nap
while [ "$(wc -l <{pids})" -lt 2 ]; do sleep 0.05; done
echo ready
case {end} in
  fail) false ;;
  exit) exit 3 ;;
  *) wait ;;
esac
"""


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return False
    return state != "Z"


def _start(tmp_path: Path, end: str) -> tuple[subprocess.Popen[str], Path]:
    pids = tmp_path / "pids"
    pids.write_text("")
    script = _SCRIPT.format(jobs=JOBS, pids=pids, end=end)
    proc = subprocess.Popen(
        ["bash", "-c", script],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    assert proc.stdout is not None
    assert proc.stdout.readline() == "ready\n"
    return proc, pids


def _children(pids: Path) -> list[int]:
    return [int(p) for p in pids.read_text().split()]


def _gone(children: list[int], within: float = 20.0) -> bool:
    deadline = time.monotonic() + within
    while time.monotonic() < deadline:
        if not any(_alive(p) for p in children):
            return True
        time.sleep(0.05)
    return False


def _clean(children: list[int]) -> None:
    for pid in children:
        if _alive(pid):
            os.kill(pid, signal.SIGKILL)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT, signal.SIGHUP])
@pytest.mark.parametrize("to", ["script", "group"])
def test_a_signal_to_the_script_ends_its_jobs(tmp_path: Path, sig: int, to: str) -> None:
    proc, pids = _start(tmp_path, "wait")
    children = _children(pids)
    try:
        if to == "script":
            os.kill(proc.pid, sig)
        else:
            os.killpg(proc.pid, sig)
        proc.wait(timeout=20)
        assert proc.returncode == 128 + sig
        assert _gone(children)
    finally:
        _clean(children)
        proc.kill()
        proc.communicate()


@pytest.mark.parametrize("end", ["fail", "exit"])
def test_a_script_ending_before_its_jobs_ends_them(tmp_path: Path, end: str) -> None:
    proc, pids = _start(tmp_path, end)
    children = _children(pids)
    try:
        proc.wait(timeout=20)
        assert proc.returncode == (1 if end == "fail" else 3)
        assert _gone(children)
    finally:
        _clean(children)
        proc.communicate()


def test_a_job_s_status_is_what_wait_returns_and_nothing_else_is_printed() -> None:
    script = f"""set -euo pipefail
source {JOBS}
ends() {{ sleep 0.2; return "$1"; }}
background ends 0
ok=$!
background ends 7
bad=$!
wait "$ok"
rc=0; wait "$bad" || rc=$?
echo "$rc"
"""
    out = subprocess.run(["bash", "-c", script], capture_output=True, text=True, timeout=60)
    assert (out.returncode, out.stdout, out.stderr) == (0, "7\n", "")
