"""A build's Python side: every graph of a cell as N-Triples, handed to a sink as written.

The store's build gives its loader thread as the sink; the build benchmark gives a list,
to time this side alone. Both therefore run the same steps in the same order.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable

from cadkg.usecases.iema.cabinet import CellModel, derive_cell
from cadkg.usecases.iema.collect import InputCollector
from cadkg.usecases.iema.emit import derived_graph, derived_ntriples
from cadkg.ingest.manifest import Manifest, SourceSpec
from cadkg.ingest.pipeline import GraphData, read_manifest_graphs

__all__ = ["write_graphs"]


def write_graphs(
    manifest: Manifest,
    sink: Callable[[str, bytes], None],
    *,
    stream: bool,
    on_source: Callable[[SourceSpec], None] | None = None,
    on_graph: Callable[[GraphData], None] | None = None,
    edits: Iterable[tuple[str, str]] = (),
) -> CellModel | None:
    """Hand ``sink(graph, chunk)`` the manifest's graph, each source's and the derived one.

    With ``stream``, a file's N-Triples go to ``sink`` in chunks while its later rows are
    still being mapped; without, one call per graph. ``on_graph`` sees the
    :class:`GraphData` (report and files) of the manifest and of each source once mapped;
    ``edits`` are the assignments kept from an earlier build. The derived model is
    returned, or ``None`` when the records did not hold all the derivation needs and it
    must be read from the store.
    """
    collector = InputCollector(manifest)
    collector.add_edits(edits)
    graphs = read_manifest_graphs(
        manifest,
        on_source,
        sink=sink if stream else None,
        on_record=lambda source: collector.source(source.rel),
    )
    for data in graphs:
        sink(data.graph, data.ntriples)  # what was not streamed
        if on_graph is not None:
            on_graph(data)
    if not collector.complete:
        return None
    # Derived while a loader may still be indexing the sources.
    model = derive_cell(collector.inputs())
    graph = derived_graph(model)
    sink(graph, derived_ntriples(model, model.base, (lambda chunk: sink(graph, chunk)) if stream else None))
    return model
