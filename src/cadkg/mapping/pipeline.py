"""From a manifest to N-Triples per named graph: read, map, report.

Reading and mapping finish for a file before anything of it reaches a store, so
a bad file never leaves half of itself behind.
"""

from __future__ import annotations

import time
import warnings
from collections.abc import Callable, Iterable, Iterator
from contextlib import closing
from dataclasses import dataclass, field
from itertools import chain, islice
from pathlib import Path

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.manifest import Manifest, SourceSpec
from cadkg.limited import read_limited
from cadkg.mapping.dispatch import mapper
from cadkg.mapping.writer import TripleWriter, graph_iri, map_provenance, sha256_of
from cadkg.registry import load_mappings, reader_for, sniff_kind

__all__ = ["GraphData", "SourceReport", "read_manifest_graphs", "read_source"]


@dataclass(frozen=True)
class SourceReport:
    """What one input file gave: for the build summary."""

    rel_path: str
    kind: str
    records: int
    triples: int
    seconds: float
    warnings: tuple[str, ...] = field(default=())


@dataclass(frozen=True)
class GraphData:
    """The N-Triples of one named graph and the report of the file it came from."""

    graph: str
    ntriples: bytes
    report: SourceReport
    files: dict[str, bytes] = field(default_factory=dict)


def read_source(
    path: Path,
    rel_path: str,
    kind: str | None,
    base_iri: str,
    frame: str | None = None,
    sink: Callable[[str, bytes], None] | None = None,
    on_record: Callable[[object], None] | None = None,
    profile: str = "",
    keep: Callable[[object], bool] | None = None,
) -> GraphData:
    """Read one file with the reader of its kind and map it into its named graph.

    ``frame`` names the frame a scene file's root is placed in (default ``cabinet``).
    With ``sink``, the N-Triples go to ``sink(graph, chunk)`` as they are mapped and the
    returned ``ntriples`` is empty; a reader that streams its records is then mapped row by
    row, so ``sink`` may have had part of a file when a later row raises (builds use it for a
    store that a failure discards). ``on_record`` sees every record for which ``keep`` (called
    where the file is read: see below) is true, all of them without ``keep``, in file order.
    ``profile`` is the cell's use case, which picks the reader of a shared suffix that no
    content tells apart (see :func:`cadkg.registry.sniff_kind`).

    The file is read and mapped in a limited child (:func:`cadkg.limited.read_limited`), which
    sends back the N-Triples in chunks, the records ``on_record`` is to see and the files beside
    the graph: all of it counts against what a file may give per byte (``CADKG_READ_RATIO``),
    so what this process does with it is bounded by the file.

    Raises
    ------
    IngestError
        Located errors of the reader; an unknown kind; ``needs more than N MiB to read`` and the
        other read limits (see :mod:`cadkg.limited`).
    """
    started = time.perf_counter()
    _register_core_mappings()
    kind = kind or sniff_kind(path, profile=profile)
    try:
        reader = reader_for(kind)
    except KeyError as err:
        raise IngestError(path, str(err.args[0])) from None
    graph = graph_iri(base_iri, rel_path)
    if on_record is not None and keep is None:
        keep = _everything
    source = _Source(path, rel_path, kind, base_iri, frame or "cabinet", graph, keep)
    held: list[bytes] = []
    put = held.append if sink is None else (lambda chunk: sink(graph, chunk))
    mapped: _Mapped | None = None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", IngestWarning)
        # Without a sink nothing leaves this function before the last record is mapped, so a
        # later row's error still leaves nothing behind. Closed on an error here too, which
        # stops the child at once.
        with closing(read_limited(path, _mapped, reader.stream or reader.read, source)) as incoming:
            for item in incoming:
                if type(item) is bytes:
                    put(item)
                elif type(item) is _Mapped:
                    mapped = item
                elif on_record is not None:
                    on_record(item)
    assert mapped is not None  # the child's last item, unless it raised
    report = SourceReport(
        rel_path=rel_path,
        kind=kind,
        records=mapped.records,
        triples=mapped.triples,
        seconds=time.perf_counter() - started,
        warnings=tuple(str(w.message) for w in caught if issubclass(w.category, IngestWarning)),
    )
    ntriples = b"".join(held)
    return GraphData(graph=graph, ntriples=ntriples, report=report, files=mapped.files)


def _everything(record: object) -> bool:
    return True


@dataclass(frozen=True)
class _Source:
    """What the child that reads one file needs to map it."""

    path: Path
    rel_path: str
    kind: str
    base_iri: str
    frame: str
    graph: str
    keep: Callable[[object], bool] | None


@dataclass(frozen=True)
class _Mapped:
    """The last item of a file's read: how many records and triples, the files beside the graph."""

    records: int
    triples: int
    files: dict[str, bytes]


_CHILD_CHUNK_LINES = 16_000


def _mapped(read: Callable[[Path], Iterable[object]], source: _Source) -> Iterator[object]:
    """In the child: the N-Triples of ``source`` in chunks (``bytes``), the records its ``keep``
    takes, then a :class:`_Mapped`."""
    writer = TripleWriter(source.base_iri)
    writer.root_frame = source.frame
    chunks: list[bytes] = []
    # Small chunks: what the child holds stays near the file's own size (the loader in the
    # calling process gathers them into large bulk loads).
    writer.stream_to(chunks.append, most=_CHILD_CHUNK_LINES)
    slug = Path(source.rel_path).stem
    keep = source.keep
    records = iter(read(source.path))
    # The first records (or the file's refusal) before the checksum, which reads every byte.
    first = list(islice(records, 1))
    map_provenance(writer, source.graph, source.rel_path, sha256_of(source.path), source.kind)
    count = 0
    for record in chain(first, records):
        count += 1
        mapper(type(record))(record, writer, slug)
        writer.maybe_flush()
        if chunks:
            yield from chunks
            chunks.clear()
        if keep is not None and keep(record):
            yield record
    yield writer.data()
    yield _Mapped(count, writer.triples, writer.all_files())


def _register_core_mappings() -> None:
    # Each mapping module imports the record classes it registers for, and so their readers:
    # imported when a file is first mapped rather than with cadkg. A use case's mappings are
    # registered from the module each names (cadkg.usecase.UseCase.mapping).
    from cadkg.mapping import cell, eplan, harness  # noqa: F401

    load_mappings()


def manifest_graph(manifest: Manifest) -> GraphData:
    """The graph the manifest itself states: the cell and its static frames."""
    from cadkg.mapping.cell import map_manifest

    started = time.perf_counter()
    rel = manifest.path.name
    graph = graph_iri(manifest.cell.base_iri, rel)
    writer = TripleWriter(manifest.cell.base_iri)
    map_provenance(writer, graph, rel, sha256_of(manifest.path), "manifest")
    map_manifest(writer, manifest)
    report = SourceReport(
        rel, "manifest", 1 + len(manifest.frames), writer.triples, time.perf_counter() - started
    )
    return GraphData(graph=graph, ntriples=writer.data(), report=report)


def read_manifest_graphs(
    manifest: Manifest,
    on_source: Callable[[SourceSpec], None] | None = None,
    sink: Callable[[str, bytes], None] | None = None,
    on_record: Callable[[SourceSpec], Callable[[object], None]] | None = None,
    keep: Callable[[object], bool] | None = None,
) -> Iterator[GraphData]:
    """The manifest's own graph, then one graph per source, in manifest order.

    ``sink`` receives the sources' N-Triples in chunks (see :func:`read_source`);
    ``on_record(source)`` gives the function that sees each record of ``source`` that ``keep``
    takes (every record without ``keep``).
    """
    yield manifest_graph(manifest)
    for source in manifest.sources:
        if on_source is not None:
            on_source(source)
        yield read_source(
            source.path,
            source.rel,
            source.kind,
            manifest.cell.base_iri,
            source.frame,
            sink=sink,
            on_record=on_record(source) if on_record is not None else None,
            profile=manifest.cell.profile,
            keep=keep,
        )
