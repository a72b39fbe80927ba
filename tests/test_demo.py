"""The README's main job, ``bash scripts/demo.sh``, works on a fresh copy of the checkout.

The copy holds the checkout's tracked files as they are in the working tree (edits included),
with no ``.venv``, no built web page and no stores: the demo's own set-up must install all it
needs, so this also proves that the demo needs nothing the set-up does not install. It runs
in its own process group, killed whole if it overruns.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path

import pytest

from tests.conftest import ROOT, run_capped

pytestmark = pytest.mark.slow

# The set-up (a new .venv, npm ci, Vite) and five builds; measured at about 5 minutes on a
# 2-core machine kept busy by other work.
CAP_SECONDS = 1800
SECTIONS = ("IEMA switchgear", "ELVEZ harness assembly", "ELIMCO aeronautic", "Volkswagen wire", "ENKI hose")
Demo = tuple[Path, subprocess.CompletedProcess[str]]
STORES = ("iema-store", "elvez-store", "elimco-store", "vw-store", "enki-store")


def _tracked_copy(target: Path) -> None:
    listed = subprocess.run(
        ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
        cwd=ROOT,
        capture_output=True,
        check=True,
    ).stdout
    for name in filter(None, listed.decode().split("\0")):
        source = ROOT / name
        if source.is_file():  # a file deleted in the working tree is not in the copy either
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(source, target / name)


def _run(checkout: Path, *command: str) -> subprocess.CompletedProcess[str]:
    # What a new user's shell has: no virtual environment active, no path into this checkout.
    env = {k: v for k, v in os.environ.items() if k not in {"VIRTUAL_ENV", "PYTHONPATH", "PYTHONHOME"}}
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep) if str(ROOT) not in p)
    return run_capped(list(command), cwd=checkout, env=env, cap=CAP_SECONDS)


@pytest.fixture(scope="module")
def demo(tmp_path_factory: pytest.TempPathFactory) -> Demo:
    checkout = tmp_path_factory.mktemp("clone")
    _tracked_copy(checkout)
    assert not (checkout / ".venv").exists() and (checkout / "scripts" / "demo.sh").is_file()
    return checkout, _run(checkout, "bash", "scripts/demo.sh")


def test_the_demo_runs_to_the_end(demo: Demo) -> None:
    checkout, done = demo
    assert done.returncode == 0, f"exit {done.returncode}\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
    assert "Traceback" not in done.stdout + done.stderr
    for store in STORES:
        assert (checkout / "build" / store / "CURRENT").is_file(), store
    assert (checkout / "build" / "door-l.graphml").read_text(encoding="utf-8").startswith("<?xml")


def test_the_demo_is_a_short_section_per_use_case(demo: Demo) -> None:
    _, done = demo
    out = done.stdout
    positions = [out.index(f"━━ {title}") for title in SECTIONS]
    assert positions == sorted(positions)
    sections = re.split(r"^━━ ", out, flags=re.M)[1:]
    assert len(sections) == len(SECTIONS) + 1  # and where things are
    for section in sections[:-1]:
        assert re.search(r"\d+ triples in \d+ named graphs, built in [\d.]+ s", section)
        assert re.search(r"^    holds \d+ \w+", section, flags=re.M)
        assert re.search(r"^    \d+ error\(s\), \d+ warning\(s\)$", section, flags=re.M)
        assert len(section.splitlines()) <= 45, section
    assert "cadkg serve build/iema-store" in sections[-1]
    # A service answer is shown a field a line, not as pages of JSON.
    assert not re.search(r'^\s*"position": \{', out, flags=re.M)
    assert len(out.splitlines()) <= 220


def test_the_demo_shows_what_it_runs_as_runnable_commands(demo: Demo) -> None:
    checkout, done = demo
    shown = [line.split("$ ", 1)[1] for line in done.stdout.splitlines() if line.startswith("  $ cadkg ")]
    assert len(shown) >= 20
    # Each shown command works as typed in the checkout (a query shown gives its table).
    for command in (c for c in shown if c.startswith(("cadkg query", "cadkg validate"))):
        again = subprocess.run(
            f".venv/bin/{command}", shell=True, cwd=checkout, capture_output=True, text=True, check=False
        )
        assert again.returncode == 0, f"{command}: {again.stderr}"


def test_verbose_shows_each_whole_answer(demo: Demo) -> None:
    checkout, first = demo
    assert first.returncode == 0
    done = _run(checkout, str(checkout / ".venv" / "bin" / "python"), "scripts/demo.py", "--verbose")
    assert done.returncode == 0, done.stderr
    assert re.search(r'^\s*"position": \{', done.stdout, flags=re.M)  # the JSON, whole
    assert "┃ file or stage" in done.stdout  # each build's table
