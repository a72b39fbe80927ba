"""A build's Python side: every graph of a cell as N-Triples, handed to a sink as written.

The store's build gives its loader thread as the sink; the build benchmark gives a list,
to time this side alone. Both therefore run the same steps in the same order.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterable
from typing import Any

import cadkg.registry as registry
from cadkg.ingest.manifest import Manifest, SourceSpec
from cadkg.mapping.pipeline import GraphData, read_manifest_graphs

__all__ = ["StageClock", "write_graphs"]


class StageClock:
    """Times a build's stages back to back, so that together they are the whole build.

    ``start(name)`` ends the stage under way and starts ``name``, telling ``report`` (a
    progress display); :attr:`stages` holds ``(name, seconds)`` of every ended stage.
    """

    def __init__(self, report: Callable[[str], None] | None = None) -> None:
        self.report = report
        self.stages: list[tuple[str, float]] = []
        self._current: tuple[str, float] | None = None

    def start(self, name: str) -> None:
        self.stop()
        self._current = (name, time.perf_counter())
        if self.report is not None:
            self.report(name)

    def stop(self) -> None:
        if self._current is not None:
            name, began = self._current
            self.stages.append((name, time.perf_counter() - began))
            self._current = None


def write_graphs(
    manifest: Manifest,
    sink: Callable[[str, bytes], None],
    *,
    stream: bool,
    on_source: Callable[[SourceSpec], None] | None = None,
    on_graph: Callable[[GraphData], None] | None = None,
    edits: Iterable[tuple[str, str]] = (),
    on_stage: Callable[[str], None] | None = None,
) -> Any:
    """Hand ``sink(graph, chunk)`` the manifest's graph, each source's and the derived one.

    With ``stream``, a file's N-Triples go to ``sink`` in chunks while its later rows are
    still being mapped; without, one call per graph. ``on_graph`` sees the
    :class:`GraphData` (report and files) of the manifest and of each source once mapped;
    ``edits`` are the assignments kept from an earlier build; ``on_stage`` hears when the
    derivation starts and when its graph is written. The derived model is
    returned, or ``None`` when the records did not hold all the derivation needs and it
    must be read from the store.
    """
    derivation = registry.derivation(manifest.cell.profile)
    collector = derivation.collector(manifest) if derivation is not None else None
    if collector is not None:
        collector.add_edits(edits)
    graphs = read_manifest_graphs(
        manifest,
        on_source,
        sink=sink if stream else None,
        on_record=(lambda source: collector.source(source.rel)) if collector is not None else None,
        keep=collector.wants if collector is not None else None,
    )
    for data in graphs:
        sink(data.graph, data.ntriples)  # what was not streamed
        if on_graph is not None:
            on_graph(data)
    if derivation is None or collector is None or not collector.complete:
        return None
    # Derived while a loader may still be indexing the sources.
    if on_stage is not None:
        on_stage("deriving the cell model")
    model = derivation.derive(collector.inputs())
    if on_stage is not None:
        on_stage("writing the derived graph")
    graph = derivation.graph(model)
    rest = derivation.ntriples(
        model, derivation.base(model), (lambda chunk: sink(graph, chunk)) if stream else None
    )
    sink(graph, rest)
    return model
