"""The README's commands, pasted into a fresh shell after the set-up command, work as written.

Every ``cadkg ...`` line of the ``sh`` blocks of the README and of the guides its reference
material moved to (:data:`GUIDES`, read after it in this order) runs in a new ``bash`` with a
bare environment that only sources ``.venv/bin/activate``, in a scratch folder where
``examples`` is the checkout's (so ``build/...`` and the exported files land there). The lines
that start servers, reach an external store or need ROS are left to their own tests
(tests/server, tests/remote, tests/ros). The Python block runs the same way.
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest

from tests.conftest import ROOT

# Every command of the README and its guides, each in a fresh shell.
pytestmark = pytest.mark.slow

README = (ROOT / "README.md").read_text(encoding="utf-8")
# Where the README's reference material lives; every sh block of theirs runs as written too.
GUIDES = ("docs/usage.md", "docs/use-cases.md")
TEXTS = (README, *((ROOT / guide).read_text(encoding="utf-8") for guide in GUIDES))
# Served, remote or ROS: each has its own end-to-end test.
ELSEWHERE = ("cadkg serve", "cadkg push", "cadkg ros", "http://", "https://", "curl ")
# What a command exits with when it works as documented; 0 for every other line.
EXPECTED_STATUS = {"cadkg validate examples/bad-cell/manifest.toml": 1}


def _blocks(language: str) -> list[str]:
    return [
        block
        for text in TEXTS
        for block in re.findall(rf"^```{language}\n(.*?)^```", text, flags=re.M | re.S)
    ]


def _commands() -> list[str]:
    lines: list[str] = []
    for block in _blocks("sh"):
        for line in block.replace("\\\n", " ").splitlines():
            command = line.split("  #", 1)[0].strip()
            if command.startswith("cadkg ") and not any(word in command for word in ELSEWHERE):
                lines.append(command)
    return lines


def _fresh_shell(workdir: Path, script: str) -> subprocess.CompletedProcess[str]:
    """``script`` in a new bash that knows only what the README says to do first."""
    env = {"HOME": str(workdir), "PATH": "/usr/local/bin:/usr/bin:/bin", "LANG": "C.UTF-8"}
    return subprocess.run(
        ["bash", "-c", f"source {ROOT / '.venv' / 'bin' / 'activate'} && {script}"],
        cwd=workdir,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
        check=False,
        start_new_session=True,
    )


@pytest.fixture(scope="module")
def workdir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("readme")
    (folder / "examples").symlink_to(ROOT / "examples")
    return folder


def test_the_readme_says_how_to_put_cadkg_on_the_path() -> None:
    assert "source .venv/bin/activate" in README
    assert len(_commands()) >= 20  # the tour, the usage guide and each use case's


def test_every_readme_command_works_as_written(workdir: Path) -> None:
    failures = []
    for command in _commands():
        done = _fresh_shell(workdir, command)
        expected = next((s for prefix, s in EXPECTED_STATUS.items() if command.startswith(prefix)), 0)
        if done.returncode != expected:
            failures.append(f"{command}\n  exit {done.returncode}: {done.stderr.strip()[-400:]}")
    assert failures == []
    assert (workdir / "cell.graphml").is_file() and (workdir / "build" / "iema").is_dir()


def test_every_file_the_readme_names_exists() -> None:
    named = set(
        name
        for text in TEXTS
        for name in re.findall(
            r"\b(?:examples|docs|scripts|benchmarks)/[\w./-]+\.(?:rq|toml|md|sh|py)\b", text
        )
    )
    assert named
    assert sorted(p for p in named if not (ROOT / p).exists()) == []


def test_the_readme_python_block_runs(workdir: Path) -> None:
    blocks = _blocks("python")
    assert blocks
    for code in blocks:
        done = _fresh_shell(workdir, f"python - <<'EOF'\n{code}\nEOF")
        assert done.returncode == 0, done.stderr[-2000:]
    assert (workdir / "cell.ttl").stat().st_size > 0


def test_the_fresh_shell_has_no_cadkg_without_the_activate_line(workdir: Path) -> None:
    # The test above would pass on a machine with cadkg installed elsewhere: this one proves the
    # bare shell is bare, so the activate line is what puts cadkg on the PATH.
    env = {"HOME": str(workdir), "PATH": "/usr/local/bin:/usr/bin:/bin"}
    done = subprocess.run(
        ["bash", "-c", "command -v cadkg"], cwd=workdir, env=env, capture_output=True, text=True, check=False
    )
    assert done.returncode != 0 or ".venv" not in done.stdout
    assert os.access(ROOT / ".venv" / "bin" / "cadkg", os.X_OK)
