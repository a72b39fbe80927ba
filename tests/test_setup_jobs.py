"""scripts/jobs.sh: the set-up's background builds end with the script, however it ends;
and scripts/setup.sh, whose steps all run as such jobs, on stand-ins for its steps.

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


# scripts/setup.sh on stand-ins for its steps: each step starts a child of its own and waits
# ("hang"), or says its name and ends ("done", "fail"; "late-fail" once another step's child
# runs), so the test sees whether the script ends its steps.
SCRIPTS = JOBS.parent
_STEP = """nap() {{ if [ "{mode}" = hang ]; then sleep 300 & echo "$!" >>{pids}; wait; fi; }}
late() {{ if [ "{mode}" = late-fail ]; then while [ ! -s {pids} ]; do sleep 0.05; done; fi; }}
nap; late; echo "{name} said"; [ "{mode}" = done ] || [ "{mode}" = hang ]
"""
_VENV = """venv_install() {{ {step} }}
compile_sources() {{ :; }}
"""


def _setup_tree(tmp_path: Path, modes: dict[str, str]) -> tuple[Path, Path]:
    pids = tmp_path / "pids"
    pids.write_text("")
    scripts = tmp_path / "tree" / "scripts"
    scripts.mkdir(parents=True)
    for name in ("setup.sh", "jobs.sh"):
        (scripts / name).write_text((SCRIPTS / name).read_text())
    for name in ("ros-setup.sh", "browser-setup.sh", "virtuoso.sh", "build-web.sh"):
        step = _STEP.format(mode=modes.get(name, "done"), pids=pids, name=name)
        (scripts / name).write_text(step)
    venv_step = _STEP.format(mode=modes.get("venv", "done"), pids=pids, name="venv")
    (scripts / "venv.sh").write_text(_VENV.format(step=venv_step.replace("\n", "; ")))
    python = tmp_path / "tree" / ".venv" / "bin" / "python"
    python.parent.mkdir(parents=True)
    python.write_text("#!/bin/sh\n")
    python.chmod(0o755)
    return scripts / "setup.sh", pids


def _run_setup(setup: Path) -> subprocess.Popen[str]:
    return subprocess.Popen(
        ["bash", str(setup), "--test"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def _wait_for(pids: Path, count: int, within: float = 20.0) -> list[int]:
    deadline = time.monotonic() + within
    while len(_children(pids)) < count:
        assert time.monotonic() < deadline, pids.read_text()
        time.sleep(0.05)
    return _children(pids)


@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGINT, signal.SIGHUP])
@pytest.mark.parametrize("to", ["script", "group"])
def test_setup_killed_ends_every_set_up_it_started(tmp_path: Path, sig: int, to: str) -> None:
    modes = {"ros-setup.sh": "hang", "browser-setup.sh": "hang", "venv": "hang"}
    setup, pids = _setup_tree(tmp_path, modes)
    proc = _run_setup(setup)
    children = _wait_for(pids, 3)
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


def test_setup_failing_ends_the_set_ups_beside_it(tmp_path: Path) -> None:
    setup, pids = _setup_tree(tmp_path, {"ros-setup.sh": "hang", "venv": "late-fail"})
    proc = _run_setup(setup)
    try:
        out, _ = proc.communicate(timeout=30)
        children = _children(pids)
        assert proc.returncode != 0
        assert "build-web.sh said" not in out
        assert children and _gone(children)
    finally:
        _clean(_children(pids))
        proc.kill()


def test_setup_waits_for_its_set_ups_and_shows_what_they_said(tmp_path: Path) -> None:
    setup, _ = _setup_tree(tmp_path, {"virtuoso.sh": "fail"})
    out = subprocess.run(["bash", str(setup), "--test"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    said = [line for line in out.stdout.splitlines() if line.endswith(" said")]
    assert said[:2] == ["venv said", "build-web.sh said"]
    assert said[2:] == ["ros-setup.sh said", "browser-setup.sh said", "virtuoso.sh said"]
