"""rdflib interop: ``kg.rdflib_dataset()`` is rdflib's API over the same pyoxigraph store."""

from __future__ import annotations

import builtins
from typing import Any

import pytest

import cadkg
from cadkg.errors import StoreError

COUNT = "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }"
WIRES = "PREFIX ck: <https://w3id.org/cadkg#> SELECT ?w WHERE { ?w a ck:Wire } ORDER BY ?w"


def test_rdflib_sees_the_quads_cadkg_holds(iema: cadkg.KnowledgeGraph) -> None:
    pytest.importorskip("oxrdflib")
    dataset = iema.rdflib_dataset()
    assert sum(1 for _ in dataset.quads((None, None, None, None))) == len(iema) > 1000
    ((count,),) = list(dataset.query(COUNT))
    assert int(count) == iema.query(COUNT).rows[0]["n"] == len(iema)
    wires = [str(row[0]) for row in dataset.query(WIRES)]
    assert wires == [row["w"] for row in iema.query(WIRES).rows]
    assert len(wires) > 10


def test_a_change_through_rdflib_is_in_the_store() -> None:
    rdflib = pytest.importorskip("rdflib")
    pytest.importorskip("oxrdflib")
    kg = cadkg.KnowledgeGraph.memory()
    before = len(kg)
    graph = rdflib.URIRef("https://example.org/g")
    dataset = kg.rdflib_dataset()
    dataset.graph(graph).add((rdflib.URIRef("https://example.org/s"), rdflib.RDFS.label, rdflib.Literal("s")))
    assert len(kg) == before + 1
    assert kg.query("SELECT ?l WHERE { <https://example.org/s> rdfs:label ?l }").rows == ({"l": "s"},)


def test_without_the_extra_the_error_names_it(monkeypatch: pytest.MonkeyPatch) -> None:
    real_import = builtins.__import__

    def refuse(name: str, *args: Any, **kwargs: Any) -> Any:
        if name == "oxrdflib":
            raise ImportError("no oxrdflib", name="oxrdflib")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", refuse)
    with pytest.raises(StoreError, match=r"oxrdflib is missing.*pip install 'cadkg\[rdflib\]'"):
        cadkg.KnowledgeGraph.memory().rdflib_dataset()
