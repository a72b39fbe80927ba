"""The knowledge graph: a pyoxigraph store with one named graph per input file.

On disk a store is a directory holding generations (``gen-*/``, each a complete
oxigraph database) and a ``CURRENT`` file naming the live one. A build writes a
new generation and then replaces ``CURRENT`` with one atomic rename, so a failed
build leaves the previous store exactly as it was and readers never see half a build.
Each generation also keeps its derived cell model (``cell-model.json``), dropped before
any change to the graph and written again after it.
"""

from __future__ import annotations

import contextlib
import gc
import shutil
import tempfile
import time
import traceback
import uuid
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import pyoxigraph as ox

from cadkg.errors import QueryError, StoreError
from cadkg.ingest.manifest import Manifest, SourceSpec, load_manifest
from cadkg.ingest.pipeline import GraphData, SourceReport, read_source
from cadkg.loading import BackgroundLoader, paused_gc
from cadkg.ontology.terms import CK_NS, ONTOLOGY_IRI, ontology_path
from cadkg.sparql_text import bind_values, syntax_error_message, term_value

if TYPE_CHECKING:
    import networkx as nx
    import pandas as pd

    from cadkg.usecases.iema.cabinet import CellModel

__all__ = ["EXPORT_FORMATS", "PREFIXES", "KnowledgeGraph", "QueryResult", "build", "open_store"]

PREFIXES = {
    "ck": CK_NS,
    "rdf": "http://www.w3.org/1999/02/22-rdf-syntax-ns#",
    "rdfs": "http://www.w3.org/2000/01/rdf-schema#",
    "owl": "http://www.w3.org/2002/07/owl#",
    "xsd": "http://www.w3.org/2001/XMLSchema#",
}
EXPORT_FORMATS = {
    "ttl": ox.RdfFormat.TURTLE,
    "nt": ox.RdfFormat.N_TRIPLES,
    "nq": ox.RdfFormat.N_QUADS,
    "trig": ox.RdfFormat.TRIG,
    "jsonld": ox.RdfFormat.JSON_LD,
}
_CURRENT = "CURRENT"
_GENERATION = "gen-"  # the name of each generation directory starts so
_FILES = "files"
_MODEL_FILE = "cell-model.json"  # cadkg.usecases.iema.persist
PERFORMERS = ("robot", "human")
ASSIGNABLE = ("wire", "component", "operation")


@dataclass(frozen=True)
class QueryResult:
    """Rows of a SELECT query as plain Python values (IRIs as strings)."""

    variables: tuple[str, ...]
    rows: tuple[dict[str, Any], ...]

    def __iter__(self) -> Iterator[dict[str, Any]]:
        return iter(self.rows)

    def __len__(self) -> int:
        return len(self.rows)

    def to_dataframe(self) -> pd.DataFrame:
        import pandas as pd

        return pd.DataFrame(list(self.rows), columns=list(self.variables))


class KnowledgeGraph:
    """The cell's RDF graph over pyoxigraph, in memory or in a store directory.

    Queries see the union of all named graphs as their default graph.
    """

    def __init__(self, store: ox.Store, directory: Path | None = None, read_only: bool = False) -> None:
        self._store = store
        self.directory = directory
        self.read_only = read_only
        self.reports: list[SourceReport] = []
        self._model: CellModel | None = None
        self._scratch: tempfile.TemporaryDirectory[str] | None = None
        self._files_dir: Path | None = None
        # An in-memory graph's files, held until files_dir is first asked for.
        self._unwritten: dict[str, bytes] = {}
        self._model_file: Path | None = None

    # -- opening and building -------------------------------------------------
    @classmethod
    def memory(cls) -> KnowledgeGraph:
        kg = cls(ox.Store())
        kg._load_ontology()
        return kg

    @classmethod
    def open(cls, directory: str | Path, *, read_only: bool = True) -> KnowledgeGraph:
        """Open a store directory written by :meth:`build_into`.

        Raises
        ------
        StoreError
            When the directory is not a cadkg store or cannot be opened.
        """
        directory = Path(directory)
        generation = _current_generation(directory)
        try:
            store = ox.Store.read_only(str(generation)) if read_only else ox.Store(str(generation))
        except OSError as err:
            raise StoreError(f"{directory}: cannot open the store: {err}") from err
        kg = cls(store, directory, read_only)
        kg._files_dir = generation / _FILES
        kg._model_file = generation / _MODEL_FILE
        return kg

    @classmethod
    def build(
        cls,
        manifest: str | Path | Manifest,
        directory: str | Path | None = None,
        *,
        on_source: Callable[[SourceSpec], None] | None = None,
    ) -> KnowledgeGraph:
        """Build the graph of a manifest, in memory or atomically into ``directory``.

        Raises
        ------
        IngestError, ManifestError
            When any input is malformed; an existing store directory is left unchanged.
        """
        if not isinstance(manifest, Manifest):
            manifest = load_manifest(manifest)
        with paused_gc():
            if directory is None:
                kg = cls.memory()
                kg._load_sources(manifest, on_source, bulk=False)
                return kg
            return cls._build_into(manifest, Path(directory), on_source)

    @classmethod
    def _build_into(
        cls, manifest: Manifest, directory: Path, on_source: Callable[[SourceSpec], None] | None
    ) -> KnowledgeGraph:
        if (
            directory.exists()
            and not (directory / _CURRENT).exists()
            and not all(_left_by_a_build(entry) for entry in directory.iterdir())
        ):
            raise StoreError(f"{directory}: exists and is not a cadkg store; refusing to write into it")
        directory.mkdir(parents=True, exist_ok=True)
        name = f"{_GENERATION}{time.strftime('%Y%m%dT%H%M%S')}-{uuid.uuid4().hex[:8]}"
        generation = directory / name
        reports: list[SourceReport] = []
        store: ox.Store | None = None
        kg: KnowledgeGraph | None = None
        try:
            store = ox.Store(str(generation))
            kg = cls(store, directory)
            kg._files_dir = generation / _FILES
            kg._model_file = generation / _MODEL_FILE
            kg._load_ontology()
            edits = kg._keep_edits(directory, manifest.cell.base_iri)
            reports = kg._load_sources(manifest, on_source, bulk=True, edits=edits)
            model = kg.cell_model()
            if not (generation / _MODEL_FILE).exists():
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
            raise
        store = kg = None
        pointer = directory / f".{_CURRENT}.{name}"
        pointer.write_text(name + "\n", encoding="utf-8")
        previous = _read_pointer(directory)
        pointer.replace(directory / _CURRENT)
        if previous is not None and previous != name:
            shutil.rmtree(directory / previous, ignore_errors=True)
        opened = cls.open(directory, read_only=False)
        opened.reports = reports
        opened._model = model
        return opened

    def _load_sources(
        self,
        manifest: Manifest,
        on_source: Callable[[SourceSpec], None] | None,
        *,
        bulk: bool,
        edits: Iterable[tuple[str, str]] = (),
    ) -> list[SourceReport]:
        """Load every source, derive the geometry and load it; the store ends complete."""
        from cadkg.building import write_graphs

        # A failure anywhere discards the whole store being built, so chunks of a file may be
        # loaded while the rest of it is still being mapped. On disk, one bulk load per file:
        # bulk-loading many chunks writes many small tables that cost more to merge.
        with BackgroundLoader(self._store, bulk=bulk) as loader:
            model = write_graphs(
                manifest, loader.put, stream=not bulk, on_source=on_source, on_graph=self._took, edits=edits
            )
        if model is None:
            self.derive()
        else:
            self._model = model
        return list(self.reports)

    def _took(self, data: GraphData) -> None:
        """Keep what a build read from one source besides its triples: files and report."""
        self._write_files(data.files)
        self.reports.append(data.report)

    def _load_ontology(self) -> None:
        self._store.load(
            path=ontology_path(), format=ox.RdfFormat.TURTLE, to_graph=ox.NamedNode(ONTOLOGY_IRI)
        )

    def _keep_edits(self, directory: Path, base_iri: str) -> list[tuple[str, str]]:
        """Carry the live generation's hand-edited assignments over; give (target, performer) pairs."""
        # Assignments edited by hand live in their own graph; a rebuild from the
        # source files carries them over from the live generation.
        previous = _read_pointer(directory)
        if previous is None or not (directory / previous).is_dir():
            return []
        graph = ox.NamedNode(base_iri + "assignments")
        try:
            old = ox.Store.read_only(str(directory / previous))
        except OSError:
            return []
        self._store.extend(list(old.quads_for_pattern(None, None, None, graph)))
        del old
        rows = self.query(
            "SELECT ?g ?target ?who WHERE { GRAPH ?g { ?a ck:assignmentOf ?target ; ck:assignedTo ?who } }",
            g=graph,
        )
        return [(row["target"], row["who"].rsplit("#", 1)[-1]) for row in rows]

    @property
    def generation(self) -> str | None:
        """The name of the live generation of a store directory (None in memory)."""
        return _read_pointer(self.directory) if self.directory is not None else None

    @property
    def files_dir(self) -> Path:
        """Where files that come with the graph (STL meshes) are kept; ``ck:meshUri`` is relative to it."""
        if self._files_dir is None:
            self._scratch = tempfile.TemporaryDirectory(prefix="cadkg-files-")
            self._files_dir = Path(self._scratch.name)
        if self._unwritten:
            files, self._unwritten = self._unwritten, {}
            self._write_files(files)
        return self._files_dir

    def _write_files(self, files: Mapping[str, bytes]) -> None:
        if self._files_dir is None:
            # In memory, a scene's meshes (one file each: 78,786 at 100k wires, 0.2 ms a file
            # here) are written when something asks where they are, not during the build.
            self._unwritten.update(files)
            return
        made: set[Path] = set()  # a scene's tens of thousands of meshes share one folder
        for rel, content in files.items():
            target = self._files_dir / rel
            if target.parent not in made:
                target.parent.mkdir(parents=True, exist_ok=True)
                made.add(target.parent)
            target.write_bytes(content)

    # -- derived geometry and assignments -----------------------------------------
    def cell_model(self) -> CellModel:
        """The cabinet's derived geometry, computed from the graph once per change.

        An on-disk store keeps a copy of it (:mod:`cadkg.usecases.iema.persist`) written with the
        store and after each change, so opening the store again reads it instead of deriving.
        """
        if self._model is None:
            from cadkg.usecases.iema.cabinet import derive_cell
            from cadkg.usecases.iema.extract import extract

            with paused_gc():
                self._model = self._kept_model()
                if self._model is None:
                    self._model = derive_cell(extract(self))
                    if not self.read_only:
                        self._keep_model(self._model)
        return self._model

    def _kept_model(self) -> CellModel | None:
        if self._model_file is None:
            return None
        from cadkg.usecases.iema.persist import load_model

        try:
            data = self._model_file.read_bytes()
        except OSError:
            return None
        return load_model(data)

    def _keep_model(self, model: CellModel) -> None:
        if self._model_file is None:
            return
        from cadkg.usecases.iema.persist import dump_model

        # Written whole and renamed into place, so a reader finds the old copy, none, or this one.
        partial = self._model_file.with_name(self._model_file.name + ".partial")
        with contextlib.suppress(OSError):
            partial.write_bytes(dump_model(model))
            partial.replace(self._model_file)

    def _forget_model(self) -> None:
        """Drop the model and its kept copy; called before the graph changes, so no copy outlives it."""
        self._model = None
        if self._model_file is not None:
            self._model_file.unlink(missing_ok=True)

    def derive(self) -> CellModel:
        """Recompute the derived geometry and replace the ``{base}derived`` graph with it."""
        from cadkg.usecases.iema.emit import derived_graph, derived_ntriples

        self._forget_model()
        model = self.cell_model()
        if model.base and not self.read_only:
            graph = ox.NamedNode(derived_graph(model))
            if graph in set(self._store.named_graphs()):
                self._store.remove_graph(graph)
            with paused_gc():
                data = derived_ntriples(model, model.base)
            self._store.load(data, ox.RdfFormat.N_TRIPLES, to_graph=graph, lenient=True)
        return model

    def assign(self, kind: str, ident: str, performer: str) -> str:
        """Decide who makes a wire, handles a component or performs an operation; kept across rebuilds.

        Raises
        ------
        StoreError
            On an unknown kind or performer, or a read-only store.
        NotFound
            When no such wire, component or operation is in the graph.
        """
        from cadkg.errors import NotFound
        from cadkg.mapping.core import node_iri

        if self.read_only:
            raise StoreError("the store is open read-only")
        if kind not in ASSIGNABLE or performer not in PERFORMERS:
            raise StoreError(
                f"cannot assign {kind!r} to {performer!r}: kind is one of {', '.join(ASSIGNABLE)}, "
                f"performer one of {', '.join(PERFORMERS)}"
            )
        model = self.cell_model()
        if not model.base:
            raise StoreError("the store has no cell; build it from a manifest first")
        known = {
            "wire": {s.wire for s in model.steps},
            "component": set(model.components),
            "operation": {str(s.position) for s in model.steps},
        }[kind]
        if ident not in known:
            raise NotFound(f"no {kind} {ident!r} in the graph")
        target = node_iri(model.base, kind, ident)
        node = node_iri(model.base, "assignment", kind, ident)
        graph = f"{model.base}assignments"
        self._forget_model()
        # One update request: the old decision goes only if the new one lands.
        self._store.update(
            f"""DELETE WHERE {{ GRAPH <{graph}> {{ <{node}> ?p ?o }} }} ;
                INSERT DATA {{ GRAPH <{graph}> {{
                  <{node}> a <{CK_NS}Assignment> ; <{CK_NS}assignmentOf> <{target}> ;
                    <{CK_NS}assignedTo> <{CK_NS}{performer}> }} }}"""
        )
        self.derive()
        return target

    def _write_graph(self, data: GraphData, *, bulk: bool) -> None:
        self._write_files(data.files)
        graph = ox.NamedNode(data.graph)
        # The N-Triples are written by the mapping, which percent-encodes every IRI part and
        # escapes every literal; re-validating them costs a third of the load.
        if bulk:
            self._store.bulk_load(data.ntriples, ox.RdfFormat.N_TRIPLES, to_graph=graph, lenient=True)
        else:
            self._store.load(data.ntriples, ox.RdfFormat.N_TRIPLES, to_graph=graph, lenient=True)
        self.reports.append(data.report)

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
            data = read_source(Path(path), rel_path, kind, base_iri, frame)
        self._write_files(data.files)
        # One update request is one transaction: the old graph goes only if the new one lands.
        # The graph IRI is minted by us and every term of the data is escaped by the mapping.
        inserts = data.ntriples.decode("utf-8")
        self._forget_model()
        self._store.update(
            f"DROP SILENT GRAPH <{data.graph}> ; INSERT DATA {{ GRAPH <{data.graph}> {{ {inserts} }} }}"
        )
        self.derive()
        self.reports.append(data.report)
        return data.report

    def close(self) -> None:
        if not self.read_only:
            with contextlib.suppress(OSError):
                self._store.flush()
        del self._store
        if self._scratch is not None:
            self._scratch.cleanup()

    def __enter__(self) -> KnowledgeGraph:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    # -- reading ---------------------------------------------------------------
    def __len__(self) -> int:
        return len(self._store)

    def named_graphs(self) -> list[str]:
        return sorted(g.value for g in self._store.named_graphs() if isinstance(g, ox.NamedNode))

    def sources(self) -> list[dict[str, Any]]:
        """Provenance of every ingested file: graph, path, sha256, kind, time."""
        return list(
            self.query(
                """SELECT ?graph ?path ?sha256 ?kind ?time WHERE {
                     GRAPH ?graph { ?graph a ck:SourceFile ; ck:sourcePath ?path ;
                       ck:sha256 ?sha256 ; ck:readerKind ?kind ; ck:ingestedAt ?time } }
                   ORDER BY ?path"""
            )
        )

    def raw_query(self, sparql: str, bindings: Mapping[str, Any] | None = None) -> Any:
        """Run SPARQL on the union graph with bound parameters; returns pyoxigraph results.

        Parameters are bound by a ``VALUES`` block opening the query's WHERE group
        (:func:`cadkg.sparql_text.bind_values`), never pasted into the text; pyoxigraph
        then starts its joins from them.

        Raises
        ------
        QueryError
            On a syntax error, a parameter name that is not a SPARQL variable name or a
            value that cannot be bound.
        """
        text = bind_values(sparql, bindings or {})
        try:
            return self._store.query(text, prefixes=PREFIXES, use_default_graph_as_union=True)
        except SyntaxError as err:
            raise QueryError(syntax_error_message(err, text, PREFIXES)) from None
        except (RuntimeError, OSError) as err:
            raise QueryError(str(err)) from None

    def query(self, sparql: str, **bindings: Any) -> QueryResult:
        """Run a SELECT and return its rows as dictionaries of Python values.

        >>> kg = KnowledgeGraph.memory()
        >>> kg.query("SELECT ?c WHERE { ?c a owl:Class ; rdfs:label ?l } LIMIT 1").variables
        ('c',)
        """
        result = self.raw_query(sparql, bindings)
        if not isinstance(result, ox.QuerySolutions):
            raise QueryError("query() runs SELECT queries; use ask() or construct()")
        variables = tuple(v.value for v in result.variables)
        convert, width = term_value, range(len(variables))
        rows = tuple(
            dict(zip(variables, [convert(solution[i]) for i in width], strict=True)) for solution in result
        )
        return QueryResult(variables, rows)

    def ask(self, sparql: str, **bindings: Any) -> bool:
        result = self.raw_query(sparql, bindings)
        if not isinstance(result, ox.QueryBoolean):
            raise QueryError("ask() runs ASK queries")
        return bool(result)

    def construct(self, sparql: str, **bindings: Any) -> list[ox.Triple]:
        result = self.raw_query(sparql, bindings)
        if not isinstance(result, ox.QueryTriples):
            raise QueryError("construct() runs CONSTRUCT or DESCRIBE queries")
        return list(result)

    def quads(self) -> Iterator[ox.Quad]:
        return iter(self._store)

    def graph_quads(self, graph: str) -> Iterator[ox.Quad]:
        """The quads of one named graph (``cadkg push`` sends a store graph by graph)."""
        return iter(self._store.quads_for_pattern(None, None, None, ox.NamedNode(graph)))

    # -- export -----------------------------------------------------------------
    def serialize(
        self, fmt: str = "ttl", *, include_ontology: bool = False, graphs: Iterable[str] | None = None
    ) -> bytes:
        """The graph as Turtle, N-Triples (merged), N-Quads, TriG or JSON-LD (named graphs kept);
        with ``graphs``, only those named graphs."""
        if fmt not in EXPORT_FORMATS:
            raise QueryError(f"unknown export format {fmt!r}; one of {', '.join(EXPORT_FORMATS)}")
        rdf_format = EXPORT_FORMATS[fmt]
        keep = ox.Store()
        ontology = ox.NamedNode(ONTOLOGY_IRI)
        merge = not rdf_format.supports_datasets
        if graphs is None:
            quads: Iterable[ox.Quad] = self._store
        else:
            quads = (q for g in graphs for q in self.graph_quads(g))
        keep.extend(
            ox.Quad(q.subject, q.predicate, q.object, ox.DefaultGraph() if merge else q.graph_name)
            for q in quads
            if include_ontology or q.graph_name != ontology
        )
        if merge:
            data = keep.dump(format=rdf_format, from_graph=ox.DefaultGraph(), prefixes=PREFIXES)
        else:
            data = keep.dump(format=rdf_format, prefixes=PREFIXES)
        assert data is not None  # dump() returns bytes when given no output
        return data

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
        """Run a named query of ``query/sparql`` (see :func:`cadkg.query.named.run_named`)."""
        from cadkg.query.named import run_named

        return run_named(self, name, **params)

    def execute(
        self,
        sparql: str,
        *,
        update: bool = False,
        default_graphs: Iterable[str] | None = None,
        named_graphs: Iterable[str] | None = None,
    ) -> Any:
        """Run a SPARQL 1.1 Protocol operation: a query over an explicit dataset, or an update.

        With ``default_graphs`` the default graph is the merge of those graphs (not the union of
        all), and the named graphs are ``named_graphs`` (none when not given); with neither the
        dataset is as in :meth:`raw_query`. An update is followed by the derivation, so the
        ``derived`` graph and the cell model reflect it.

        Raises
        ------
        QueryError
            On a syntax error (with its line and column) or an evaluation error.
        StoreError
            On an update of a read-only store.
        """
        try:
            if update:
                if self.read_only:
                    raise StoreError("the store is open read-only")
                self._forget_model()
                self._store.update(sparql, prefixes=PREFIXES)
                # The derived graph follows what it is derived from, as after a rebuild.
                self.derive()
                return None
            if default_graphs is None and named_graphs is None:
                return self._store.query(sparql, prefixes=PREFIXES, use_default_graph_as_union=True)
            return self._store.query(
                sparql,
                prefixes=PREFIXES,
                default_graph=[ox.NamedNode(g) for g in default_graphs or ()],
                named_graphs=[ox.NamedNode(g) for g in named_graphs or ()],
            )
        except SyntaxError as err:
            raise QueryError(syntax_error_message(err, sparql, PREFIXES)) from None
        except ValueError as err:
            raise QueryError(f"not an IRI: {err}") from None
        except (RuntimeError, OSError) as err:
            raise QueryError(str(err)) from None


def _left_by_a_build(entry: Path) -> bool:
    """Whether ``entry`` is what a build killed before its end leaves: a generation or a pointer."""
    if entry.is_dir():
        return entry.name.startswith(_GENERATION)
    return entry.name.startswith(f".{_CURRENT}.{_GENERATION}")


def _read_pointer(directory: Path) -> str | None:
    try:
        return (directory / _CURRENT).read_text(encoding="utf-8").strip() or None
    except FileNotFoundError:
        return None


def _current_generation(directory: Path) -> Path:
    name = _read_pointer(directory)
    if name is None:
        raise StoreError(f"{directory}: not a cadkg store (no {_CURRENT} file); build one with 'cadkg build'")
    generation = directory / name
    if not generation.is_dir():
        raise StoreError(f"{directory}: {_CURRENT} names {name!r}, which is missing")
    return generation


def build(manifest: str | Path, store: str | Path | None = None) -> KnowledgeGraph:
    """Build the graph of a manifest: in memory, or into a store directory (atomically)."""
    return KnowledgeGraph.build(manifest, store)


def open_store(directory: str | Path, *, read_only: bool = True) -> KnowledgeGraph:
    """Open a store directory written by :func:`build`."""
    return KnowledgeGraph.open(directory, read_only=read_only)
