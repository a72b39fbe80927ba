"""The limited child: work past its memory, CPU-time or wall-time limit is stopped in its child
and said in one line naming the work, the limit and the setting that raises it.

The work functions are generated: busy loops, waits and allocations of several shapes and
sizes, each drawn from a seeded generator. The limits are small (64 MiB, 1 s of CPU, 2 s of
time) so the tests are quick, and every other limit is generous so that a loaded machine, where
a second of CPU may take several of time, still names the limit the work ran into.
"""

from __future__ import annotations

import os
import random
import select
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from cadkg.errors import IngestError, LimitError, MemoryLimitError, ReadLimitError, TimeLimitError
from cadkg.limited import Limits, read_limited, run_limited

ROOM = 120.0  # seconds any limit here may take to show on a loaded 2-core machine


def _spin(seed: int) -> None:
    """A busy loop of one of a few shapes, that never ends."""
    shape = seed % 3
    n = 1
    while True:
        if shape == 0:
            n = (n * 31 + seed) % 1_000_003
        elif shape == 1:
            sorted(range(seed % 500 + 10, 0, -1))
        else:
            n = len(str(n**3)) + seed


def _wait(seed: int) -> None:
    """A wait that uses no CPU and never ends."""
    shape = seed % 3
    if shape == 0:
        time.sleep(3600)
    elif shape == 1:
        readable, _ = os.pipe()
        select.select([readable], [], [])
    else:
        # A grandchild in the same group, waited on: killing the group must stop it too.
        subprocess.run(["sleep", "3600"], check=False)


def _grow(seed: int) -> list[object]:
    """Allocations of a growing size, past any limit."""
    rng = random.Random(seed)
    kept: list[object] = []
    size = rng.randint(1 << 10, 1 << 20)
    while True:
        shape = rng.randrange(3)
        if shape == 0:
            kept.append(bytearray(size))
        elif shape == 1:
            kept.append(list(range(size // 8)))
        else:
            kept.append("x" * size)
        size = size * 3 // 2


SEEDS = [random.Random(f"limited {n}").randrange(1 << 30) for n in range(6)]
CASES: list[tuple[str, Callable[[int], object], Limits, str]] = [
    ("cpu", _spin, Limits(cpu=1, wall=ROOM), "cpu"),
    ("wall", _wait, Limits(wall=2), "wall"),
    ("memory", _grow, Limits(memory=64, wall=ROOM), "memory"),
]


@pytest.mark.parametrize("seed", SEEDS)
@pytest.mark.parametrize(("name", "work", "limits", "limit"), CASES, ids=[c[0] for c in CASES])
def test_a_query_past_a_limit_is_stopped_in_one_line(
    name: str, work: Callable[[int], object], limits: Limits, limit: str, seed: int
) -> None:
    limits = Limits(
        memory=limits.memory, cpu=limits.cpu, wall=limits.wall, wall_setting="--timeout", cpu_setting="--cpu"
    )
    started = time.monotonic()
    with pytest.raises(LimitError) as info:
        run_limited(work, (seed,), limits)
    assert time.monotonic() - started < ROOM
    error = info.value
    assert error.limit == limit
    text = str(error)
    assert "\n" not in text and text.startswith("the query ")
    expected = {
        "cpu": "the query needed more than 1 s of CPU time and was stopped (--cpu)",
        "wall": "the query ran past the time limit of 2 s and was stopped (--timeout)",
        "memory": "the query needed more than the 64 MiB of memory a query may take and was stopped "
        "(--max-query-memory)",
    }[limit]
    assert text == expected
    assert isinstance(error, MemoryLimitError if limit == "memory" else TimeLimitError)


@pytest.fixture
def small_read_limits(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CADKG_READ_LIMIT_MIB", "64")
    monkeypatch.setenv("CADKG_READ_CPU_S", "1")
    monkeypatch.setenv("CADKG_READ_WALL_S", "2")


@pytest.mark.parametrize("seed", SEEDS[:3])
@pytest.mark.parametrize(("name", "work", "limits", "limit"), CASES, ids=[c[0] for c in CASES])
def test_a_reader_past_a_limit_is_refused_naming_the_file_and_the_variable(
    small_read_limits: None,
    monkeypatch: pytest.MonkeyPatch,
    name: str,
    work: Callable[[int], object],
    limits: Limits,
    limit: str,
    seed: int,
) -> None:
    # Only the limit under test is small: the others leave room for a loaded machine.
    if limit != "wall":
        monkeypatch.setenv("CADKG_READ_WALL_S", str(int(ROOM)))
    path = f"cell/input-{seed}.csv"

    def read(seed: int) -> list[object]:
        work(seed)
        return []

    with pytest.raises(ReadLimitError) as info:
        list(read_limited(path, read, seed))
    assert info.value.limit == limit and isinstance(info.value, IngestError)
    expected = {
        "cpu": "needs more than 1 s of CPU time to read (limit set by CADKG_READ_CPU_S)",
        "wall": "took more than 2 s to read and was stopped (limit set by CADKG_READ_WALL_S)",
        "memory": "needs more than 64 MiB to read (limit set by CADKG_READ_LIMIT_MIB)",
    }[limit]
    assert str(info.value) == f"{path}: {expected}"


def _sleeper_pid(path: Path) -> None:
    child = subprocess.Popen(["sleep", "3600"])
    path.write_text(str(child.pid))
    child.wait()


def test_the_wall_limit_kills_the_child_s_whole_group(tmp_path: Path) -> None:
    pid_file = tmp_path / "pid"
    with pytest.raises(TimeLimitError):
        run_limited(_sleeper_pid, (pid_file,), Limits(wall=2))
    grandchild = int(pid_file.read_text())
    deadline = time.monotonic() + 30
    while Path(f"/proc/{grandchild}").exists() and time.monotonic() < deadline:
        stat = Path(f"/proc/{grandchild}/stat").read_text(errors="replace")
        if stat.rsplit(")", 1)[1].split()[0] == "Z":  # killed, waiting for init to reap it
            break
        time.sleep(0.1)
    else:
        assert not Path(f"/proc/{grandchild}").exists(), "the grandchild outlived the wall limit"


def test_time_spent_by_the_caller_is_not_the_reader_s(monkeypatch: pytest.MonkeyPatch) -> None:
    # The wall limit counts the time the build waits for the reader, not the time it spends
    # mapping what came back.
    monkeypatch.setenv("CADKG_READ_WALL_S", "2")
    items = read_limited("f.csv", lambda n: iter(range(n)), 5000)
    assert next(items) == 0
    time.sleep(3)
    assert sum(items) == sum(range(5000))


def test_work_within_its_limits_answers_and_raises_as_it_does() -> None:
    limits = Limits(memory=256, cpu=30, wall=ROOM, network=False)
    assert run_limited(sorted, ([3, 1, 2],), limits) == [1, 2, 3]
    with pytest.raises(ZeroDivisionError):
        run_limited(divmod, (1, 0), limits)


@pytest.mark.parametrize("value", ["lots", "-1", "1.5", "9" * 12])
@pytest.mark.parametrize("name", ["CADKG_READ_CPU_S", "CADKG_READ_WALL_S"])
def test_a_time_limit_that_is_no_number_is_one_line(
    monkeypatch: pytest.MonkeyPatch, name: str, value: str
) -> None:
    monkeypatch.setenv(name, value)
    with pytest.raises(Exception) as info:
        list(read_limited("f.csv", lambda: []))
    assert str(info.value) == f"{name}={value!r}: expected a whole number of seconds (0: no limit)"
