from __future__ import annotations

import gc
from pathlib import Path

import pyoxigraph as ox
import pytest

from cadkg.loading import BackgroundLoader, paused_gc

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


@pytest.mark.parametrize("bulk", [False, True])
def test_background_loader_loads_each_chunk_into_its_graph(tmp_path: Path, bulk: bool) -> None:
    store = ox.Store(str(tmp_path / "store")) if bulk else ox.Store()
    with BackgroundLoader(store, bulk=bulk) as loader:
        loader.put(G1, lines(G1, 0, 5))
        loader.put(G1, b"")
        loader.put(G2, lines(G2, 5, 5))
        loader.put(G1, lines(G1, 5, 2))
    assert triples_of(store, G1) == {(f"https://example.org/s/{i}", f"one {i}") for i in range(7)}
    assert triples_of(store, G2) == {(f"https://example.org/s/{i}", f"two {i}") for i in range(5, 10)}


def test_bulk_chunks_are_gathered_per_graph_and_loaded_by_two_threads(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    store = ox.Store(str(tmp_path / "store"))
    loads: list[tuple[str, int]] = []

    class Counted:  # pyoxigraph's Store cannot be patched: its bulk loads, counted
        def bulk_load(self, data: bytes, *args: object, to_graph: ox.NamedNode, **kwargs: object) -> None:
            loads.append((to_graph.value, data.count(b"\n")))
            store.bulk_load(data, *args, to_graph=to_graph, **kwargs)

    # A gathered chunk is sent once it holds three of these 40-line chunks.
    monkeypatch.setattr("cadkg.loading.BULK_CHUNK_BYTES", 3 * len(lines(G1, 0, 40)) - 1)
    with BackgroundLoader(Counted(), bulk=True) as loader:  # type: ignore[arg-type]
        for first in range(0, 400, 40):
            loader.put(G1, lines(G1, first, 40))
        loader.put(G2, lines(G2, 0, 40))
        loader.put(G1, lines(G1, 400, 40))
    assert len(loader._threads) == 2
    assert sorted(loads) == sorted([(G1, 120)] * 3 + [(G1, 40), (G2, 40), (G1, 40)])
    assert triples_of(store, G1) == {(f"https://example.org/s/{i}", f"one {i}") for i in range(440)}
    assert len(triples_of(store, G2)) == 40


def test_a_bulk_load_error_is_raised_in_the_producer(tmp_path: Path) -> None:
    loader = BackgroundLoader(ox.Store(str(tmp_path / "store")), bulk=True)
    loader.put(G1, lines(G1, 0, 3))
    loader.put(G2, b"<broken\n")
    with pytest.raises(SyntaxError):
        loader.close()
    assert not any(thread.is_alive() for thread in loader._threads)


def test_a_load_error_is_raised_in_the_producer() -> None:
    loader = BackgroundLoader(ox.Store(), bulk=False)
    loader.put(G1, b"<broken\n")
    with pytest.raises(SyntaxError):
        loader.close()


def test_a_producer_failure_stops_the_loading_thread() -> None:
    with pytest.raises(RuntimeError, match="row 7"), BackgroundLoader(ox.Store(), bulk=False) as loader:
        loader.put(G1, lines(G1, 0, 10))
        raise RuntimeError("row 7 is bad")
    assert not any(thread.is_alive() for thread in loader._threads)


def test_paused_gc_restores_the_collector_and_leaves_the_build_in_the_oldest_generation() -> None:
    class Record:  # instances are tracked by the collector, as the build's records are
        pass

    gc.collect()
    with paused_gc():
        assert not gc.isenabled()
        kept = [Record() for _ in range(5_000)]
        assert gc.get_count()[0] >= 5_000  # nothing collected while paused
    assert gc.isenabled()
    assert gc.get_count() == (0, 0, 0)
    young = {id(o) for o in gc.get_objects(generation=0)} | {id(o) for o in gc.get_objects(generation=1)}
    assert not any(id(o) in young for o in kept)
    assert all(gc.is_tracked(o) for o in kept[:10])  # still collectable, in the oldest generation
    assert any(o is kept[0] for o in gc.get_objects(generation=2))


def test_paused_gc_leaves_a_disabled_collector_disabled() -> None:
    gc.disable()
    try:
        with paused_gc():
            pass
        assert not gc.isenabled()
    finally:
        gc.enable()


def test_paused_gc_leaves_what_the_program_froze_frozen() -> None:
    # Containers the collector tracks. Not gc.get_freeze_count() before and after: it counts
    # the frozen objects alive, and in a test run another thread may free some of them.
    frozen = [[index] for index in range(10)]
    assert all(gc.is_tracked(item) for item in frozen)
    gc.freeze()
    try:
        with paused_gc():
            [[] for _ in range(100)]
        # Frozen objects are in none of the collector's generations; thawed, they would be.
        collected = {id(item) for item in gc.get_objects()}
        assert not any(id(item) in collected for item in frozen)
    finally:
        gc.unfreeze()
    assert frozen
