"""A store directory on disk: its generations, the pointer to the live one, and who holds what.

A store directory holds generations (``gen-*/``, each a complete oxigraph database) and a
``CURRENT`` file naming the live one. A build writes a new generation and then replaces
``CURRENT`` with one atomic rename, so a failed build leaves the previous store exactly as it
was and readers never see half a build.

A build killed before its end leaves its generation behind. Each build therefore holds an
exclusive ``flock`` on ``.gen-*.lock`` beside its generation while it writes (the kernel drops it
when the process dies, however it dies), and the next successful build into the directory
removes every generation that is neither live, nor the one live before it (``PREVIOUS``, kept
for ``cadkg diff STORE``), nor held. The query workers of ``cadkg serve``
read a snapshot of the store (:func:`take_snapshot`), held the same way while served.
"""

from __future__ import annotations

import contextlib
import fcntl
import gc
import os
import shutil
import signal
import tempfile
import threading
import time
import uuid
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pyoxigraph as ox

from cadkg.errors import StoreError

__all__ = [
    "PREVIOUS",
    "Claim",
    "Snapshot",
    "checkpoint",
    "claim",
    "crash_point",
    "current_generation",
    "new_generation",
    "open_writable",
    "publish_generation",
    "read_pointer",
    "remove_stale",
    "take_snapshot",
    "writing",
]

CURRENT = "CURRENT"
PREVIOUS = "PREVIOUS"  # names the generation live before the current one
GENERATION = "gen-"  # the name of each generation directory starts so
SNAPSHOT = ".snapshot-"  # and of each snapshot the query workers read
_LOCK = ".lock"
WRITER = "WRITER"  # the lock (``.WRITER.lock``) every change of a store directory holds
KILL_AT = "CADKG_KILL_AT"
_SCRATCH = "cadkg-snapshot-"  # a snapshot of an in-memory graph, in the temporary directory


def read_pointer(directory: Path, pointer: str = CURRENT) -> str | None:
    try:
        return (directory / pointer).read_text(encoding="utf-8").strip() or None
    except FileNotFoundError:
        return None


def current_generation(directory: Path) -> Path:
    """The live generation of a store directory.

    Raises
    ------
    StoreError
        When the directory is not a store or its live generation is missing.
    """
    name = read_pointer(directory)
    if name is None:
        raise StoreError(f"{directory}: not a cadkg store (no {CURRENT} file); build one with 'cadkg build'")
    generation = directory / name
    if not generation.is_dir():
        raise StoreError(f"{directory}: {CURRENT} names {name!r}, which is missing")
    return generation


def _left_by_a_build(entry: Path) -> bool:
    """Whether ``entry`` is what a build killed before its end leaves: a generation, its lock
    or a pointer."""
    if entry.is_dir():
        return entry.name.startswith(GENERATION)
    return entry.name.startswith((f".{CURRENT}.{GENERATION}", f".{GENERATION}", f".{WRITER}"))


def new_generation(directory: Path) -> Path:
    """The path of a new generation in the store directory ``directory`` (made if missing).

    Raises
    ------
    StoreError
        When ``directory`` holds something other than a store or what a killed build left.
    """
    if (
        directory.exists()
        and not (directory / CURRENT).exists()
        and not all(_left_by_a_build(entry) for entry in directory.iterdir())
    ):
        raise StoreError(f"{directory}: exists and is not a cadkg store; refusing to write into it")
    directory.mkdir(parents=True, exist_ok=True)
    return directory / f"{GENERATION}{time.strftime('%Y%m%dT%H%M%S')}-{uuid.uuid4().hex[:8]}"


class Claim:
    """An exclusive ``flock`` on the lock file of one generation or snapshot (``.NAME.lock``)."""

    def __init__(self, path: Path, fd: int) -> None:
        self.path = path
        self._fd: int | None = fd

    def release(self) -> None:
        """Remove the lock file, then let the lock go (in this order, so nobody takes a lock on
        a file about to vanish)."""
        if self._fd is None:
            return
        with contextlib.suppress(OSError):
            self.path.unlink()
        os.close(self._fd)
        self._fd = None


def claim(entry: Path, *, wait: bool = True) -> Claim | None:
    """Hold the lock of ``entry`` (a generation or snapshot directory, made or not yet).

    Returns ``None`` when ``wait`` is false and another process holds it.
    """
    path = entry.with_name(f"{'' if entry.name.startswith('.') else '.'}{entry.name}{_LOCK}")
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | (0 if wait else fcntl.LOCK_NB))
        except BlockingIOError:
            os.close(fd)
            return None
        # The holder before us may have removed the file once done: a lock on a removed file
        # protects nothing, so take the one now at that path.
        try:
            same = os.fstat(fd).st_ino == path.stat().st_ino
        except FileNotFoundError:
            same = False
        if same:
            return Claim(path, fd)
        os.close(fd)


def crash_point(step: str) -> None:
    """Where a change of a store directory may be cut short. The tests name one step in the
    environment variable ``CADKG_KILL_AT`` to kill the process there with SIGKILL, and check
    the store is as before the change or as after it."""
    if os.environ.get(KILL_AT) == step:
        os.kill(os.getpid(), signal.SIGKILL)


_HELD: dict[str, tuple[threading.RLock, list[Any]]] = {}
_HELD_LOCK = threading.Lock()


@contextlib.contextmanager
def writing(directory: Path) -> Iterator[None]:
    """Hold the writer lock of a store directory: one build or change at a time, so a change
    made meanwhile is never written into a generation a build is about to replace. Waits for
    the holder; the kernel lets it go when its process dies. A thread holding it may take it
    again (a change inside a larger one); other threads of the process wait as others do."""
    key = os.path.realpath(directory)
    with _HELD_LOCK:
        thread_lock, state = _HELD.setdefault(key, (threading.RLock(), [None, 0]))
    with thread_lock:
        if state[1] == 0:
            state[0] = claim(directory / WRITER)
        state[1] += 1
        try:
            yield
        finally:
            state[1] -= 1
            if state[1] == 0:
                state[0].release()
                state[0] = None


# How long a change waits for the process that built a generation to let its database go.
_OPEN_WAIT = 60.0


def open_writable(generation: Path) -> ox.Store:
    """The database of ``generation`` opened for writing, once the build that made it (which
    holds it open until its command ends) lets it go.

    Raises
    ------
    StoreError
        When it cannot be opened, or is still held by another process after a minute.
    """
    deadline = time.monotonic() + _OPEN_WAIT
    while True:
        try:
            return ox.Store(str(generation))
        except OSError as err:
            if "lock" not in str(err).lower() or time.monotonic() > deadline:
                raise StoreError(f"{generation.parent}: cannot open the store for writing: {err}") from None
        time.sleep(0.1)


@contextlib.contextmanager
def checkpoint(store: ox.Store, live: Path, directory: Path, files: str) -> Iterator[Path]:
    """A new generation of ``directory`` copied from ``store`` (the live generation ``live``'s
    database; its folder ``files`` as hard links). The block changes it; when the block ends it
    is published (:func:`publish_generation`), when it raises it is removed. The caller drops
    every handle on the live database before the block ends (its files go then)."""
    fresh = new_generation(directory)
    held = claim(fresh)
    assert held is not None  # claim() waits for the lock
    published = False
    try:
        store.flush()
        store.backup(str(fresh))
        del store  # no handle kept here on the live database
        if (live / files).is_dir():
            shutil.copytree(live / files, fresh / files, copy_function=os.link)
        crash_point("change:copied")
        yield fresh
        gc.collect()  # the live database closes before its files are removed
        publish_generation(directory, fresh)
        published = True
        crash_point("change:published")
    finally:
        if not published and read_pointer(directory) != fresh.name:
            gc.collect()
            shutil.rmtree(fresh, ignore_errors=True)
        held.release()


def remove_stale(directory: Path, keep: str | None = None) -> list[str]:
    """Remove the generations and snapshots of ``directory`` that are neither live, nor the
    previous one, nor ``keep``, nor held by a running process; returns their names."""
    live = {read_pointer(directory), read_pointer(directory, PREVIOUS), keep}
    removed = []
    for entry in sorted(directory.iterdir()):
        name = entry.name
        if entry.is_dir():
            if name in live or not name.startswith((GENERATION, SNAPSHOT)):
                continue
        elif name.startswith((f".{GENERATION}", SNAPSHOT)) and name.endswith(_LOCK):
            # A lock whose directory is gone: its build died before making it, or this ran before.
            base = name.removesuffix(_LOCK)
            entry = entry.with_name(base if base.startswith(SNAPSHOT) else base.removeprefix("."))
            if entry.exists():
                continue
        else:
            continue
        if _remove_unheld(entry):
            with contextlib.suppress(OSError):
                (directory / f".{CURRENT}.{entry.name}").unlink()
            removed.append(entry.name)
    return removed


def _remove_unheld(entry: Path) -> bool:
    """Remove ``entry`` unless a live process holds it; whether it was removed."""
    held = claim(entry, wait=False)
    if held is None:
        return False
    shutil.rmtree(entry, ignore_errors=True)
    held.release()
    return True


def publish_generation(directory: Path, generation: Path) -> None:
    """Make the complete ``generation`` the live one with one atomic rename; keep the one it
    replaces as ``PREVIOUS``, and drop the one before and whatever killed builds and servers
    left (:func:`remove_stale`)."""
    name = generation.name
    pointer = directory / f".{CURRENT}.{name}"
    pointer.write_text(name + "\n", encoding="utf-8")
    crash_point("publish:pointer-written")
    previous = read_pointer(directory)
    pointer.replace(directory / CURRENT)
    crash_point("publish:renamed")
    if previous is not None and previous != name:
        kept = directory / f".{PREVIOUS}.{name}"
        kept.write_text(previous + "\n", encoding="utf-8")
        kept.replace(directory / PREVIOUS)
    remove_stale(directory, keep=name)


@dataclass
class Snapshot:
    """A store directory other processes open read-only, holding a graph as it was taken;
    :meth:`remove` deletes ``scratch`` (what was written for it, if anything)."""

    path: Path
    scratch: Path | None = None
    held: Claim | None = None

    def remove(self) -> None:
        if self.scratch is not None:
            shutil.rmtree(self.scratch, ignore_errors=True)
        if self.held is not None:
            self.held.release()


def take_snapshot(store: ox.Store, directory: Path | None, generation: Path | None) -> Snapshot:
    """A read-only copy of ``store`` for worker processes.

    An on-disk store is checkpointed beside its generations (hard links: cheap, and unaffected
    when a rebuild deletes the generation), under a claim a later build respects; where that
    cannot be written, the generation itself is used. An in-memory store is written whole to a
    temporary store (about 20 µs a triple), held the same way; those of killed processes are
    removed by the next one taken.
    """
    if directory is not None and generation is not None:
        target = directory / f"{SNAPSHOT}{uuid.uuid4().hex[:12]}"
        held = claim(target)
        try:
            assert held is not None
            store.backup(str(target))
            return Snapshot(target, target, held)
        except OSError:
            shutil.rmtree(target, ignore_errors=True)
            if held is not None:
                held.release()
            return Snapshot(generation)
    temporary = Path(tempfile.gettempdir())
    for left in temporary.glob(f"{_SCRATCH}*"):  # by servers killed before they removed theirs
        with contextlib.suppress(OSError):
            if left.is_dir() and left.stat().st_uid == os.getuid():
                _remove_unheld(left)
    scratch = temporary / f"{_SCRATCH}{uuid.uuid4().hex[:12]}"
    held = claim(scratch)  # before it exists, so no sweep removes it meanwhile
    try:
        scratch.mkdir(mode=0o700)
        dump = scratch / "graph.nq"
        store.dump(output=str(dump), format=ox.RdfFormat.N_QUADS)
        copy = ox.Store(str(scratch / "store"))
        copy.bulk_load(path=str(dump), format=ox.RdfFormat.N_QUADS)
        copy.flush()
        del copy
        dump.unlink()
    except BaseException:
        shutil.rmtree(scratch, ignore_errors=True)
        if held is not None:
            held.release()
        raise
    return Snapshot(scratch / "store", scratch, held)
