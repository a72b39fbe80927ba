"""Two baselines of ``bench_build.py``, each run as a job in a fresh process.

- **rdflib terms**: rdflib's fastest way in, for a program that makes its own triples: the
  terms built in Python (``URIRef``, ``Literal``, each distinct term once) and added in bulk
  (``Dataset.store.addN``, the store's own bulk call, without ``Dataset.addN``'s per-quad
  graph lookups, which cost another 80 % here). The quads are the build's N-Triples, parsed
  into plain strings before the clock starts, so only the making and adding of terms is timed.
  Both rdflib paths run with the cyclic garbage collector paused, as cadkg's build does.
- **bare bulk load**: the build's own quads (the ontology and the N-Triples of every named
  graph) bulk-loaded into a fresh on-disk pyoxigraph store, one ``bulk_load`` per graph, then
  ``flush`` and ``optimize`` as the on-disk build finishes its store. No cadkg code runs: it
  is what the store alone costs for what the build writes.
"""

from __future__ import annotations

import shutil
import time
from pathlib import Path
from typing import Any

Json = dict[str, Any]
Plain = tuple[str, ...]  # ("i", iri) | ("b", id) | ("l", text, datatype, language)
_STRING = "http://www.w3.org/2001/XMLSchema#string"


def _plain(term: Any) -> Plain:
    import pyoxigraph as ox

    if isinstance(term, ox.NamedNode):
        return ("i", term.value)
    if isinstance(term, ox.BlankNode):
        return ("b", term.value)
    return ("l", term.value, term.datatype.value, term.language or "")


def _graphs(spec: Json) -> list[tuple[str, bytes, Any]]:
    """(graph, data, format) of the ontology and of each graph the read+map job wrote."""
    import pyoxigraph as ox

    from bench_build import load_graph_files
    from cadkg.ontology.terms import ONTOLOGY_IRI, ontology_path

    ontology = Path(ontology_path()).read_bytes()
    graphs = [(ONTOLOGY_IRI, ontology, ox.RdfFormat.TURTLE)]
    return graphs + [(g, data, ox.RdfFormat.N_TRIPLES) for g, data in load_graph_files(Path(spec["workdir"]))]


def job_rdflib_terms(spec: Json) -> Json:
    """The quads as rdflib terms, added to a ``Dataset(default_union=True)`` in bulk."""
    import pyoxigraph as ox
    from rdflib import BNode, Dataset, Literal, URIRef

    from bench_build import peak_rss_mib
    from cadkg.loading import paused_gc

    rows = [
        (graph, _plain(t.subject), _plain(t.predicate), _plain(t.object))
        for graph, data, fmt in _graphs(spec)
        for t in ox.parse(data, format=fmt)
    ]
    started = time.perf_counter()
    ds = Dataset(default_union=True)
    contexts: dict[str, Any] = {}
    terms: dict[Plain, Any] = {}

    def term(plain: Plain) -> Any:
        made = terms.get(plain)
        if made is None:
            if plain[0] == "i":
                made = URIRef(plain[1])
            elif plain[0] == "b":
                made = BNode(plain[1])
            elif plain[3]:
                made = Literal(plain[1], lang=plain[3])
            else:
                made = Literal(plain[1], datatype=None if plain[2] == _STRING else URIRef(plain[2]))
            terms[plain] = made
        return made

    def context(graph: str) -> Any:
        made = contexts.get(graph)
        if made is None:
            made = contexts[graph] = ds.graph(URIRef(graph))
        return made

    with paused_gc():  # as cadkg's build runs
        ds.store.addN((term(s), term(p), term(o), context(g)) for g, s, p, o in rows)
    seconds = time.perf_counter() - started
    triples = sum(len(graph) for graph in contexts.values())
    return {"seconds": seconds, "triples": triples, "peak_mib": peak_rss_mib()}


def job_bulk_load(spec: Json) -> Json:
    """The build's quads bulk-loaded into a fresh on-disk store, flushed and optimized."""
    import pyoxigraph as ox

    from bench_build import peak_rss_mib

    graphs = _graphs(spec)
    target = Path(spec["workdir"]) / "bulk-store"
    shutil.rmtree(target, ignore_errors=True)
    started = time.perf_counter()
    store = ox.Store(str(target))
    for graph, data, fmt in graphs:
        store.bulk_load(data, fmt, to_graph=ox.NamedNode(graph), lenient=True)
    store.flush()
    store.optimize()
    seconds = time.perf_counter() - started
    quads = len(store)
    del store
    shutil.rmtree(target, ignore_errors=True)
    return {"seconds": seconds, "triples": quads, "peak_mib": peak_rss_mib()}
