"""Loading N-Triples into a pyoxigraph store on a thread of its own.

pyoxigraph parses and indexes without holding the GIL, so while one chunk of a
source is loaded the mapping (pure Python) goes on with the next: a build costs
about the longer of the two instead of their sum. In memory the chunks are loaded
one by one (:class:`BackgroundLoader`); on disk each graph is one bulk load that
reads its N-Triples from a pipe as they are mapped (:class:`PipedBulkLoader`).
"""

from __future__ import annotations

import contextlib
import fcntl
import gc
import os
import queue
import threading
from collections.abc import Iterator
from types import TracebackType
from typing import Self

import pyoxigraph as ox

__all__ = ["BackgroundLoader", "PipedBulkLoader", "paused_gc"]

_DONE = None


class _Loader:
    """What both loaders share: a load error is kept and re-raised in the producer."""

    _error: BaseException | None = None

    def _raise(self) -> None:
        if self._error is not None:
            raise self._error

    def _stop(self) -> None:
        """Let the loading thread finish what it has and end."""
        raise NotImplementedError

    def close(self) -> None:
        """Wait until everything put is loaded; raise the first load error."""
        self._stop()
        self._raise()

    def __enter__(self) -> Self:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, tb: TracebackType | None
    ) -> None:
        if kind is None:
            self.close()
        else:
            self._stop()  # the store being built is discarded by the caller


class BackgroundLoader(_Loader):
    """``put(graph, chunk)`` queues N-Triples for ``graph``; ``close()`` waits and re-raises.

    The queue is short so mapped text does not pile up in memory when loading is the
    slower side.
    """

    def __init__(self, store: ox.Store, depth: int = 2) -> None:
        self._store = store
        self._queue: queue.Queue[tuple[str, bytes] | None] = queue.Queue(maxsize=depth)
        self._thread = threading.Thread(target=self._run, name="cadkg-load", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while (item := self._queue.get()) is not _DONE:
            if self._error is not None:
                continue  # drain, so a producer blocked on put() can go on and see the error
            graph, chunk = item
            try:
                # The mapping percent-encodes IRI parts and escapes literals: no re-validation.
                self._store.load(chunk, ox.RdfFormat.N_TRIPLES, to_graph=ox.NamedNode(graph), lenient=True)
            except BaseException as err:  # re-raised in the producer by close()
                self._error = err

    def put(self, graph: str, chunk: bytes) -> None:
        self._raise()
        if chunk:
            self._queue.put((graph, chunk))

    def _stop(self) -> None:
        if self._thread.is_alive():
            self._queue.put(_DONE)
            self._thread.join()


class PipedBulkLoader(_Loader):
    """``put(graph, chunk)`` writes N-Triples into the bulk load of ``graph``; ``close()`` waits.

    A bulk load of many small chunks writes many small tables that cost more to merge
    than one of the whole file, and waiting for the whole file before loading leaves the
    loader idle while it is mapped. So each graph gets one ``Store.bulk_load`` on a thread,
    reading a pipe the mapping writes into; chunks of one graph must come together.
    """

    # The largest pipe buffer an unprivileged process may ask for by default (Linux).
    _PIPE_BYTES = 1 << 20

    def __init__(self, store: ox.Store) -> None:
        self._store = store
        self._graph: str | None = None
        self._write_fd: int | None = None
        self._thread: threading.Thread | None = None

    def _load(self, graph: str, read_fd: int) -> None:
        try:
            # pyoxigraph opens the path itself and reads it without the GIL.
            self._store.bulk_load(
                path=f"/dev/fd/{read_fd}",
                format=ox.RdfFormat.N_TRIPLES,
                to_graph=ox.NamedNode(graph),
                lenient=True,
            )
        except BaseException as err:  # re-raised in the producer by put() or close()
            self._error = err
        finally:
            os.close(read_fd)  # a writer still writing now gets a broken pipe, not a hang

    def _start(self, graph: str) -> None:
        read_fd, write_fd = os.pipe()
        with contextlib.suppress(OSError, AttributeError):  # a smaller buffer only costs calls
            fcntl.fcntl(write_fd, fcntl.F_SETPIPE_SZ, self._PIPE_BYTES)
        self._graph, self._write_fd = graph, write_fd
        self._thread = threading.Thread(target=self._load, args=(graph, read_fd), name="cadkg-bulk-load")
        self._thread.start()

    def _stop(self) -> None:
        if self._write_fd is not None:
            os.close(self._write_fd)  # end of input: the bulk load writes what it has read
            self._write_fd = None
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        self._graph = None

    def put(self, graph: str, chunk: bytes) -> None:
        self._raise()
        if not chunk:
            return
        if graph != self._graph:
            self.close()
            self._start(graph)
        assert self._write_fd is not None
        view = memoryview(chunk)
        try:
            while view:
                view = view[os.write(self._write_fd, view) :]
        except BrokenPipeError:
            self.close()
            raise


@contextlib.contextmanager
def paused_gc() -> Iterator[None]:
    """Run a build without the cyclic garbage collector.

    A build creates millions of records, strings and poses, none of them in reference
    cycles; the collector's full passes over all of them found nothing to free and cost a
    third of a 100k-wire build. Reference counting frees everything as usual.
    """
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            gc.enable()
