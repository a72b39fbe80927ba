"""The knowledge graph of a cell: the store, built from a manifest, with what is derived from it.

:class:`KnowledgeGraph` adds to :class:`cadkg.store.GraphStore` the build (files → records →
triples → store, :mod:`cadkg.building`), the cell model that the registered derivation
computes from the graph (kept beside an on-disk store, recomputed after every change), the
robot/human assignments, and the named queries and networkx views.
"""

from __future__ import annotations

import contextlib
import gc
import shutil
import traceback
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pyoxigraph as ox

import cadkg.registry as registry
from cadkg.building import StageClock, write_graphs
from cadkg.errors import NotFound, StoreError
from cadkg.generations import (
    checkpoint,
    claim,
    crash_point,
    current_generation,
    new_generation,
    open_writable,
    publish_generation,
    read_pointer,
    writing,
)
from cadkg.ingest.manifest import Manifest, SourceSpec, load_manifest
from cadkg.loading import BackgroundLoader, paused_gc
from cadkg.mapping.pipeline import GraphData, SourceReport, read_source
from cadkg.mapping.writer import node_iri
from cadkg.model_file import MODEL_FILE, read_model, write_model
from cadkg.ontology.terms import CK_NS
from cadkg.plan.decision import Performer
from cadkg.query.named import run_named
from cadkg.store import FILES, GraphStore, QueryResult, cell_profile
from cadkg.usecase import Derivation

if TYPE_CHECKING:
    import networkx as nx

__all__ = ["ASSIGNABLE", "KnowledgeGraph", "build", "open_store"]

ASSIGNABLE = ("wire", "component", "operation")


def _derivation(graph: GraphStore) -> Derivation:
    found = registry.derivation(cell_profile(graph))
    if found is None:
        raise StoreError("no registered use case derives a cell model")
    return found


class KnowledgeGraph(GraphStore):
    """The cell's RDF graph, built from a manifest, with its derived cell model.

    Queries see the union of all named graphs as their default graph.
    """

    def __init__(self, store: ox.Store, directory: Path | None = None, read_only: bool = False) -> None:
        super().__init__(store, directory, read_only)
        self._model: Any = None
        # Whether the store is a generation being made, which no other reader sees yet.
        self._unpublished = False
        self._changing = False  # inside _change: a change within it is part of it
        self._holding = False  # inside _writing: the writer lock is this object's already
        # The stages of the build that made this graph and their seconds (see build).
        self.stages: list[tuple[str, float]] = []

    def __repr__(self) -> str:
        where = f"store {str(self.directory)!r}" if self.directory is not None else "in memory"
        rows = self.query(
            "SELECT ?name ?profile WHERE { ?c a ck:Cell ; ck:label ?name ; ck:profile ?profile } LIMIT 1"
        ).rows
        cell = f"cell {rows[0]['name']!r} ({rows[0]['profile']}), " if rows else ""
        return (
            f"<KnowledgeGraph {where}: {cell}{len(self)} triples in {len(self.named_graphs())} named graphs>"
        )

    @property
    def _model_file(self) -> Path | None:
        return self._generation / MODEL_FILE if self._generation is not None else None

    # -- building -----------------------------------------------------------------
    @classmethod
    def build(
        cls,
        manifest: str | Path | Manifest,
        directory: str | Path | None = None,
        *,
        on_source: Callable[[SourceSpec], None] | None = None,
        on_stage: Callable[[str], None] | None = None,
    ) -> KnowledgeGraph:
        """Build the graph of a manifest, in memory or atomically into ``directory``.

        ``on_source`` hears of each input file as its reading starts; ``on_stage`` of every
        stage by name (``opening the store``, ``reading FILE``, ``deriving the cell model``,
        ``writing the derived graph``, ``loading into the store``, on disk ``indexing the
        store``), whose times :attr:`stages` keeps afterwards.

        Raises
        ------
        IngestError, ManifestError
            When any input is malformed; an existing store directory is left unchanged.
        """
        if not isinstance(manifest, Manifest):
            manifest = load_manifest(manifest)
        clock = StageClock(on_stage)

        def reading(source: SourceSpec) -> None:
            clock.start(f"reading {source.rel}")
            if on_source is not None:
                on_source(source)

        clock.start("opening the store")
        with paused_gc():
            if directory is None:
                kg = cls.memory()
                kg._load_sources(manifest, reading, clock, bulk=False)
            else:
                root = Path(directory)
                generation = new_generation(root)
                # No change is made to the live generation while this one is built from it: a
                # change waits, then goes into what this build publishes (see _change).
                with writing(root):
                    kg = cls._build_locked(manifest, root, generation, reading, clock)
        clock.stop()
        kg.stages = clock.stages
        return kg

    @classmethod
    def _build_locked(
        cls,
        manifest: Manifest,
        directory: Path,
        generation: Path,
        on_source: Callable[[SourceSpec], None],
        clock: StageClock,
    ) -> KnowledgeGraph:
        # Held until the generation is live or removed: a later build removes it only when the
        # kernel has dropped this lock, i.e. when this process is gone (killed mid-build).
        held = claim(generation)
        assert held is not None  # claim() waits for the lock
        reports: list[SourceReport] = []
        store: ox.Store | None = None
        kg: KnowledgeGraph | None = None
        try:
            store = ox.Store(str(generation))
            kg = cls(store, directory)
            kg._unpublished = True
            kg._files_dir = generation / FILES
            kg._generation = generation
            kg._load_ontology()
            edits = kg._keep_edits(directory, manifest.cell.base_iri)
            reports = kg._load_sources(manifest, on_source, clock, bulk=True, edits=edits)
            clock.start("indexing the store")
            model = kg.cell_model()
            if not (generation / MODEL_FILE).exists():
                kg._keep_model(model)
            store.flush()
            store.optimize()
        except BaseException as err:
            # RocksDB goes on writing (flushes, compactions) until the store is dropped; removed
            # while open, the generation would come back as debris that blocks the next build.
            # The failed frames below this one still hold the store: clear them, then drop it.
            traceback.clear_frames(err.__traceback__)
            store = kg = None
            gc.collect()
            shutil.rmtree(generation, ignore_errors=True)
            held.release()
            raise
        store = kg = None
        try:
            publish_generation(directory, generation)
        finally:
            held.release()
        opened = cls.open(directory, read_only=False)
        opened.reports = reports
        opened._model = model
        return opened

    def _load_sources(
        self,
        manifest: Manifest,
        on_source: Callable[[SourceSpec], None] | None,
        clock: StageClock,
        *,
        bulk: bool,
        edits: Iterable[tuple[str, str]] = (),
    ) -> list[SourceReport]:
        """Load every source, derive the cell model and load its graph; the store ends complete."""
        # A failure anywhere discards the whole store being built, so chunks of a file, and of
        # the derived graph, are loaded while the rest of it is still being written; on disk
        # the loader gathers them into large bulk loads (see BackgroundLoader).
        with BackgroundLoader(self._store, bulk=bulk) as loader:
            model = write_graphs(
                manifest,
                loader.put,
                stream=True,
                on_source=on_source,
                on_graph=self._took,
                edits=edits,
                on_stage=clock.start,
            )
            clock.start("loading into the store")  # what the loader has still to take in
        if model is None:
            clock.start("deriving the cell model")
            self.derive()
        else:
            self._model = model
        return list(self.reports)

    def _took(self, data: GraphData) -> None:
        """Keep what a build read from one source besides its triples: files and report."""
        self._write_files(data.files)
        self.reports.append(data.report)

    def _keep_edits(self, directory: Path, base_iri: str) -> list[tuple[str, str]]:
        """Carry the live generation's hand-edited assignments and progress over; give the
        assignments as (target, performer) pairs."""
        # Assignments edited by hand live in their own graph; a rebuild from the
        # source files carries them over from the live generation.
        previous = read_pointer(directory)
        if previous is None or not (directory / previous).is_dir():
            return []
        graph = ox.NamedNode(base_iri + "assignments")
        try:
            old = ox.Store.read_only(str(directory / previous))
        except OSError:
            return []
        # The cell's progress reports too, matched to the new revision's work when read.
        for kept in (graph, ox.NamedNode(base_iri + "progress")):
            self._store.extend(list(old.quads_for_pattern(None, None, None, kept)))
        del old
        rows = self.query(
            "SELECT ?g ?target ?who WHERE { GRAPH ?g { ?a ck:assignmentOf ?target ; ck:assignedTo ?who } }",
            g=graph,
        )
        return [(row["target"], row["who"].rsplit("#", 1)[-1]) for row in rows]

    # -- derived model and assignments ----------------------------------------------
    def cell_model(self) -> Any:
        """The cell model the derivation of the cell's profile computes from the graph
        (:func:`cadkg.registry.derivation`), once per change.

        An on-disk store keeps a copy of it written with the store and after each change, so
        opening the store again reads it instead of deriving.
        """
        if self._model is None:
            with paused_gc():
                if self.derived_model() is None:
                    derivation = _derivation(self)
                    self._model = derivation.derive(derivation.extract(self))
                    if not self.read_only:
                        self._keep_model(self._model)
        return self._model

    def derived_model(self) -> Any:
        """The cell model if it is derived already or kept beside the store, else None; never
        derives (a served store's readers must not pause the collector for it)."""
        if self._model is None and not self._changing:
            self._model = self._kept_model()
        return self._model

    def _kept_model(self) -> Any:
        return None if self._model_file is None else read_model(self._model_file, _derivation(self))

    def _keep_model(self, model: Any) -> None:
        if self._model_file is not None:
            write_model(self._model_file, _derivation(self), model)

    def _forget_model(self) -> None:
        """Drop the model and its kept copy; called before the graph changes, so no copy outlives it."""
        self._model = None
        if self._model_file is not None:
            self._model_file.unlink(missing_ok=True)

    def derive(self) -> Any:
        """Recompute the cell model and replace its named graph (``{base}derived``) with it, in
        one transaction: a reader sees the old graph or the new one, never none."""
        self._forget_model()
        model = self.cell_model()
        derivation = _derivation(self)
        base = derivation.base(model)
        if base and not self.read_only:
            graph = ox.NamedNode(derivation.graph(model))
            with paused_gc():
                data = derivation.ntriples(model, base, None)
            if self._unpublished:
                # Nobody sees this generation before it is complete: two steps are as good as one.
                self._store.remove_graph(graph)
                self._store.load(data, ox.RdfFormat.N_TRIPLES, to_graph=graph, lenient=True)
            else:
                # Loaded beside it, then moved over it by one update (one transaction): twice as
                # fast as the same triples parsed as SPARQL in an INSERT DATA.
                staged = ox.NamedNode(graph.value + "-next")
                self._store.update(f"DROP SILENT GRAPH {staged}")
                self._store.load(data, ox.RdfFormat.N_TRIPLES, to_graph=staged, lenient=True)
                self._store.update(f"MOVE SILENT GRAPH {staged} TO GRAPH {graph}")
        return model

    def change(self) -> contextlib.AbstractContextManager[None]:
        """The changes of the block as one: whole or not at all, derived once (:meth:`_change`)."""
        return self._change()

    @contextlib.contextmanager
    def _change(self) -> Iterator[None]:
        """One change of the graph, then the derived graph made anew; whole or not at all.

        In memory, the change and the derivation are each one transaction. A store directory
        is changed in a new generation (a checkpoint of the live one: hard links), made live
        by one rename of ``CURRENT`` when complete, so a process killed at any moment leaves
        the store as it was or as changed. It is made under the directory's writer lock, so a
        change during a build waits for it and goes into the generation the build made. A
        change inside another is part of it.
        """
        if self._changing:
            yield
            return
        self._changing = True
        try:
            if self.directory is None or self._generation is None:
                self._forget_model()
                yield
                self.derive()
            else:
                with self._writing(), self._next_generation():
                    yield
                    crash_point("change:applied")
                    self.derive()
                    self._store.flush()
                    crash_point("change:derived")
        finally:
            self._changing = False

    @contextlib.contextmanager
    def _writing(self) -> Iterator[None]:
        """Hold the store directory's writer lock, on its live generation (a build's); inside a
        change, which holds it already, on the change's generation."""
        if self.directory is None or self._generation is None or self._holding:
            yield
            return  # in memory: nothing to wait for; in a change: part of it
        with writing(self.directory):
            live = current_generation(self.directory)
            if live != self._generation:
                self._swap_store(open_writable(live), live)
            self._holding = True
            try:
                yield
            finally:
                self._holding = False

    def _swap_store(self, store: ox.Store, generation: Path) -> None:
        self._store, self._generation, self._files_dir = store, generation, generation / FILES
        self._model = None

    @contextlib.contextmanager
    def _next_generation(self) -> Iterator[None]:
        """Work on a copy of the live generation; publish it when the block ends, drop it when
        it raises (:func:`cadkg.generations.checkpoint`)."""
        assert self.directory is not None and self._generation is not None
        live = self._generation
        with checkpoint(self._store, live, self.directory, FILES) as fresh:
            old = self._store
            self._swap_store(ox.Store(str(fresh)), fresh)
            self._unpublished = True
            try:
                yield
            except BaseException as err:
                traceback.clear_frames(err.__traceback__)
                self._swap_store(old, live)
                raise
            finally:
                self._unpublished = False
            del old  # closed before checkpoint() removes its files
            self._keep_model(self.cell_model())

    def assign(
        self, kind: str, ident: str, performer: str, also: Callable[[], Iterable[str]] | None = None
    ) -> str:
        """Decide who makes a wire, handles a component or performs an operation; kept across rebuilds.
        ``also`` gives the ids of ``kind`` the cell model does not list but its plan's tasks
        are assigned by (an ELVEZ operation by its order in the sequence), asked only then.

        Raises
        ------
        StoreError
            On an unknown kind or performer, or a read-only store.
        NotFound
            When no such wire, component or operation is in the graph.
        """
        if self.read_only:
            raise StoreError("the store is open read-only")
        if kind not in ASSIGNABLE or performer not in tuple(Performer):
            raise StoreError(
                f"cannot assign {kind!r} to {performer!r}: kind is one of {', '.join(ASSIGNABLE)}, "
                f"performer one of {', '.join(Performer)}"
            )
        with self._writing():  # after a build in progress, on what it made
            model = self.cell_model()
            if not model.base:
                raise StoreError("the store has no cell; build it from a manifest first")
            known = {
                "wire": {s.wire for s in model.steps},
                "component": set(model.components),
                "operation": {str(s.position) for s in model.steps},
            }[kind]
            if ident not in known and also is not None:
                known = known | set(also())
            if ident not in known:
                raise NotFound(f"no {kind} {ident!r} in the graph")
            target = node_iri(model.base, kind, ident)
            node = node_iri(model.base, "assignment", kind, ident)
            graph = f"{model.base}assignments"
            with self._change():
                # One update request: the old decision goes only if the new one lands.
                self._store.update(
                    f"""DELETE WHERE {{ GRAPH <{graph}> {{ <{node}> ?p ?o }} }} ;
                        INSERT DATA {{ GRAPH <{graph}> {{
                          <{node}> a <{CK_NS}Assignment> ; <{CK_NS}assignmentOf> <{target}> ;
                            <{CK_NS}assignedTo> <{CK_NS}{performer}> }} }}"""
                )
                # The model read above holds the old performers: what else the change does (a plan
                # made in it) must see the new one.
                self._forget_model()
            return target

    def replace_source(
        self,
        path: str | Path,
        rel_path: str,
        base_iri: str,
        kind: str | None = None,
        frame: str | None = None,
    ) -> SourceReport:
        """Re-read one input file and replace its named graph, leaving every other graph as is.

        The file is read and mapped before the store is touched, and the swap is one
        transaction: on a read error the old graph stays.

        Raises
        ------
        IngestError
            When the file is malformed.
        """
        if self.read_only:
            raise StoreError("the store is open read-only")
        with paused_gc():
            data = read_source(Path(path), rel_path, kind, base_iri, frame, profile=cell_profile(self))
        # One update request is one transaction: the old graph goes only if the new one lands.
        # The graph IRI is minted by us and every term of the data is escaped by the mapping.
        inserts = data.ntriples.decode("utf-8")
        with self._change():
            self._write_files(data.files)
            self._store.update(
                f"DROP SILENT GRAPH <{data.graph}> ; INSERT DATA {{ GRAPH <{data.graph}> {{ {inserts} }} }}"
            )
        self.reports.append(data.report)
        return data.report

    # -- views and exports ----------------------------------------------------------
    def export(self, path: str | Path, fmt: str | None = None) -> Path:
        """Write the graph to ``path``; the format comes from ``fmt`` or the suffix
        (``.ttl .nt .nq .trig .jsonld .graphml``)."""
        path = Path(path)
        fmt = fmt or path.suffix.lstrip(".").lower()
        if fmt == "graphml":
            from cadkg.query.views import write_graphml

            write_graphml(self, path)
            return path
        path.write_bytes(self.serialize(fmt))
        return path

    def graph_view(self, relations: Iterable[str] | None = None) -> nx.MultiDiGraph:
        """A networkx view of the selected relations (see :func:`cadkg.query.views.graph_view`)."""
        from cadkg.query.views import graph_view

        return graph_view(self, relations)

    def named_query(self, name: str, **params: Any) -> QueryResult:
        """Run a named query (see :func:`cadkg.query.named.run_named`)."""
        return run_named(self, name, **params)


def build(manifest: str | Path, store: str | Path | None = None) -> KnowledgeGraph:
    """Build the graph of a manifest: in memory, or into a store directory (atomically)."""
    return KnowledgeGraph.build(manifest, store)


def open_store(directory: str | Path, *, read_only: bool = True) -> KnowledgeGraph:
    """Open a store directory written by :func:`build`."""
    return KnowledgeGraph.open(directory, read_only=read_only)
