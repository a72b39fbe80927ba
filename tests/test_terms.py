from __future__ import annotations

import pytest
import rdflib

from cadkg.errors import UnknownTermError
from cadkg.ontology import CK, CK_NS, ontology_path
from cadkg.ontology.terms import declared_terms


def test_terms_match_the_turtle_file() -> None:
    graph = rdflib.Graph().parse(ontology_path(), format="turtle")
    owl = rdflib.OWL
    declared = {
        str(s)[len(CK_NS) :]
        for kind in (owl.Class, owl.ObjectProperty, owl.DatatypeProperty, owl.NamedIndividual)
        for s in graph.subjects(rdflib.RDF.type, kind)
        if str(s).startswith(CK_NS)
    }
    assert declared == set(declared_terms())
    for name in declared:
        assert CK[name].value == CK_NS + name


@pytest.mark.parametrize("name", ["Wier", "fromPins", "wire", "Hasbranch"])
def test_a_misspelt_term_raises(name: str) -> None:
    with pytest.raises(UnknownTermError, match=name):
        getattr(CK, name)


def test_attribute_access() -> None:
    assert CK.Wire.value == "https://w3id.org/cadkg#Wire"
    assert "fromPin" in CK
    assert "fromPins" not in CK
