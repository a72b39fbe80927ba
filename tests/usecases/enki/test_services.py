"""ENKI's hose_info on examples/enki-hose."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.query.validate import validate
from cadkg.services.session import Session
from cadkg.services.table import call, services_for
from cadkg.usecases.enki.services import HoseInfoResult, hose_info, hose_model
from tests.conftest import EXAMPLES


@pytest.fixture(scope="module")
def kg() -> Iterator[KnowledgeGraph]:
    graph = KnowledgeGraph.build(EXAMPLES / "enki-hose" / "manifest.toml")
    yield graph
    graph.close()


def test_hose_info_of_each_product(kg: KnowledgeGraph) -> None:
    hoses = hose_model(kg)
    assert list(hoses) == ["HX-08", "HX-16", "HX-25"]
    assert hose_info(hoses, "HX-16") == HoseInfoResult(True, "ok", "HX-16", 0.016, 2.5, "EPDM", 0.08)
    assert hose_info(hoses, "HX-25") == HoseInfoResult(
        True, "not given: length", "HX-25", 0.0254, None, "PVC", 0.125
    )
    assert hose_info(hoses, "HX-08") == HoseInfoResult(
        True, "not given: bend radius", "HX-08", 0.008, 1.2, "silicone", None
    )


def test_product_names_match_ignoring_case_when_unambiguous(kg: KnowledgeGraph) -> None:
    assert hose_info(hose_model(kg), " hx-16 ").diameter == 0.016


def test_unknown_product(kg: KnowledgeGraph) -> None:
    result = hose_info(hose_model(kg), "HX-99")
    assert result == HoseInfoResult(False, "no hose product 'HX-99'; products: HX-08, HX-16, HX-25")


def test_through_the_service_table(kg: KnowledgeGraph) -> None:
    session = Session(kg.cell_model(), kg=kg)
    assert [s.name for s in services_for("enki")] == ["hose_info"]
    assert call(session, "hose_info", {"product": "HX-25"}).bend_radius == 0.125


def test_a_graph_without_hoses() -> None:
    assert hose_info({}, "HX-16").message == "no hose product 'HX-16'; products: none"


def test_the_example_graph_validates(kg: KnowledgeGraph) -> None:
    assert validate(kg) == []
