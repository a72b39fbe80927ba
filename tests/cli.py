"""The ``cadkg`` command as the tests run it: in this process (click's runner) for what a
command prints and exits with, in a new interpreter where the process itself is the point
(its signals, its children, its environment, a ``python -m cadkg.cli`` start)."""

from __future__ import annotations

import os
import subprocess
import sys
from collections.abc import Mapping
from pathlib import Path

from click.testing import CliRunner

from tests.conftest import ROOT

__all__ = ["CADKG", "run", "run_process"]

CADKG = [sys.executable, "-m", "cadkg.cli"]


def run(
    *args: str | Path, input: str | None = None, env: Mapping[str, str] | None = None
) -> subprocess.CompletedProcess[str]:
    """``cadkg ARGS`` in this process, from the checkout's root as a user would type it: the
    exit code, standard output and standard error a new process would give."""
    from cadkg.cli import cli

    here = Path.cwd()
    os.chdir(ROOT)
    try:
        result = CliRunner().invoke(
            cli, [str(a) for a in args], input=input, env=dict(env or {}), prog_name="cadkg"
        )
    finally:
        os.chdir(here)
    if result.exception is not None and not isinstance(result.exception, SystemExit):
        raise result.exception
    return subprocess.CompletedProcess(
        ["cadkg", *map(str, args)], result.exit_code, result.stdout, result.stderr
    )


def run_process(*args: str | Path, env: Mapping[str, str] | None = None) -> subprocess.CompletedProcess[str]:
    """``cadkg ARGS`` in a new interpreter (``python -m cadkg.cli``)."""
    return subprocess.run(
        [*CADKG, *map(str, args)],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=None if env is None else dict(env),
        check=False,
    )
