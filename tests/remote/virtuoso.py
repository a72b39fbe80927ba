"""A private Virtuoso for a test module: started by scripts/virtuoso.sh, stopped afterwards."""

from __future__ import annotations

import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

SCRIPT = Path(__file__).resolve().parents[2] / "scripts" / "virtuoso.sh"


@contextmanager
def running_virtuoso(directory: Path) -> Iterator[dict[str, str]]:
    """The ``KEY=VALUE`` lines the script prints (endpoints, user, password); skips the test
    only when apt cannot install Virtuoso here."""
    started = subprocess.run(
        ["bash", str(SCRIPT), "start", str(directory)],
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
    )
    if started.returncode == 3:
        pytest.skip(f"Virtuoso cannot be installed here: {started.stderr.strip()}")
    assert started.returncode == 0, started.stderr
    try:
        yield dict(line.split("=", 1) for line in started.stdout.splitlines() if "=" in line)
    finally:
        subprocess.run(["bash", str(SCRIPT), "stop", str(directory)], capture_output=True, timeout=60)
