"""``cadkg query`` on a local graph, evaluated in a limited child (:mod:`cadkg.limited`):
without the network, within a memory limit, and killed at its time limit.

A fork costs milliseconds where a worker of :mod:`cadkg.query.workers` costs a new interpreter:
the child is this process as it is, before any store is open (so no database thread is left
half-way in it). It opens the graph, says so (the time limit and the memory limit count from
then), answers and prints; this process waits, kills it at its time limit, and turns a death
past its memory limit into one line.
"""

from __future__ import annotations

import contextlib
import os
import sys
import traceback
from collections.abc import Callable

import click

from cadkg.cli.common import guarded
from cadkg.limited import Limits, exceeded, run_limited

__all__ = ["run_limited_query"]

Work = Callable[[Callable[[], None]], None]


def run_limited_query(work: Work, *, seconds: float | None, memory: int, network: bool) -> None:
    """``work(ready)`` in a limited child that leaves the network first (unless ``network``);
    ``work`` calls ``ready()`` once its graph is open, and from then on may take ``memory`` MiB
    more (0: no limit) and ``seconds`` (``None``: no limit).

    Raises
    ------
    TimeLimitError
        When the time is up (the child is killed).
    MemoryLimitError
        When the child died past its memory limit.
    SystemExit
        With the child's exit code when it failed (it said why on stderr).
    """
    # A limit of 0 s is one already up, not none.
    wall = 0.0 if seconds is None else max(seconds, 1e-6)
    limits = Limits(memory=memory, wall=wall, network=network, wall_setting="--timeout")
    code = run_limited(_child, (work, limits), limits, ready=True, relay=True)
    if code:
        sys.exit(code)


def _quiet_native_stderr() -> None:
    """Python's stderr stays; what native code writes to descriptor 2 (the line pyoxigraph writes
    as it aborts past the memory limit) goes nowhere: the parent says it in one line."""
    sys.stderr.flush()
    kept = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    os.close(devnull)
    sys.stderr = os.fdopen(kept, "w", buffering=1)


def _child(ready: Callable[[], None], work: Work, limits: Limits) -> int:
    """In the child: ``work``, its errors printed as the command prints them; its exit code."""

    def opened() -> None:
        ready()
        _quiet_native_stderr()

    @guarded
    def evaluate() -> None:
        try:
            work(opened)
        except MemoryError:
            raise exceeded(limits, "memory") from None

    code = 0
    try:
        evaluate()
    except SystemExit as exit_:
        code = exit_.code if isinstance(exit_.code, int) else 1
    except click.ClickException as error:  # a usage error (a target that is not there): as click says it
        error.show()
        code = error.exit_code
    except BaseException:
        traceback.print_exc()
        code = 1
    finally:
        with contextlib.suppress(OSError, ValueError):
            sys.stdout.flush()
            sys.stderr.flush()
    return code
