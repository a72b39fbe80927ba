"""The nested run of tests/ros/live with real rclpy in .venv-ros, reported by tests/ros/test_live.py.

The run waits on ROS as much as it computes (discovery, nodes starting, services answering):
alone in a worker it held that worker for three to four minutes at about half a core. So a
session on several workers that will report it starts it at its beginning, beside the workers
(:func:`start_beside`), and test_live.py's tests, sorted last, read what it wrote; any other
session (one worker, a selection by marker or keyword) runs it when test_live.py needs it.
Either way the run is in its own process group, killed whole past :data:`CAP_SECONDS`.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import tempfile
import time
from pathlib import Path

import pytest

from tests.paths import ROOT

PYTHON = ROOT / ".venv-ros" / "bin" / "python"
FAILED = ROOT / "build" / "ros" / "setup-failed"
MODULE = ROOT / "tests" / "ros" / "test_live.py"
# The live run took 11-15 minutes on a loaded 2-core machine while test_colcon compiled every
# interface's C++ type supports too; the cap stays as generous as it was for then.
CAP_SECONDS = 2400
# Where a run the session started writes: set for the session's workers, which inherit it.
RUN = "CADKG_ROS_LIVE_RUN"
_PROCESS = pytest.StashKey[subprocess.Popen[bytes]]()


def environment() -> dict[str, str]:
    env = {
        key: value
        for key, value in os.environ.items()
        if not key.startswith(("PYTEST_", "_ROS_WHEELS")) and key not in ("VIRTUAL_ENV", "PYTHONPATH", RUN)
    }
    env.update(
        CADKG_ROS_LIVE="1",
        ROS_DOMAIN_ID=str(1 + os.getpid() % 100),
        ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
    )
    return env


def command(report: Path) -> list[str]:
    return [
        str(PYTHON), "-m", "pytest", "-q", "-p", "no:cacheprovider", "-n", "0",
        f"--junitxml={report}", "tests/ros/live",
    ]  # fmt: skip


def _covers(config: pytest.Config) -> bool:
    """Whether the session's selection holds test_live.py whole: its paths name it or a folder
    above it, and no marker or keyword expression may leave it out."""
    if config.option.markexpr or config.option.keyword:
        return False
    invoked = Path(config.invocation_params.dir)
    for arg in config.args:
        path = (invoked / arg.partition("::")[0]).resolve()
        if "::" not in arg and (path == MODULE or path in MODULE.parents):
            return True
    return False


def start_beside(config: pytest.Config) -> None:
    """In a session's controller on several workers that reports the run whole: start it now,
    writing into a new folder named by :data:`RUN` for the workers."""
    workers = config.getoption("numprocesses", None)
    if hasattr(config, "workerinput") or not workers or RUN in os.environ:
        return
    if FAILED.is_file() or not PYTHON.is_file() or not _covers(config):
        return  # test_live.py says why, or is not run
    folder = Path(tempfile.mkdtemp(prefix="cadkg-ros-live-"))
    # The shell leads the group and writes the run's exit status once it is over; beside the
    # run (not the run itself, which keeps its default signals: a background job ignores
    # SIGINT), a watch ends the group should this session end without a word (a SIGKILL or
    # SIGTERM skips stop_beside).
    script = (
        "parent=$1; shift\n"
        '(while kill -0 "$parent" 2>/dev/null; do sleep 1; done; rm -rf "$0"; kill -KILL 0) & watch=$!\n'
        '"$@" > "$0/output" 2>&1; rc=$?\n'
        'kill "$watch"; echo "$rc" > "$0/rc.part" && mv "$0/rc.part" "$0/rc"'
    )
    config.stash[_PROCESS] = subprocess.Popen(
        ["bash", "-c", script, str(folder), str(os.getpid()), *command(folder / "live.xml")],
        cwd=ROOT,
        env=environment(),
        stdin=subprocess.DEVNULL,
        start_new_session=True,
    )
    (folder / "started").write_text(f"{time.time()} {config.stash[_PROCESS].pid}\n", encoding="utf-8")
    os.environ[RUN] = str(folder)


def stop_beside(config: pytest.Config) -> None:
    """At the session's end: the run killed if it still runs (the session was cut short, or
    test_live.py was left out after all), and its folder removed."""
    process = config.stash.get(_PROCESS, None)
    if process is None:
        return
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()
    shutil.rmtree(os.environ.pop(RUN), ignore_errors=True)


def outcome(tmp: Path) -> tuple[Path, str, int]:
    """The run's report, what it printed and its exit status: the session's run, waited for, or
    one run here into ``tmp``."""
    folder = os.environ.get(RUN)
    if folder is None:
        from tests.conftest import run_capped

        done = run_capped(command(tmp / "live.xml"), cwd=ROOT, env=environment(), cap=CAP_SECONDS)
        return tmp / "live.xml", done.stdout, done.returncode
    return _waited(Path(folder))


def _waited(folder: Path) -> tuple[Path, str, int]:
    started, group = (folder / "started").read_text(encoding="utf-8").split()
    rc = folder / "rc"
    while not rc.is_file():
        if time.time() - float(started) > CAP_SECONDS:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(int(group), signal.SIGKILL)
            pytest.fail(f"the live ROS run ran over {CAP_SECONDS} s:\n{_output(folder)[-6000:]}")
        if not _running(int(group)) and not rc.is_file():
            pytest.fail(f"the live ROS run was killed before it ended:\n{_output(folder)[-6000:]}")
        time.sleep(0.5)
    return folder / "live.xml", _output(folder), int(rc.read_text(encoding="utf-8"))


def _running(group: int) -> bool:
    try:
        os.killpg(group, 0)
    except ProcessLookupError:
        return False
    return True


def _output(folder: Path) -> str:
    path = folder / "output"
    return path.read_text(encoding="utf-8", errors="replace") if path.is_file() else ""
