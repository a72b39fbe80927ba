"""The assembly sequence as the reference node serves it, with a cursor per client: every
operation's spots in one form, end on the last, index from 0, rewinds, and the cases where the
reference node fails (an EC, T or TJ step handed out, an index out of range)."""

from __future__ import annotations

import pytest

from cadkg.graph import KnowledgeGraph
from cadkg.services.session import Session
from cadkg.services.table import call
from cadkg.usecases.elvez.sequence_services import OperationItem, SequenceCursor, SpotData
from tests.conftest import ROOT

ELVEZ = ROOT / "examples" / "elvez-cell" / "manifest.toml"
CODES = ["EC", "PC", "RC", "RC", "T", "EC", "PC", "RC", "TJ"]


@pytest.fixture(scope="module")
def kg(elvez: KnowledgeGraph) -> KnowledgeGraph:
    return elvez  # built once per session (tests/conftest.py)


@pytest.fixture
def session(kg: KnowledgeGraph) -> Session:
    return Session(kg.cell_model(), kg=kg)


def seq(session: Session, name: str, client: str = "default", **params: str) -> object:
    return call(session, f"CAD_platform.{name}", params, client=client)


def test_next_operation_walks_the_sequence_and_ends_on_the_last(session: Session) -> None:
    answers = [seq(session, "next_operation") for _ in range(10)]
    assert [a.type for a in answers] == [*CODES, "EC"]
    assert [a.end for a in answers] == [False] * 8 + [True, False]
    first = answers[0]
    assert (first.success, first.label, first.spot) == (True, ("WH1",), (SpotData("C1", "1", "L"),))
    assert first.message == "operation 0 (order 1): EC WH1 at C1.1.L"
    assert answers[2].spot == (SpotData("J1", "1", ""), SpotData("J2", "1", ""), SpotData("J3", "1", ""))
    assert answers[8].spot == (SpotData("J3", "1", ""),)  # TJ: jig and guide
    assert answers[8].message.endswith("; end of the sequence")


def test_each_client_has_its_own_cursor(session: Session) -> None:
    seq(session, "next_operation", "left")
    seq(session, "next_operation", "left")
    assert seq(session, "next_operation", "right").type == "EC"
    assert seq(session, "next_operation", "left").type == "RC"
    assert session.cursor("elvez", "left", SequenceCursor).position == 3
    assert session.dump()["elvez"] == {"left": {"position": 3}, "right": {"position": 1}}


def test_index_operation_from_zero_moves_the_cursor(session: Session) -> None:
    result = seq(session, "index_operation", index="3")
    assert (result.success, result.index, result.type, result.label, result.end) == (
        True,
        4,
        "RC",
        ("GR12",),
        False,
    )
    assert seq(session, "next_operation").type == "T"
    last = seq(session, "index_operation", index="8")
    assert (last.type, last.index, last.end) == ("TJ", 0, True)
    for index in ("9", "-1"):
        missing = seq(session, "index_operation", index=index)
        assert (missing.success, missing.message) == (
            False,
            f"no operation {index}; the sequence has operations 0 to 8",
        )


def test_resets(session: Session) -> None:
    seq(session, "index_operation", index="5")
    assert seq(session, "reset_sequence_list").success
    assert seq(session, "next_operation").type == "EC"
    moved = seq(session, "reset_sequence_list_to", index="7")
    assert (moved.success, moved.message) == (True, "next: operation 7")
    assert seq(session, "next_operation").type == "RC"
    for index in ("9", "-1"):  # the reference counted -1 from the end; cadkg refuses it
        refused = seq(session, "reset_sequence_list_to", index=index)
        assert (refused.success, refused.message) == (
            False,
            f"no operation {index}; the sequence has operations 0 to 8",
        )


def test_all_operations_rewinds_the_cursor(session: Session) -> None:
    seq(session, "index_operation", index="4")
    result = seq(session, "all_operations")
    assert [op.type for op in result.data] == CODES
    assert result.data[1] == OperationItem("PC", ("WH1",), (SpotData("J4", "1", "L"),))
    assert result.data[5].spot == (SpotData("C2", "1", "R"),)
    assert seq(session, "next_operation").type == "EC"


def test_a_cursor_read_back_from_a_file_keeps_its_type(session: Session) -> None:
    session.load({"elvez": {"arm": {"position": "2"}}})
    assert seq(session, "next_operation", "arm").type == "RC"
