"""The limits of a limited child, how a process puts them on itself, and what is said past one.

Memory is the data segment (``RLIMIT_DATA``: heap and private mappings, where a reader's records
and a query's solutions live) beyond what the process holds when the limits start. ``RLIMIT_AS``
would count the address space RocksDB reserves for its caches and the files it maps, hundreds of
MiB that vary from run to run; ``RLIMIT_DATA`` counts what the work can grow. An allocation past
it fails: Python raises ``MemoryError``, pyoxigraph and other native code abort their process,
which is why the limit is only ever set in a process made for the work.

CPU time is ``RLIMIT_CPU``: the kernel sends ``SIGXCPU`` at the limit (which ends the process) and
``SIGKILL`` a second later. Wall time is kept by the process waiting for the child, which kills
it (:mod:`cadkg.limited.child`).
"""

from __future__ import annotations

import math
import os
import resource
import signal
from dataclasses import dataclass
from pathlib import Path

from cadkg.errors import (
    CadkgError,
    IngestError,
    LimitError,
    MemoryLimitError,
    QueryError,
    ReadLimitError,
    TimeLimitError,
)

__all__ = [
    "DEFAULT_QUERY_MEMORY",
    "DEFAULT_READ_CPU",
    "DEFAULT_READ_MEMORY",
    "DEFAULT_READ_RATIO",
    "DEFAULT_READ_WALL",
    "OUT_OF_MEMORY",
    "READ_CPU_ENV",
    "READ_MEMORY_ENV",
    "READ_RATIO_ENV",
    "READ_WALL_ENV",
    "Limits",
    "cause",
    "exceeded",
    "limit_cpu",
    "limit_memory",
    "read_limits",
    "stopped",
]

DEFAULT_QUERY_MEMORY = 1024
"""MiB a query may take beyond the graph its process holds open (0: no limit)."""
READ_MEMORY_ENV = "CADKG_READ_LIMIT_MIB"
DEFAULT_READ_MEMORY = 1024
"""MiB the reader of one input file may take (0: no limit)."""
READ_CPU_ENV = "CADKG_READ_CPU_S"
DEFAULT_READ_CPU = 300
"""CPU seconds the reader of one input file may take (0: no limit). The largest real inputs and
the 100,000-wire synthetic cabinet read in well under a minute; five minutes leaves room for a
machine whose cores are shared, while a reader looping on a crafted file is stopped."""
READ_WALL_ENV = "CADKG_READ_WALL_S"
DEFAULT_READ_WALL = 600
"""Seconds a build may wait for the reader of one input file (0: no limit): twice the CPU
limit, as a loaded machine gives a reader half a core; a reader that waits on nothing (a hung
library, a file that never ends) holds no CPU and is stopped by this one."""

READ_RATIO_ENV = "CADKG_READ_RATIO"
DEFAULT_READ_RATIO = 256
"""Bytes the read of one input file may hand back per byte of the file (0: no limit): its
triples as N-Triples, the records its cell's derivation takes and the files beside its graph.
The bundled examples hand back at most 46 bytes a byte (an ID table; a file of a few hundred
bytes more, which the allowance below covers) and the synthetic cabinets' lists about 30; a
compressed workbook a few times what its text would. What follows a read (the loader, the
store, the derivation's inputs) grows with what it hands back, so this bounds them by the file."""
READ_RATIO_ALLOWANCE = 1 << 20
"""Bytes every file may hand back besides its ratio: the provenance of its graph, a small file's
few rows (docs/server.md, "Bounded memory on input files")."""

OUT_OF_MEMORY = 75
"""The exit code of a child that ran out of memory where a message may not fit any more."""
# A native library aborts on an allocation it cannot make (or crashes on the null it got); the
# kernel's OOM killer kills.
_MEMORY_SIGNALS = frozenset({signal.SIGABRT, signal.SIGKILL, signal.SIGSEGV, signal.SIGBUS})


@dataclass(frozen=True)
class Limits:
    """What a limited child may take, and what is said when it takes more.

    ``memory`` MiB of data segment, ``cpu`` seconds of CPU time, ``wall`` seconds of time,
    ``output`` bytes of what a streamed child sends back, ``ratio`` of them per byte of ``file``
    (each 0: no limit); ``network``: whether it keeps the network. ``file`` is the file read
    (else the work is a query); the ``*_setting`` fields name the option or variable that raises
    a limit.
    """

    memory: int = 0
    cpu: int = 0
    wall: float = 0.0
    network: bool = True
    file: str | None = None
    memory_setting: str = "--max-query-memory"
    cpu_setting: str = ""
    wall_setting: str = ""
    output: int = 0
    ratio: int = 0
    output_setting: str = ""

    @property
    def any(self) -> bool:
        """Whether any limit is set (without, the work may as well run where it is)."""
        return bool(self.memory or self.cpu or self.wall or self.output or not self.network)


def _setting(name: str, default: int, unit: str) -> int:
    text = os.environ.get(name, "").strip()
    if not text:
        return default
    if not (text.isascii() and text.isdigit() and len(text) <= 9):
        raise CadkgError(f"{name}={text[:40]!r}: expected a whole number of {unit} (0: no limit)")
    return int(text)


def read_limits(path: str | Path) -> Limits:
    """The limits of reading ``path``: the ``CADKG_READ_*`` variables where set, else the defaults.
    What the read hands back is bounded by the size of ``path`` (a file that is not there, by
    the allowance alone).

    Raises
    ------
    CadkgError
        When a variable is not a whole number.
    """
    ratio = _setting(READ_RATIO_ENV, DEFAULT_READ_RATIO, "bytes per byte of the file")
    try:
        size = Path(path).stat().st_size
    except OSError:
        size = 0
    return Limits(
        memory=_setting(READ_MEMORY_ENV, DEFAULT_READ_MEMORY, "MiB"),
        cpu=_setting(READ_CPU_ENV, DEFAULT_READ_CPU, "seconds"),
        wall=_setting(READ_WALL_ENV, DEFAULT_READ_WALL, "seconds"),
        file=str(path),
        memory_setting=READ_MEMORY_ENV,
        cpu_setting=READ_CPU_ENV,
        wall_setting=READ_WALL_ENV,
        output=ratio * size + READ_RATIO_ALLOWANCE if ratio else 0,
        ratio=ratio,
        output_setting=READ_RATIO_ENV,
    )


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


def _lower(which: int, soft: int, hard: int) -> None:
    _, kept = resource.getrlimit(which)
    if kept != resource.RLIM_INFINITY:
        soft, hard = min(soft, kept), min(hard, kept)
    resource.setrlimit(which, (soft, hard))


def limit_memory(mib: int) -> None:
    """Let this process's data segment grow by at most ``mib`` MiB from now (0: no limit)."""
    if mib <= 0:
        return
    limit = _data_size() + (mib << 20)
    _lower(resource.RLIMIT_DATA, limit, limit)
    # pyoxigraph aborts on a failed allocation: one line on stderr, not a backtrace.
    os.environ["RUST_BACKTRACE"] = "0"


def limit_cpu(seconds: int) -> None:
    """Let this process use at most ``seconds`` more of CPU time (0: no limit)."""
    if seconds <= 0:
        return
    used = resource.getrusage(resource.RUSAGE_SELF)
    soft = math.ceil(used.ru_utime + used.ru_stime) + seconds
    # SIGXCPU would dump a core by default: the parent says what happened in one line.
    _lower(resource.RLIMIT_CORE, 0, 0)
    _lower(resource.RLIMIT_CPU, soft, soft + 1)


def exceeded(limits: Limits, limit: str) -> LimitError:
    """The error of work stopped at its ``limit`` (``"memory"``, ``"cpu"``, ``"wall"`` or, of a
    file's read, ``"output"``)."""
    if limits.file is not None:
        reason = {
            "memory": f"needs more than {limits.memory:,} MiB to read",
            "cpu": f"needs more than {limits.cpu:,} s of CPU time to read",
            "wall": f"took more than {limits.wall:g} s to read and was stopped",
            "output": f"gives more than {limits.ratio:,} bytes of triples and records per byte of "
            f"the file ({limits.output / (1 << 20):,.1f} MiB in all) and was stopped",
        }[limit]
        setting = getattr(limits, f"{limit}_setting")
        return ReadLimitError(limits.file, f"{reason} (limit set by {setting})", limit=limit)
    if limit == "memory":
        return MemoryLimitError(
            f"the query needed more than the {limits.memory} MiB of memory a query may take and was "
            f"stopped ({limits.memory_setting})"
        )
    error = TimeLimitError(
        f"the query ran past the time limit of {limits.wall:g} s and was stopped"
        if limit == "wall"
        else f"the query needed more than {limits.cpu} s of CPU time and was stopped"
    )
    error.limit = limit
    setting = getattr(limits, f"{limit}_setting")
    if setting:
        error.args = (f"{error.args[0]} ({setting})",)
    return error


def cause(limits: Limits, status: int, cpu_used: float | None = None) -> str | None:
    """Which limit a child that ended with ``status`` (an exit code, a negative signal number)
    ran into, if one: ``"cpu"`` or ``"memory"``; ``None`` when it ended otherwise."""
    if limits.cpu and (
        status == -signal.SIGXCPU or (status == -signal.SIGKILL and (cpu_used or 0.0) >= limits.cpu)
    ):
        return "cpu"
    if limits.memory and (status == OUT_OF_MEMORY or (status < 0 and -status in _MEMORY_SIGNALS)):
        return "memory"
    return None


def stopped(limits: Limits, status: int) -> CadkgError:
    """The error of a child that ended with ``status`` before it finished, at no limit."""
    how = f"signal {signal.Signals(-status).name}" if status < 0 else f"exit status {status}"
    if limits.file is not None:
        return IngestError(
            limits.file, f"its reader stopped ({how}) before it finished", expected="a readable file"
        )
    if status < 0:
        return QueryError(f"the query's process ended by signal {-status}")
    return QueryError(f"the query's process ended with {how}")
