"""Untrusted work in a forked child under :class:`~cadkg.limited.limits.Limits`.

A fork costs milliseconds and keeps in the child what the caller registered in Python (a
notebook's reader). The child makes a process group of its own, dies with its parent, leaves
the network unless it may keep it, puts its memory and CPU limits on itself, and runs the work;
what it returns (or raises) comes back pickled through a pipe. The parent waits on that pipe no
longer than the wall limit, counting only the time it waits (not the time its caller spends on
what came back), and then kills the child's whole process group. A child that dies past a limit
is told apart by how it ended (its exit code or signal, its CPU time) and said as one
:class:`~cadkg.errors.LimitError`.
"""

from __future__ import annotations

import codecs
import contextlib
import ctypes
import faulthandler
import gc
import os
import pickle
import select
import signal
import struct
import sys
import threading
import time
import warnings
from collections.abc import Callable, Generator, Iterable, Iterator
from pathlib import Path
from typing import Any, TextIO

from cadkg.errors import CadkgError
from cadkg.limited.limits import (
    OUT_OF_MEMORY,
    Limits,
    cause,
    exceeded,
    limit_cpu,
    limit_memory,
    read_limits,
    stopped,
)
from cadkg.limited.network import leave_network, warn_unconfined

__all__ = ["read_limited", "run_limited", "stream_limited"]

_BATCH = 2000
_HEADER = struct.Struct("<Q")
_PR_SET_PDEATHSIG = 1


class _Child:
    """The parent's end of one child: its pid, the pipe from it, and the time waited for it."""

    def __init__(self, limits: Limits, body: Callable[[Any], int], *, relay: bool = False) -> None:
        self.limits = limits
        self.waited = 0.0
        sys.stdout.flush()
        sys.stderr.flush()
        # A stream without a descriptor (click's test runner, a program that embeds a command)
        # is written by the child into a pipe this process copies into the stream.
        relays = {
            fd: os.pipe()
            for fd, stream in ((1, sys.stdout), (2, sys.stderr))
            if relay and not _has_descriptor(stream)
        }
        readable, writable = os.pipe()
        with warnings.catch_warnings():
            # Python 3.12 warns of forking a process with threads (a build's loader, a server's
            # requests): the child runs only the work and the pipe, and touches no lock of theirs.
            warnings.simplefilter("ignore", DeprecationWarning)
            pid = os.fork()
        if pid == 0:  # pragma: no cover - the child; its coverage is not collected
            os.close(readable)
            code = 1
            try:
                for fd, (relay_read, relay_write) in relays.items():
                    os.close(relay_read)
                    os.dup2(relay_write, fd)
                    os.close(relay_write)
                    _reopen(fd)
                with os.fdopen(writable, "wb") as stream:
                    _settle(limits)
                    code = body(stream)
            except MemoryError:
                code = OUT_OF_MEMORY
            except BaseException:
                code = 1
            finally:
                os._exit(code)
        os.close(writable)
        self.copies = []
        for fd, (relay_read, relay_write) in relays.items():
            os.close(relay_write)
            copy = threading.Thread(target=_copy, args=(relay_read, sys.stdout if fd == 1 else sys.stderr))
            copy.start()
            self.copies.append(copy)
        # Both ends set the group, so it is the child's own before either relies on it.
        with contextlib.suppress(OSError):
            os.setpgid(pid, pid)
        self.pid = pid
        self.pipe = os.fdopen(readable, "rb", buffering=0)
        self.clock = True
        self.reaped = False

    def receive(self) -> Any:
        """The child's next message; ``None`` once it has said all it will.

        Raises
        ------
        LimitError
            When the wall limit is up first (the child is killed).
        """
        if self.clock and self.limits.wall:
            left = self.limits.wall - self.waited
            started = time.monotonic()
            ready = left > 0 and select.select([self.pipe], [], [], left)[0]
            self.waited += time.monotonic() - started
            if not ready:
                self.kill()
                raise exceeded(self.limits, "wall")
        header = self._read(_HEADER.size)
        if header is None:
            return None
        data = self._read(_HEADER.unpack(header)[0])
        return None if data is None else pickle.loads(data)

    def _read(self, size: int) -> bytes | None:
        chunks = []
        while size:
            chunk = self.pipe.read(size)
            if not chunk:
                return None
            chunks.append(chunk)
            size -= len(chunk)
        return b"".join(chunks)

    def ended(self) -> CadkgError:
        """The error of a child that stopped without its last word."""
        status, cpu = self.reap()
        limit = cause(self.limits, status, cpu)
        return exceeded(self.limits, limit) if limit else stopped(self.limits, status)

    def reap(self) -> tuple[int, float]:
        """The child's exit code (a negative signal number) and the CPU seconds it used."""
        self.reaped = True
        try:
            _, status, usage = os.wait4(self.pid, 0)
        except ChildProcessError:
            return 0, 0.0
        return os.waitstatus_to_exitcode(status), usage.ru_utime + usage.ru_stime

    def kill(self) -> None:
        for kill in (os.killpg, os.kill):
            with contextlib.suppress(ProcessLookupError, PermissionError):
                kill(self.pid, signal.SIGKILL)

    def close(self, *, ended: bool) -> None:
        """Kill the child unless it said its last word, reap it (once: its pid may be another
        child's after), close the pipe."""
        if not self.reaped:
            if not ended:
                self.kill()
            self.reap()
        self.pipe.close()
        for copy in self.copies:  # the child is gone: its pipes are at their end
            copy.join()


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


def _settle(limits: Limits) -> None:
    """In the child, before the work: its own group, no Ctrl-C, no network if so limited."""
    os.setpgid(0, 0)
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    # Ctrl-C is the parent's, which kills this; a write to a terminal from this group must not
    # stop it (``stty tostop``).
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTTOU, signal.SIG_IGN)
    # The collector would walk (and, writing to them, copy) every object the child inherited,
    # again and again as the work allocates: they are left out of its reach.
    gc.freeze()
    if not limits.network and (why := leave_network()) is not None:
        warn_unconfined(why)


def _limit(limits: Limits) -> None:
    limit_memory(limits.memory)
    limit_cpu(limits.cpu)


def _send(stream: Any, message: object) -> int:
    """Send ``message``; the bytes it took."""
    return _send_packed(stream, pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL))


def _send_packed(stream: Any, data: bytes) -> int:
    stream.write(_HEADER.pack(len(data)))
    stream.write(data)
    stream.flush()
    return len(data)


def _batches(items: Iterable[object]) -> Iterator[list[object]]:
    """``items`` in lists of up to ``_BATCH``; a ``bytes`` item (a chunk of triples, already a
    batch of its own) ends its list, so it is sent while the work goes on."""
    batch: list[object] = []
    for item in items:
        batch.append(item)
        if len(batch) >= _BATCH or type(item) is bytes:
            yield batch
            batch = []
    if batch:
        yield batch


def _picklable(err: BaseException) -> BaseException:
    try:
        pickle.loads(pickle.dumps(err))
    except Exception:
        return CadkgError(f"{type(err).__name__}: {err}")
    return err


def _failed(stream: Any, limits: Limits, err: BaseException) -> int:
    """Send ``err``; a ``MemoryError`` past the memory limit ends the child instead (its message
    may not fit any more, and the parent knows what it means)."""
    if isinstance(err, MemoryError) and limits.memory:
        return OUT_OF_MEMORY
    _send(stream, ("error", _picklable(err)))
    return 0


def stream_limited(
    read: Callable[..., Iterable[object]], args: tuple[Any, ...], limits: Limits
) -> Generator[object, None, None]:
    """The items of ``read(*args)``, computed in a limited child and sent in batches while it
    goes on. Warnings it gives are given again here after its last item; its exceptions are
    raised here. Closing the iterator early stops the child. Raises as :func:`run_limited`, and
    past ``limits.output`` bytes of items sent (pickled), ``exceeded(limits, "output")``: the
    child stops before it sends the batch that would pass it.
    """

    def body(stream: Any) -> int:
        # What the child has to say comes through the pipe: a native library's words on its way
        # down (an allocation that failed, a backtrace) would break the caller's one line.
        faulthandler.disable()
        quiet = os.open(os.devnull, os.O_WRONLY)
        os.dup2(quiet, 2)
        os.close(quiet)
        _limit(limits)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                sent = 0
                for batch in _batches(read(*args)):
                    data = pickle.dumps(("items", batch), protocol=pickle.HIGHEST_PROTOCOL)
                    sent += len(data)
                    if limits.output and sent > limits.output:
                        raise exceeded(limits, "output")
                    _send_packed(stream, data)
                    del data, batch
            except Exception as err:  # MemoryError included
                return _failed(stream, limits, err)
        _send(stream, ("warnings", [(w.category, w.message) for w in caught]))
        _send(stream, ("end", None))
        return 0

    child = _Child(limits, body)
    ended = False
    try:
        while (message := child.receive()) is not None:
            what, value = message
            if what == "items":
                yield from value
            elif what == "warnings":
                for category, text in value:
                    warnings.warn(text, category, stacklevel=2)
            else:
                ended = True
                if what == "error":
                    raise value
                return
        raise child.ended()
    finally:
        child.close(ended=ended)


def run_limited(
    function: Callable[..., Any],
    args: tuple[Any, ...],
    limits: Limits,
    *,
    ready: bool = False,
    relay: bool = False,
) -> Any:
    """``function(*args)`` in a limited child; what it returns (pickled), or its exception.

    With ``ready``, ``function`` is called as ``function(ready, *args)`` and calls ``ready()``
    once it has done what is not to be limited (opened its graph): the memory and CPU limits,
    and the wall clock, start then. With ``relay``, what the child prints reaches this
    process's ``sys.stdout`` and ``sys.stderr`` even where they have no descriptor.

    Raises
    ------
    LimitError
        Past a limit (:func:`cadkg.limited.limits.exceeded`).
    CadkgError
        When the child died otherwise; and whatever ``function`` raises.
    """

    def body(stream: Any) -> int:
        def started() -> None:
            _send(stream, ("ready", None))
            _limit(limits)

        try:
            if ready:
                value = function(started, *args)
            else:
                _limit(limits)
                value = function(*args)
        except Exception as err:  # MemoryError included
            return _failed(stream, limits, err)
        _send(stream, ("value", value))
        return 0

    child = _Child(limits, body, relay=relay)
    child.clock = not ready
    ended = False
    try:
        while (message := child.receive()) is not None:
            what, value = message
            if what == "ready":
                child.clock = True
                continue
            ended = True
            if what == "error":
                raise value
            return value
        raise child.ended()
    finally:
        child.close(ended=ended)


def read_limited(
    path: str | Path, read: Callable[..., Iterable[object]], *args: Any
) -> Generator[object, None, None]:
    """The items of ``read(*args)``, the reader of the file ``path``, read in a limited child
    under :func:`~cadkg.limited.limits.read_limits` (with every limit 0, or where there is no
    ``fork``, in this process).

    Raises
    ------
    ReadLimitError
        ``path: needs more than N MiB to read (limit set by CADKG_READ_LIMIT_MIB)``, and the
        same of CPU time (``CADKG_READ_CPU_S``), time (``CADKG_READ_WALL_S``) and what the read
        gives back per byte of ``path`` (``CADKG_READ_RATIO``).
    IngestError
        When the child died otherwise; and whatever ``read`` raises.
    """
    limits = read_limits(path)
    if not limits.any or not hasattr(os, "fork"):
        yield from read(*args)
        return
    yield from stream_limited(read, args, limits)
