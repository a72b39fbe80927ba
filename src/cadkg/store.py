"""The store: a pyoxigraph database with one named graph per input file.

On disk a store is a directory holding generations and a ``CURRENT`` file naming the live
one (:mod:`cadkg.generations`). Each generation also keeps the files that come with the graph
(``files/``: STL meshes) and what :mod:`cadkg.graph` derives from it (``cell-model.json``).
"""

from __future__ import annotations

import contextlib
import html
import tempfile
from collections.abc import Iterable, Iterator, Mapping
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path
from typing import TYPE_CHECKING, Any, Self

import pyoxigraph as ox

from cadkg.confined import write_files
from cadkg.errors import QueryError, StoreError
from cadkg.generations import (
    GENERATION,
    Snapshot,
    current_generation,
    new_generation,
    open_writable,
    publish_generation,
    read_pointer,
    take_snapshot,
)
from cadkg.mapping.pipeline import SourceReport
from cadkg.ontology.terms import CK_NS, ONTOLOGY_IRI, ontology_path
from cadkg.outbound import check_outbound
from cadkg.sparql_text import bind_values, syntax_error_message, term_value

if TYPE_CHECKING:
    import pandas as pd
    import rdflib

__all__ = [
    "EXPORT_FORMATS",
    "FILES",
    "PREFIXES",
    "GraphStore",
    "QueryResult",
    "cell_profile",
    "evaluation_errors",
    "new_generation",
    "publish_generation",
    "read_pointer",
]

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
# Rows a notebook shows of a result; the rest are counted.
_HTML_ROWS = 50
FILES = "files"


@dataclass(frozen=True)
class QueryResult:
    """Rows of a SELECT query as plain Python values (IRIs as strings)."""

    variables: tuple[str, ...]
    rows: tuple[dict[str, Any], ...]

    def __iter__(self) -> Iterator[dict[str, Any]]:
        return iter(self.rows)

    def __len__(self) -> int:
        return len(self.rows)

    def to_dataframe(self, *, keep_decimals: bool = False) -> pd.DataFrame:
        """The rows as a pandas DataFrame, one column per variable.

        ``xsd:decimal`` values (Python ``Decimal``) become floats, so numeric columns are
        numeric (``describe()``, plots); ``keep_decimals=True`` keeps them exact.
        """
        import pandas as pd

        rows = self.rows
        if not keep_decimals:
            rows = tuple(
                {k: float(v) if isinstance(v, Decimal) else v for k, v in row.items()} for row in rows
            )
        return pd.DataFrame(list(rows), columns=list(self.variables))

    def _repr_html_(self) -> str:
        """A table of the first rows, for notebooks."""
        head = "".join(f"<th>{html.escape(v)}</th>" for v in self.variables)
        body = "".join(
            "<tr>"
            + "".join(
                f"<td>{'' if row[v] is None else html.escape(str(row[v]))}</td>" for v in self.variables
            )
            + "</tr>"
            for row in self.rows[:_HTML_ROWS]
        )
        more = f" (the first {_HTML_ROWS} shown)" if len(self.rows) > _HTML_ROWS else ""
        table = f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"
        return f"{table}<p>{len(self)} row(s){more}</p>"

    def __repr__(self) -> str:
        return f"QueryResult(variables={list(self.variables)!r}, rows={len(self.rows)})"


def cell_profile(graph: Any) -> str:
    """The profile of the cell a graph (anything with ``query``) holds; ``""`` when it holds none."""
    rows = graph.query("SELECT ?p WHERE { ?c a ck:Cell ; ck:profile ?p } LIMIT 1").rows
    return str(rows[0]["p"]) if rows else ""


class GraphStore:
    """The cell's RDF graph over pyoxigraph, in memory or in a store directory.

    Queries see the union of all named graphs as their default graph. What is derived from
    the graph (the cell model, its derived graph) is :class:`cadkg.graph.KnowledgeGraph`'s.

    ``allowed_services`` are the only endpoints a query's ``SERVICE`` (or an update's ``LOAD``)
    may reach; none by default, so a query makes no outbound request (:mod:`cadkg.outbound`).
    """

    allowed_services: frozenset[str] = frozenset()

    def __init__(self, store: ox.Store, directory: Path | None = None, read_only: bool = False) -> None:
        self._store = store
        self.directory = directory
        self.read_only = read_only
        self.reports: list[SourceReport] = []
        self._scratch: tempfile.TemporaryDirectory[str] | None = None
        self._files_dir: Path | None = None
        # An in-memory graph's files, held until files_dir is first asked for.
        self._unwritten: dict[str, bytes] = {}
        # The live generation's directory, for what a store keeps beside its database.
        self._generation: Path | None = None

    # Whether the graph lives in an external store (cadkg.remote.RemoteGraph) rather than here.
    remote = False

    @classmethod
    def of_quads(cls, quads: Iterable[ox.Quad]) -> GraphStore:
        """An in-memory store holding ``quads`` (and no ontology)."""
        store = GraphStore(ox.Store())
        store._store.extend(quads)
        return store

    @classmethod
    def memory(cls) -> Self:
        kg = cls(ox.Store())
        kg._load_ontology()
        return kg

    @classmethod
    def open(cls, directory: str | Path, *, read_only: bool = True, generation: str | None = None) -> Self:
        """Open a store directory written by a build: its live generation, or the generation
        named ``generation`` (a kept earlier one, read-only), with what it keeps beside it.

        Raises
        ------
        StoreError
            When the directory is not a cadkg store or cannot be opened, or the generation is
            gone or asked for writing.
        """
        directory = Path(directory)
        if generation is None:
            at = current_generation(directory)
        elif (
            read_only
            and Path(generation).name == generation
            and generation.startswith(GENERATION)
            and (directory / generation).is_dir()
        ):
            at = directory / generation
        else:
            raise StoreError(f"{directory}: no generation {generation!r} to open read-only")
        if read_only:
            try:
                store = ox.Store.read_only(str(at))
            except OSError as err:
                what = "the store" if generation is None else f"the generation {generation}"
                raise StoreError(f"{directory}: cannot open {what}: {err}") from err
        else:
            # The build that published it may still hold it until its command ends.
            store = open_writable(at)
        kg = cls(store, directory, read_only)
        kg._files_dir = at / FILES
        kg._generation = at
        return kg

    def _load_ontology(self) -> None:
        self._store.load(
            path=ontology_path(), format=ox.RdfFormat.TURTLE, to_graph=ox.NamedNode(ONTOLOGY_IRI)
        )

    @property
    def generation(self) -> str | None:
        """The name of the live generation of a store directory (None in memory)."""
        return read_pointer(self.directory) if self.directory is not None else None

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
        # Names come from the files read (an X3D DEF): each is opened inside the files folder,
        # never followed out of it (cadkg.confined).
        write_files(self._files_dir, dict(files))

    def snapshot(self) -> Snapshot:
        """The graph as it is now in a store directory other processes open read-only (the query
        workers of :mod:`cadkg.query.workers`); :meth:`Snapshot.remove` when done."""
        return take_snapshot(self._store, self.directory, self._generation)

    def close(self) -> None:
        if not self.read_only:
            with contextlib.suppress(OSError):
                self._store.flush()
        del self._store
        if self._scratch is not None:
            self._scratch.cleanup()

    def __enter__(self) -> Self:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @contextlib.contextmanager
    def _change(self) -> Iterator[None]:
        """Around every change of the graph (an update, see :meth:`execute`): where a subclass
        makes the change whole or not at all, and keeps what it derives in step."""
        yield

    @property
    def open_generation(self) -> str | None:
        """The generation this graph has open (None in memory); :attr:`generation` is the live one."""
        return self._generation.name if self._generation is not None else None

    # -- reading ---------------------------------------------------------------
    def __len__(self) -> int:
        return len(self._store)

    def rdflib_dataset(self) -> rdflib.Dataset:
        """The same store as an rdflib ``Dataset`` (through oxrdflib): rdflib's API over this
        graph's quads, not a copy, so what one changes the other sees. The default graph is the
        union of the named graphs, as in :meth:`query`.

        Raises
        ------
        StoreError
            When rdflib or oxrdflib is not installed (the ``rdflib`` extra).
        """
        try:
            import rdflib
            from oxrdflib import OxigraphStore
        except ImportError as err:
            raise StoreError(
                f"rdflib_dataset() needs rdflib and oxrdflib ({err.name} is missing): "
                "pip install 'cadkg[rdflib]'"
            ) from None
        return rdflib.Dataset(store=OxigraphStore(store=self._store), default_union=True)

    def named_graphs(self) -> list[str]:
        return sorted(g.value for g in self._store.named_graphs() if isinstance(g, ox.NamedNode))

    def source_graphs(self, base: str | None = None) -> list[str]:
        """The named graphs but the derived one: what the files, the manifest and the
        assignments say (``base`` is the cell's base IRI, read from the graph when not given)."""
        if base is None:
            rows = self.query("SELECT ?cell WHERE { ?cell a ck:Cell } LIMIT 1").rows
            base = str(rows[0]["cell"]).removesuffix("cell/this") if rows else ""
        return [g for g in self.named_graphs() if g != base + "derived"]

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
            On a syntax error, a parameter name that is not a SPARQL variable name, a
            value that cannot be bound, or a ``SERVICE`` to an endpoint not allowed.
        StoreError
            When an allowed ``SERVICE`` or the store's files cannot be read.
        """
        text = bind_values(sparql, bindings or {})
        check_outbound(text, self.allowed_services, PREFIXES)
        try:
            with evaluation_errors():
                return self._store.query(text, prefixes=PREFIXES, use_default_graph_as_union=True)
        except SyntaxError as err:
            raise QueryError(syntax_error_message(err, text, PREFIXES)) from None

    def query(self, sparql: str, **bindings: Any) -> QueryResult:
        """Run a SELECT and return its rows as dictionaries of Python values.

        >>> kg = GraphStore.memory()
        >>> kg.query("SELECT ?c WHERE { ?c a owl:Class ; rdfs:label ?l } LIMIT 1").variables
        ('c',)
        """
        result = self.raw_query(sparql, bindings)
        if not isinstance(result, ox.QuerySolutions):
            raise QueryError("query() runs SELECT queries; use ask() or construct()")
        variables = tuple(v.value for v in result.variables)
        convert, width = term_value, range(len(variables))
        with evaluation_errors():
            rows = tuple(
                dict(zip(variables, [convert(solution[i]) for i in width], strict=True))
                for solution in result
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
        with evaluation_errors():
            return list(result)

    def quads(self, graphs: Iterable[str] | None = None) -> Iterator[ox.Quad]:
        """Every quad, or those of the named ``graphs``."""
        if graphs is None:
            return iter(self._store)
        return (q for g in graphs for q in self.graph_quads(g))

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
            quads = self.quads(graphs)
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

    def replace_graph(self, graph: str, ntriples: bytes) -> None:
        """Replace the named graph ``graph`` with ``ntriples`` in one transaction. Nothing is
        derived again: for graphs nothing is derived from (a plan).

        Raises
        ------
        StoreError
            On a read-only store.
        """
        if self.read_only:
            raise StoreError("the store is open read-only")
        inserts = ntriples.decode("utf-8")
        self._store.update(f"DROP SILENT GRAPH <{graph}> ; INSERT DATA {{ GRAPH <{graph}> {{ {inserts} }} }}")

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
        dataset is as in :meth:`raw_query`. An update runs inside :meth:`_change`, where a
        subclass keeps what it derives from the graph in step.

        Raises
        ------
        QueryError
            On a syntax error (with its line and column) or an evaluation error.
        StoreError
            On an update of a read-only store, or as :meth:`raw_query`.
        """
        check_outbound(sparql, self.allowed_services, PREFIXES)
        try:
            with evaluation_errors():
                return self._execute(sparql, update, default_graphs, named_graphs)
        except SyntaxError as err:
            raise QueryError(syntax_error_message(err, sparql, PREFIXES)) from None
        except ValueError as err:
            raise QueryError(f"not an IRI: {err}") from None

    def _execute(
        self,
        sparql: str,
        update: bool,
        default_graphs: Iterable[str] | None,
        named_graphs: Iterable[str] | None,
    ) -> Any:
        if update:
            if self.read_only:
                raise StoreError("the store is open read-only")
            with self._change():
                self._store.update(sparql, prefixes=PREFIXES)
            return None
        if default_graphs is None and named_graphs is None:
            return self._store.query(sparql, prefixes=PREFIXES, use_default_graph_as_union=True)
        return self._store.query(
            sparql,
            prefixes=PREFIXES,
            default_graph=[ox.NamedNode(g) for g in default_graphs or ()],
            named_graphs=[ox.NamedNode(g) for g in named_graphs or ()],
        )


@contextlib.contextmanager
def evaluation_errors() -> Iterator[None]:
    """Errors pyoxigraph raises while a query's solutions are read, as one line: what it could
    not reach or read (a failing ``SERVICE``, a store whose files went away) as
    :class:`StoreError`, what it could not evaluate (an unbound ``SERVICE`` variable) as
    :class:`QueryError`."""
    try:
        yield
    except OSError as err:
        raise StoreError(f"the query failed: {err}") from None
    except RuntimeError as err:
        raise QueryError(f"the query failed: {err}") from None
