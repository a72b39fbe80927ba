from __future__ import annotations

import threading
from pathlib import Path

import pyoxigraph as ox
import pytest

from cadkg.loading import BackgroundLoader, PipedBulkLoader

G1 = "https://example.org/g/one"
G2 = "https://example.org/g/two"


def lines(graph: str, first: int, count: int) -> bytes:
    return "".join(
        f'<https://example.org/s/{i}> <https://example.org/p> "{graph[-3:]} {i}" .\n'
        for i in range(first, first + count)
    ).encode()


def triples_of(store: ox.Store, graph: str) -> set[tuple[str, str]]:
    return {
        (q.subject.value, q.object.value)
        for q in store.quads_for_pattern(None, None, None, ox.NamedNode(graph))
    }


def test_piped_bulk_load_streams_each_graph_in_chunks(tmp_path: Path) -> None:
    store = ox.Store(str(tmp_path / "store"))
    # Chunks bigger than the pipe's buffer, so writing them waits on the loading thread.
    with PipedBulkLoader(store) as loader:
        for first in range(0, 60_000, 20_000):
            loader.put(G1, lines(G1, first, 20_000))
        loader.put(G1, b"")
        loader.put(G2, lines(G2, 0, 3))
    assert len(triples_of(store, G1)) == 60_000
    assert ("https://example.org/s/59999", "one 59999") in triples_of(store, G1)
    assert triples_of(store, G2) == {(f"https://example.org/s/{i}", f"two {i}") for i in range(3)}
    assert not [t for t in threading.enumerate() if t.name == "cadkg-bulk-load"]


def test_a_failed_bulk_load_stops_the_writer_instead_of_blocking_it(tmp_path: Path) -> None:
    store = ox.Store(str(tmp_path / "store"))
    loader = PipedBulkLoader(store)
    # The parser fails on the first line and the loader closes its end of the pipe: writing
    # the rest (far more than a pipe holds) must raise the parser's error, not hang.
    with pytest.raises(SyntaxError):
        loader.put(G1, b"this is not N-Triples\n" + lines(G1, 0, 100_000))
    with pytest.raises(SyntaxError):
        loader.close()


def test_a_producer_failure_ends_the_bulk_load(tmp_path: Path) -> None:
    store = ox.Store(str(tmp_path / "store"))
    with pytest.raises(RuntimeError, match="row 7"), PipedBulkLoader(store) as loader:
        loader.put(G1, lines(G1, 0, 10))
        raise RuntimeError("row 7 is bad")
    assert not [t for t in threading.enumerate() if t.name == "cadkg-bulk-load"]


def test_background_loader_loads_chunks_and_reraises_a_load_error() -> None:
    store = ox.Store()
    with BackgroundLoader(store) as loader:
        loader.put(G1, lines(G1, 0, 5))
        loader.put(G2, lines(G2, 5, 5))
    assert len(triples_of(store, G1)) == 5
    assert ("https://example.org/s/9", "two 9") in triples_of(store, G2)
    loader = BackgroundLoader(store)
    loader.put(G1, b"<broken\n")
    with pytest.raises(SyntaxError):
        loader.close()
