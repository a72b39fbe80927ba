"""``cadkg query`` on a local graph, evaluated in a forked child: without the network, within a
memory limit, and killed at its time limit (:mod:`cadkg.query.confinement`).

A fork costs milliseconds where a worker of :mod:`cadkg.query.workers` costs a new interpreter:
the child is this process as it is, before any store is open (so no database thread is left
half-way in it). It opens the graph, says so (the time limit and the memory limit count from
then), answers and prints; this process waits, kills it at its time limit, and turns a death
past its memory limit into one line.
"""

from __future__ import annotations

import codecs
import contextlib
import os
import select
import signal
import sys
import threading
import traceback
from collections.abc import Callable
from typing import TextIO

import click

from cadkg.cli.common import guarded
from cadkg.errors import QueryError, TimeLimitError
from cadkg.query.confinement import exceeded, leave_network, limit_memory, warn_unconfined

__all__ = ["run_confined"]

Work = Callable[[Callable[[], None]], None]


def run_confined(work: Work, *, seconds: float | None, memory: int, network: bool) -> None:
    """``work(ready)`` in a forked child that leaves the network first (unless ``network``);
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
    sys.stdout.flush()
    sys.stderr.flush()
    # A stream without a descriptor (click's test runner, a program that embeds the command) is
    # written by the child into a pipe this process copies into the stream.
    relays = {
        fd: os.pipe() for fd, stream in ((1, sys.stdout), (2, sys.stderr)) if not _has_descriptor(stream)
    }
    theirs_read, theirs_write = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(theirs_read)
        for fd, (relay_read, relay_write) in relays.items():
            os.close(relay_read)
            os.dup2(relay_write, fd)
            os.close(relay_write)
            _reopen(fd)
        os._exit(_child(work, theirs_write, memory, network))
    os.close(theirs_write)
    copies = []
    for fd, (relay_read, relay_write) in relays.items():
        os.close(relay_write)
        copy = threading.Thread(target=_copy, args=(relay_read, sys.stdout if fd == 1 else sys.stderr))
        copy.start()
        copies.append(copy)
    status: int | None = None
    try:
        opened = os.read(theirs_read, 1)  # nothing when the child ended before opening its graph
        if opened and seconds is not None:
            pidfd = os.pidfd_open(pid)
            try:
                ended, _, _ = select.select([pidfd], [], [], seconds)
            finally:
                os.close(pidfd)
            if not ended:
                raise TimeLimitError(f"the query ran past the time limit of {seconds:g} s and was stopped")
        status = os.waitpid(pid, 0)[1]
    finally:
        os.close(theirs_read)
        if status is None:
            with contextlib.suppress(ProcessLookupError, ChildProcessError):
                os.kill(pid, signal.SIGKILL)
                os.waitpid(pid, 0)
        for copy in copies:  # the child is gone: its pipes are at their end
            copy.join()
    if os.WIFSIGNALED(status):
        if memory:
            raise exceeded(memory)
        raise QueryError(f"the query's process ended by signal {os.WTERMSIG(status)}")
    if os.WEXITSTATUS(status):
        sys.exit(os.WEXITSTATUS(status))


def _has_descriptor(stream: TextIO) -> bool:
    try:
        stream.fileno()
    except (AttributeError, OSError, ValueError):  # io.UnsupportedOperation is both
        return False
    return True


def _reopen(fd: int) -> None:
    """In the child: its stdout (1) or stderr (2) on the descriptor, in the stream's encoding."""
    old = sys.stdout if fd == 1 else sys.stderr
    stream = os.fdopen(fd, "w", encoding=getattr(old, "encoding", None) or "utf-8", closefd=False)
    if fd == 1:
        sys.stdout = stream
    else:
        sys.stderr = stream


def _copy(source: int, stream: TextIO) -> None:
    """What the child wrote into the pipe ``source``, into ``stream``; then closes ``source``."""
    binary = getattr(stream, "buffer", None)
    text = codecs.getincrementaldecoder(getattr(stream, "encoding", None) or "utf-8")("replace")
    with os.fdopen(source, "rb") as pipe:
        for chunk in iter(lambda: pipe.read1(65536), b""):
            if binary is not None:
                binary.write(chunk)
            else:
                stream.write(text.decode(chunk))
    stream.flush()


def _quiet_native_stderr() -> None:
    """Python's stderr stays; what native code writes to descriptor 2 (the line pyoxigraph writes
    as it aborts past the memory limit) goes nowhere: the parent says it in one line."""
    sys.stderr.flush()
    kept = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    os.close(devnull)
    sys.stderr = os.fdopen(kept, "w", buffering=1)


def _child(work: Work, ready_fd: int, memory: int, network: bool) -> int:
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's, which kills this

    def ready() -> None:
        os.write(ready_fd, b".")
        os.close(ready_fd)
        limit_memory(memory)
        _quiet_native_stderr()

    @guarded
    def evaluate() -> None:
        if not network and (why := leave_network()) is not None:
            warn_unconfined(why)
        try:
            work(ready)
        except MemoryError:
            raise exceeded(memory) from None

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
