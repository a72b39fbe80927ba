"""tests/ros/nested.py starts the live ROS run beside the workers only for a session that
reports it whole: its paths hold test_live.py, and no marker or keyword expression picks."""

from __future__ import annotations

import os
import subprocess
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from tests.ros import nested
from tests.ros.nested import MODULE, ROOT, _covers, _waited


def _config(*args: str, markexpr: str = "", keyword: str = "", where: Path = ROOT) -> Any:
    return SimpleNamespace(
        args=list(args),
        option=SimpleNamespace(markexpr=markexpr, keyword=keyword),
        invocation_params=SimpleNamespace(dir=where),
    )


@pytest.mark.parametrize(
    ("args", "where"),
    [
        (("tests",), ROOT),
        (("tests/ros",), ROOT),
        (("tests/ros/test_live.py",), ROOT),
        ((str(MODULE),), Path("/")),
        (("tests/query", "tests/ros"), ROOT),
        (("ros",), ROOT / "tests"),
        (("../tests/ros/",), ROOT / "src"),
        ((".",), ROOT),
    ],
)
def test_a_selection_holding_the_module_whole_starts_it(args: tuple[str, ...], where: Path) -> None:
    assert _covers(_config(*args, where=where))


@pytest.mark.parametrize(
    "config",
    [
        _config("tests/query"),
        _config("tests/ros/test_ros_frames.py"),
        _config("tests/ros/test_live.py::test_live"),
        _config("tests", markexpr="not slow and not live"),
        _config("tests", markexpr="live"),
        _config("tests", keyword="colcon"),
        _config("src"),
    ],
)
def test_any_other_selection_leaves_it_to_the_module(config: Any) -> None:
    assert not _covers(config)


def _folder(tmp_path: Path, group: int) -> Path:
    (tmp_path / "started").write_text(f"{time.time()} {group}\n", encoding="utf-8")
    (tmp_path / "output").write_text("the run's last words\n", encoding="utf-8")
    return tmp_path


def _ended_group() -> int:
    done = subprocess.Popen(["true"], start_new_session=True)
    done.wait()
    return done.pid


def test_a_run_the_session_started_is_read_once_it_wrote_its_status(tmp_path: Path) -> None:
    folder = _folder(tmp_path, _ended_group())
    (folder / "rc").write_text("1\n", encoding="utf-8")
    assert _waited(folder) == (folder / "live.xml", "the run's last words\n", 1)


def test_a_run_killed_before_its_status_fails_at_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setattr(nested, "CAP_SECONDS", 20)  # past it, the failure would say "ran over"
    folder = _folder(tmp_path, _ended_group())
    started = time.monotonic()
    with pytest.raises(pytest.fail.Exception, match=r"killed before it ended(.|\n)*last words"):
        _waited(folder)
    assert time.monotonic() - started < 30


def test_a_session_on_workers_holding_the_module_runs_it_beside_them(request: pytest.FixtureRequest) -> None:
    # What the speed-up rests on: a full run on workers must have started the run at its start
    # (else every test still passes, each run only slower).
    config = request.config
    if not hasattr(config, "workerinput") or not _covers(config):
        pytest.skip("not a session on workers that runs tests/ros/test_live.py whole")
    if nested.FAILED.is_file() or not nested.PYTHON.is_file():
        pytest.skip("no ROS set-up: tests/ros/test_live.py says why")
    folder = Path(os.environ[nested.RUN])
    assert (folder / "started").is_file()
