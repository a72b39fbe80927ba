"""tests/ros/nested.py starts the live ROS run beside the workers only for a session that
reports it whole: its paths hold test_live.py, and no marker or keyword expression picks."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import pytest

from tests.ros.nested import MODULE, ROOT, _covers


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
