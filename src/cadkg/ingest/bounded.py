"""Reading an input file in a child process that may use only so much memory.

The pre-scans of workbooks and scenes refuse the bombs they recognise, with the cell or line
that crosses a limit; this is what holds when one is not recognised. Every input file is read
by its reader in a process forked for it, whose data segment may grow by at most the read
limit (``RLIMIT_DATA`` on top of what it inherits); the records come back pickled, in batches,
while the reader is still going. A reader that runs out of memory there (a Python
``MemoryError``, or a native library aborting on a failed allocation) ends its own process, and
the caller gets one line: ``file: needs more than N MiB to read``.

The limit is :data:`DEFAULT_LIMIT_MIB` MiB unless the environment variable named by
:data:`LIMIT_ENV` sets another (``0`` reads in the calling process, unbounded). Forking costs a
few milliseconds a file, and it keeps in the child what the caller registered in Python (a
notebook's reader); where there is no ``fork`` (not POSIX) files are read in the calling
process.
"""

from __future__ import annotations

import contextlib
import faulthandler
import gc
import os
import pickle
import resource
import signal
import struct
import warnings
from collections.abc import Callable, Generator, Iterable
from itertools import islice
from pathlib import Path
from typing import Any

from cadkg.errors import CadkgError, IngestError

__all__ = ["DEFAULT_LIMIT_MIB", "LIMIT_ENV", "read_bounded", "read_limit_mib"]

LIMIT_ENV = "CADKG_READ_LIMIT_MIB"
DEFAULT_LIMIT_MIB = 1024
_BATCH = 2000
_HEADER = struct.Struct("<Q")
# How the child says it ran out of memory where a message may not fit any more.
_OUT_OF_MEMORY = 75
# A native library aborts on an allocation it cannot make; the kernel's OOM killer kills.
_MEMORY_SIGNALS = (-signal.SIGABRT, -signal.SIGKILL)


def read_limit_mib() -> int:
    """The read limit in MiB: :data:`LIMIT_ENV` when set, else :data:`DEFAULT_LIMIT_MIB`.

    Raises
    ------
    CadkgError
        When the variable is not a whole number of MiB.
    """
    text = os.environ.get(LIMIT_ENV, "").strip()
    if not text:
        return DEFAULT_LIMIT_MIB
    if not (text.isascii() and text.isdigit() and len(text) <= 9):
        raise CadkgError(f"{LIMIT_ENV}={text[:40]!r}: expected a whole number of MiB (0: no limit)")
    return int(text)


def read_bounded(
    path: str | Path, read: Callable[..., Iterable[object]], *args: Any
) -> Generator[object, None, None]:
    """The items of ``read(*args)``, computed in a child process under the read limit.

    Warnings the reader gives are given again here, after its last item; its exceptions are
    raised here. Closing the iterator early stops the child.

    Raises
    ------
    IngestError
        ``path: needs more than N MiB to read`` when the child runs out of memory, or when it
        dies otherwise; and whatever ``read`` raises.
    """
    limit = read_limit_mib()
    if limit == 0 or not hasattr(os, "fork"):
        yield from read(*args)
        return
    readable, writable = os.pipe()
    with warnings.catch_warnings():
        # Python 3.12 warns of forking a process with threads (a build's loader, a server's
        # requests): the child runs only the reader and the pipe, and touches no lock of theirs.
        warnings.simplefilter("ignore", DeprecationWarning)
        pid = os.fork()
    if pid == 0:  # pragma: no cover - the child; its coverage is not collected
        os.close(readable)
        _child(writable, limit, read, args)
    os.close(writable)
    ended = reaped = False  # whether the child said all it had to say; whether it is reaped
    try:
        with os.fdopen(readable, "rb") as stream:
            while (message := _receive(stream)) is not None:
                what, value = message
                if what == "items":
                    yield from value
                elif what == "warnings":
                    for category, text in value:
                        warnings.warn(text, category, stacklevel=2)
                elif what == "error":
                    ended = True
                    raise value
                else:
                    ended = True
                    return
        status = _reap(pid)
        reaped = True
        raise _died(path, status, limit)
    finally:
        # A child that has not ended (the caller stopped early) is killed. Reaped once only:
        # the pid is ours until then, and may be another read's child after.
        if not reaped:
            if not ended:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(pid, signal.SIGKILL)
            _reap(pid)


def _child(fd: int, limit: int, read: Callable[..., Iterable[object]], args: tuple[Any, ...]) -> None:
    code = 1
    try:
        with os.fdopen(fd, "wb") as stream:
            code = _serve(stream, limit, read, args)
    except MemoryError:
        code = _OUT_OF_MEMORY
    except BaseException:
        code = 1
    finally:
        os._exit(code)


def _serve(stream: Any, limit: int, read: Callable[..., Iterable[object]], args: tuple[Any, ...]) -> int:
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    # The collector would walk (and, writing to them, copy) every object the child inherited,
    # again and again as the reader allocates: they are left out of its reach.
    gc.freeze()
    # What the child has to say comes through the pipe: a native library's words on its way
    # down (an allocation that failed, a backtrace) would break the caller's one line.
    faulthandler.disable()
    quiet = os.open(os.devnull, os.O_WRONLY)
    os.dup2(quiet, 2)
    os.close(quiet)
    inherited = _data_size()
    resource.setrlimit(resource.RLIMIT_DATA, (inherited + (limit << 20), resource.RLIM_INFINITY))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            items = iter(read(*args))
            while batch := list(islice(items, _BATCH)):
                _send(stream, ("items", batch))
        except MemoryError:
            return _OUT_OF_MEMORY
        except Exception as err:
            _send(stream, ("error", _picklable(err)))
            return 0
    _send(stream, ("warnings", [(w.category, w.message) for w in caught]))
    _send(stream, ("end", None))
    return 0


def _data_size() -> int:
    """The bytes of the data segment and private mappings the process holds (``VmData``)."""
    try:
        with Path("/proc/self/status").open("rb") as status:
            for line in status:
                if line.startswith(b"VmData:"):
                    return int(line.split()[1]) << 10
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss << 10


def _picklable(err: Exception) -> Exception:
    try:
        pickle.loads(pickle.dumps(err))
    except Exception:
        return CadkgError(f"{type(err).__name__}: {err}")
    return err


def _send(stream: Any, message: object) -> None:
    data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(_HEADER.pack(len(data)))
    stream.write(data)
    stream.flush()


def _receive(stream: Any) -> Any:
    header = stream.read(_HEADER.size)
    if len(header) < _HEADER.size:
        return None
    (size,) = _HEADER.unpack(header)
    data = stream.read(size)
    if len(data) < size:
        return None
    return pickle.loads(data)


def _reap(pid: int) -> int:
    """The child's exit code (a negative signal number); 0 once it has been reaped."""
    try:
        return os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])
    except ChildProcessError:
        return 0


def _died(path: str | Path, status: int, limit: int) -> IngestError:
    if status == _OUT_OF_MEMORY or status in _MEMORY_SIGNALS:
        return IngestError(path, f"needs more than {limit:,} MiB to read (limit set by {LIMIT_ENV})")
    how = f"signal {signal.Signals(-status).name}" if status < 0 else f"exit status {status}"
    return IngestError(path, f"its reader stopped ({how}) before it finished", expected="a readable file")
