from __future__ import annotations

import os
import signal
import subprocess
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import pytest

import cadkg
from tests.paths import ROOT
from tests.ros import nested

EXAMPLES = ROOT / "examples"
IEMA = EXAMPLES / "iema-switchgear" / "manifest.toml"
IEMA_FIG3 = EXAMPLES / "iema-switchgear" / "manifest-fig3.toml"
BAD = EXAMPLES / "bad-cell" / "manifest.toml"
ELVEZ = EXAMPLES / "elvez-cell" / "manifest.toml"


def run_capped(
    command: list[str], *, cwd: Path, cap: float, env: Mapping[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    """``command`` in its own process group, the whole group killed when it runs past ``cap``
    seconds (the test then fails with what it printed so far)."""
    process = subprocess.Popen(
        command,
        cwd=cwd,
        env=None if env is None else dict(env),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    try:
        stdout, stderr = process.communicate(timeout=cap)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        stdout, stderr = process.communicate()
        pytest.fail(f"{' '.join(command)} ran over {cap} s:\n{stdout[-6000:]}\n{stderr[-2000:]}")
    return subprocess.CompletedProcess(process.args, process.returncode, stdout, stderr)


def synthetic_manifest(directory: Path, wires: int, *, cabinet: bool) -> Path:
    """A synthetic cell (or complete cabinet) of ``benchmarks/synthetic.py`` written into ``directory``."""
    import sys

    sys.path.insert(0, str(ROOT / "benchmarks"))
    import synthetic

    writer = synthetic.write_cabinet if cabinet else synthetic.write_cell
    return Path(writer(directory, wires))


# A test that needs a live part the fast tier does without: the browser (Chromium and its
# driver) or Virtuoso, known by the fixture that starts it. The nested ROS run and the demo on a
# fresh copy are marked in their own modules.
LIVE_FIXTURES = frozenset({"browser", "virtuoso"})
# The modules that take longest, longest first: run first, each in a worker of its own while the
# other worker takes the many short ones, so that no long module is left running alone at the
# end of a run on both cores (measured on a loaded 2-core machine, docs/testing.md).
# The nested ROS run, when the session started it beside its workers, is read last instead: by
# then it is over (tests/ros/nested.py).
LONGEST = ("tests/ros/test_live.py", "tests/test_demo.py")
NESTED = "tests/ros/test_live.py"


def pytest_configure(config: pytest.Config) -> None:
    nested.start_beside(config)


def pytest_unconfigure(config: pytest.Config) -> None:
    nested.stop_beside(config)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    for item in items:
        if LIVE_FIXTURES.intersection(getattr(item, "fixturenames", ())):
            item.add_marker(pytest.mark.live)
    beside = nested.RUN in os.environ
    first = [name for name in LONGEST if not (beside and name == NESTED)]
    rank = {name: place for place, name in enumerate(first)}
    last = {NESTED: len(first) + 1} if beside else {}
    # A stable sort keeps each module's tests together and in their order.
    items.sort(key=lambda item: (rank | last).get(item.nodeid.partition("::")[0], len(first)))


@pytest.fixture(scope="session")
def iema() -> cadkg.KnowledgeGraph:
    """The IEMA example built in memory once; tests must not change it."""
    return cadkg.build(IEMA)


@pytest.fixture(scope="session")
def fig3() -> cadkg.KnowledgeGraph:
    return cadkg.build(IEMA_FIG3)


@pytest.fixture(scope="session")
def elvez() -> cadkg.KnowledgeGraph:
    """The ELVEZ example built in memory once; tests must not change it."""
    return cadkg.build(ELVEZ)


@pytest.fixture
def write(tmp_path: Path) -> Callable[[str, str | bytes], Path]:
    """Write ``content`` (str as UTF-8, or raw bytes) to ``tmp_path/name`` and return the path."""

    def _write(name: str, content: str | bytes) -> Path:
        path = tmp_path / name
        path.write_bytes(content.encode("utf-8") if isinstance(content, str) else content)
        return path

    return _write


@pytest.fixture(scope="session")
def browser(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    """Headless Chromium (see tests/server/browser.py); downloads go to ``browser.downloads``."""
    from tests.server.browser import chromium

    downloads = tmp_path_factory.mktemp("downloads")
    with chromium(downloads) as driver:
        driver.downloads = downloads
        yield driver
