"""Loading N-Triples into a pyoxigraph store on threads of their own.

pyoxigraph parses and indexes without holding the GIL, so while one chunk of a
source is loaded the mapping (pure Python) goes on with the next: a build costs
about the longer of the two instead of their sum.
"""

from __future__ import annotations

import contextlib
import gc
import queue
import threading
from collections.abc import Iterator
from types import TracebackType

import pyoxigraph as ox

__all__ = ["BULK_CHUNK_BYTES", "BackgroundLoader", "paused_gc"]

_DONE = None

# A bulk load sorts what it is given into tables of its own, which the store merges
# afterwards: many small bulk loads cost more to merge than they save (16k-line chunks of
# the 10k-wire cabinet loaded two to three times slower). Chunks of a graph are gathered
# to about this size first; the derived graph of that cabinet (229 MB) then goes in three
# bulk loads, two at once.
BULK_CHUNK_BYTES = 96 << 20


class BackgroundLoader:
    """``put(graph, chunk)`` queues N-Triples for ``graph``; ``close()`` waits and re-raises.

    The queue is short so mapped text does not pile up in memory when loading is the
    slower side. With ``bulk`` (an on-disk store that a failed build discards), a graph's
    chunks are gathered to :data:`BULK_CHUNK_BYTES` (or until another graph's chunk comes)
    and two threads bulk-load them: pyoxigraph's bulk loader indexes one batch at a time,
    on one core, and a build on two cores would leave the other to the mapping alone.
    In memory one thread loads: the store takes its writers one at a time.
    """

    def __init__(self, store: ox.Store, *, bulk: bool, depth: int = 2) -> None:
        self._store = store
        self._bulk = bulk
        self._queue: queue.Queue[tuple[str, bytes] | None] = queue.Queue(maxsize=depth)
        self._error: BaseException | None = None
        self._gathered: tuple[str, list[bytes], int] | None = None
        self._threads = [
            threading.Thread(target=self._run, name=f"cadkg-load-{number}", daemon=True)
            for number in range(2 if bulk else 1)
        ]
        for thread in self._threads:
            thread.start()

    def _run(self) -> None:
        while (item := self._queue.get()) is not _DONE:
            if self._error is not None:
                continue  # drain, so a producer blocked on put() can go on and see the error
            graph, chunk = item
            try:
                load = self._store.bulk_load if self._bulk else self._store.load
                # The mapping percent-encodes IRI parts and escapes literals: no re-validation.
                load(chunk, ox.RdfFormat.N_TRIPLES, to_graph=ox.NamedNode(graph), lenient=True)
            except BaseException as err:  # re-raised in the producer by close()
                self._error = err

    def put(self, graph: str, chunk: bytes) -> None:
        if self._error is not None:
            raise self._error
        if not chunk:
            return
        if not self._bulk:
            self._queue.put((graph, chunk))
            return
        if self._gathered is not None and self._gathered[0] != graph:
            self._send_gathered()
        if self._gathered is None:
            self._gathered = (graph, [], 0)
        _, parts, size = self._gathered
        parts.append(chunk)
        self._gathered = (graph, parts, size + len(chunk))
        if size + len(chunk) >= BULK_CHUNK_BYTES:
            self._send_gathered()

    def _send_gathered(self) -> None:
        if self._gathered is not None:
            graph, parts, _ = self._gathered
            self._gathered = None
            self._queue.put((graph, parts[0] if len(parts) == 1 else b"".join(parts)))

    def close(self) -> None:
        """Wait until every queued chunk is loaded; raise the first load error."""
        if self._error is None:
            self._send_gathered()
        self._stop()
        if self._error is not None:
            raise self._error

    def _stop(self) -> None:
        self._gathered = None
        for thread in self._threads:
            if thread.is_alive():
                self._queue.put(_DONE)
        for thread in self._threads:
            thread.join()

    def __enter__(self) -> BackgroundLoader:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, tb: TracebackType | None
    ) -> None:
        if kind is None:
            self.close()
        else:
            self._stop()


@contextlib.contextmanager
def paused_gc() -> Iterator[None]:
    """Run a build without the cyclic garbage collector.

    A build creates millions of records, strings and poses, none of them in reference
    cycles; the collector's full passes over all of them found nothing to free and cost a
    third of a 100k-wire build. Reference counting frees everything as usual.

    What the build keeps (the derived model: a million objects at 100k wires) is moved to
    the oldest generation on the way out. Left in the youngest, the first allocation after
    the build would walk all of it, and the next collections again, to find nothing.
    """
    was_enabled = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was_enabled:
            # freeze() moves every tracked object to the permanent generation, unfreeze() puts
            # them into the oldest: two list splices, no traversal. Not when the program froze
            # objects of its own (before forking workers, say): they would be thawed too.
            if not gc.get_freeze_count():
                gc.freeze()
                gc.unfreeze()
            gc.enable()
