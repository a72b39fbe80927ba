"""The harness text reader: the example door harness by hand, units, routes, and located errors."""

from __future__ import annotations

from collections.abc import Callable
from decimal import Decimal
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.ingest.harness.records import (
    Harness,
    HarnessCable,
    HarnessConnector,
    HarnessFixing,
    HarnessNode,
    HarnessProtection,
    HarnessRecord,
    HarnessSegment,
    HarnessWire,
    WireEnd,
    WireRoute,
)
from cadkg.registry import sniff_kind
from cadkg.usecases.vw.harness_text import FILE_FORMAT, read_harness_text
from tests.conftest import EXAMPLES

DOOR = EXAMPLES / "vw-harness" / "door-l.harness"

Write = Callable[[str, str | bytes], Path]

HEAD = "harness H\nconnector A cavities=1-2\nconnector B cavities=1,2\n"


def of(records: list[HarnessRecord], kind: type) -> list:  # type: ignore[type-arg]
    return [r for r in records if isinstance(r, kind)]


def read(write: Write, text: str) -> list[HarnessRecord]:
    return read_harness_text(write("h.harness", text))


def error(write: Write, text: str) -> IngestError:
    with pytest.raises(IngestError) as caught:
        read(write, text)
    return caught.value


def test_door_harness_by_hand() -> None:
    records = read_harness_text(DOOR)
    assert of(records, Harness) == [Harness("DOOR-L", "front door harness, left (demo)", FILE_FORMAT, 2)]
    connectors = of(records, HarnessConnector)
    assert [(c.ident, c.cavities) for c in connectors] == [
        ("X1", ("1", "2", "3", "4", "5", "6")),
        ("X2", ("1", "2", "3", "4")),
        ("X3", ("1", "2")),
        ("X4", ("1", "2", "3")),
    ]
    assert connectors[1] == HarnessConnector(
        "DOOR-L", "X2", "X2", "connector", ("1", "2", "3", "4"), "door control unit", 6
    )
    assert [(n.ident, n.connectors) for n in of(records, HarnessNode)] == [
        ("X1", ("X1",)),
        ("X2", ("X2",)),
        ("X3", ("X3",)),
        ("X4", ("X4",)),
        ("B1", ()),
        ("B2", ()),
    ]
    segments = {s.ident: s for s in of(records, HarnessSegment)}
    assert segments["S1"] == HarnessSegment(
        "DOOR-L", "S1", "S1", "X1", "B1", Decimal("0.35"), 0.009, None, 14
    )
    assert sum(s.length_m or 0 for s in segments.values()) == Decimal("1.0")
    wires = {w.ident: w for w in of(records, HarnessWire)}
    assert len(wires) == 7
    assert wires["W3"] == HarnessWire(
        harness="DOOR-L",
        ident="W3",
        label="W3",
        ends=(WireEnd("X1", "3"), WireEnd("X3", "1")),
        routes=(WireRoute("W3", ("S1", "S3", "S4")),),  # found: the one chain of segments from X1 to X3
        section_mm2=Decimal("1.5"),
        colour="RD/WH",
        length_m=Decimal("0.75"),
        diameter_m=None,
        cable=None,
        signal=None,
        line=23,
    )
    assert {name: w.route for name, w in wires.items()} == {
        "W1": ("S1", "S2"),
        "W2": ("S1", "S2"),
        "W3": ("S1", "S3", "S4"),
        "W4": ("S1", "S3", "S4"),
        "W5": ("S2", "S3", "S5"),
        "W6": ("S2", "S3", "S5"),
        "W7": ("S1", "S3", "S5"),
    }
    assert of(records, HarnessFixing) == [
        HarnessFixing("DOOR-L", "F1", "F1", "clip at the door hinge", (), ("S1",), 29),
        HarnessFixing("DOOR-L", "F2", "F2", "cable tie", ("B2",), (), 30),
    ]
    assert of(records, HarnessProtection) == [
        HarnessProtection("DOOR-L", "P1", "P1", "corrugated tube through the hinge", ("S1",), None, 31),
        HarnessProtection("DOOR-L", "P2", "P2", "tape", ("S3", "S4"), None, 32),
    ]


@pytest.mark.parametrize("length", ["250mm", "25cm", "0.25m", ".25m", "250.0mm"])
def test_length_units(write: Write, length: str) -> None:
    records = read(write, HEAD + f"segment S A B length={length} diameter=4mm\n")
    (segment,) = of(records, HarnessSegment)
    assert segment.length_m == Decimal("0.25")
    assert segment.diameter_m == pytest.approx(0.004)


def test_connector_at_a_node_cable_cores_and_forward_references(write: Write) -> None:
    text = (
        "# comment line\n"
        "harness H description='two words'   # trailing comment\n"
        'wire C1 A:1 B:2 cable=K section=0.5mm2 signal="KL 30"\n'  # names declared further down
        "cable K length=1m diameter=5mm\n"
        "connector A cavities=1-2,S at=N\n"
        "connector B cavities=1,2\n"
        "node N\n"
        "segment S1 N B length=1m section=12.5\n"
    )
    records = read(write, text)
    assert of(records, Harness)[0].description == "two words"
    assert [(n.ident, n.connectors) for n in of(records, HarnessNode)] == [("B", ("B",)), ("N", ("A",))]
    assert of(records, HarnessConnector)[0].cavities == ("1", "2", "S")
    assert of(records, HarnessCable) == [HarnessCable("H", "K", "K", Decimal(1), 0.005, 4)]
    (wire,) = of(records, HarnessWire)
    assert (wire.cable, wire.signal, wire.section_mm2, wire.route) == ("K", "KL 30", Decimal("0.5"), ("S1",))
    assert of(records, HarnessSegment)[0].section_mm2 == Decimal("12.5")


def test_wire_between_cavities_of_one_connector_needs_no_route(write: Write) -> None:
    (wire,) = of(read(write, HEAD + "wire W A:1 A:2\n"), HarnessWire)
    assert wire.route == ()


def test_shortest_chain_is_taken(write: Write) -> None:
    text = HEAD + "node M\nsegment L A B length=2m\nsegment S1 A M length=0.5m\nsegment S2 M B length=0.5m\n"
    text += "wire W A:1 B:1\n"
    (wire,) = of(read(write, text), HarnessWire)
    assert wire.route == ("S1", "S2")


def test_sniffer_and_suffix(tmp_path: Path) -> None:
    assert sniff_kind(DOOR) == "harness-text"
    odd = tmp_path / "door.desc"
    odd.write_text("# a comment first\n\nharness X\n", encoding="utf-8")
    assert sniff_kind(odd) == "harness-text"


# -- bad input ------------------------------------------------------------------------------------------


def test_segment_to_an_unknown_node(write: Write) -> None:
    err = error(write, HEAD + "node B1\nsegment S1 A B2 length=1m\n")
    assert (err.line, err.found) == (5, "B2")
    assert "segment S1 leads to an unknown node" in str(err)
    assert "expected one of: A, B, B1" in str(err)
    assert str(err).startswith(f"{err.path}:5: ")


@pytest.mark.parametrize(
    ("body", "line", "found", "reason"),
    [
        ("segment S1 A B length=1\n", 4, "1", "malformed length"),
        ("segment S1 A B length=-1m\n", 4, "-1m", "malformed length"),
        ("segment S1 A B length=0mm\n", 4, "0mm", "malformed length"),
        ("segment S1 A B\n", 4, None, "'segment' needs length="),
        ("segment S1 A B length=1m lenght=2m\n", 4, "lenght", "unknown key of 'segment'"),
        ("segment S1 A length=1m\n", 4, "S1 A", "'segment' takes 3 word(s)"),
        ("segment S1 A A length=1m\n", 4, "A", "starts and ends at the same node"),
        ("segment S1 A B length=1m diameter=3\n", 4, "3", "malformed diameter"),
        ("segment S1 A B length=1m section=0\n", 4, "0", "malformed section"),
        ("wire W1 A:1 C:1\n", 4, "C", "wire W1 ends at an unknown connector"),
        ("wire W1 A:1 B:3\n", 4, "B:3", "a cavity connector B does not have"),
        ("wire W1 A:1 B\n", 4, "B", "malformed end of wire W1"),
        ("wire W1 A:1 B:1\n", 4, "nodes A and B", "no chain of segments joins the ends of wire W1"),
        ("segment S A B length=1m\nwire W1 A:1 B:1 route=S,T\n", 5, "T", "names an unknown segment"),
        ("node M\nsegment S A M length=1m\nwire W1 A:1 B:1 route=S\n", 6, "ends at node M", "does not reach"),
        ("node M\nsegment S M B length=1m\nwire W1 A:1 B:1 route=S\n", 6, "S (M-B)", "breaks at segment S"),
        ("wire W1 A:1 A:2 cable=K\n", 4, "K", "a core of an unknown cable"),
        ("connector C cavities=3-1\n", 4, "3-1", "bad cavity range"),
        ("connector C cavities=1-" + "9" * 5000 + "\n", 4, "1-" + "9" * 5000, "bad cavity range"),
        ("connector C cavities=" + "9" * 5000 + "-1\n", 4, "9" * 5000 + "-1", "bad cavity range"),
        ("connector C cavities=1,,2\n", 4, "an empty name", "malformed cavity list"),
        ("connector C cavities=1,1\n", 4, "1", "cavity listed twice"),
        ("connector C cavities=" + ",".join(["1-900"] * 500) + "\n", 4, "1800", "too many cavities"),
        ("connector C cavities=1 at=Q\n", 4, "Q", "connector C is at an unknown node"),
        ("connector A cavities=1\n", 4, "A", "connector declared twice"),
        ("node A\n", 4, "A", "node declared twice"),
        ("fixing F on=Q\n", 4, "Q", "fixing F is on an unknown node or segment"),
        ("protection P on=A\n", 4, "A", "protection P is on an unknown segment"),
        ("splice S\n", 4, "splice", "unknown statement"),
        ("harness G\n", 4, "G", "a second harness statement"),
        ('node "N 1"\n', 4, "N 1", "malformed node name"),
        ("node N description='x\n", 4, None, "cannot split the line into words"),
        ("node N color=\n", 4, "color", "unknown key of 'node'"),
        ("wire W A:1 A:2 colour=\n", 4, None, "empty value of colour="),
    ],
)
def test_located_errors(write: Write, body: str, line: int, found: str | None, reason: str) -> None:
    err = error(write, HEAD + body)
    assert err.line == line
    assert err.found == found
    assert reason in str(err)


def test_the_harness_comes_first(write: Write) -> None:
    err = error(write, "# a door\nconnector A cavities=1\nharness H\n")
    assert (err.line, err.found) == (2, "connector")
    assert "expected harness NAME" in str(err)


@pytest.mark.parametrize(("text", "reason"), [("", "empty"), ("# only a comment\n\n", "no statements")])
def test_empty(write: Write, text: str, reason: str) -> None:
    assert reason in str(error(write, text))


def test_positions_of_nodes_and_connectors(write: Write) -> None:
    """position= gives a node's place (a connector's: that of the node named like it), in metres."""
    text = HEAD + "node M position=1.2m,-350mm,40cm\nconnector C cavities=1 position=0m,0m,0m\n"
    nodes = {n.ident: n.position for n in of(read(write, text), HarnessNode)}
    assert nodes == {"A": None, "B": None, "C": (0.0, 0.0, 0.0), "M": (1.2, -0.35, 0.4)}


@pytest.mark.parametrize(
    ("body", "found", "reason"),
    [
        ("node M position=1,2\n", "1,2", "malformed position"),
        ("node M position=1m,2m,3\n", "1m,2m,3", "malformed position"),
        (
            "node M\nconnector C cavities=1 at=M position=1m,2m,3m\n",
            "at=M",
            "connector C has both at= and position=",
        ),
    ],
)
def test_bad_positions(write: Write, body: str, found: str, reason: str) -> None:
    with pytest.raises(IngestError) as caught:
        read(write, HEAD + body)
    assert (caught.value.found, caught.value.line) == (found, HEAD.count("\n") + body.count("\n"))
    assert reason in str(caught.value)


def _shlex_words(line: str) -> list[str] | str:
    import shlex

    lexer = shlex.shlex(line, posix=True)
    lexer.whitespace_split = True
    lexer.commenters = "#"
    try:
        return list(lexer)
    except ValueError as err:
        return str(err)


def test_lines_split_into_the_words_shlex_gives() -> None:
    """The reader splits lines itself, in linear time; its words (and refusals) are shlex's."""
    import random

    from cadkg.usecases.vw.harness_statements import split_words

    def words(line: str) -> list[str] | str:
        try:
            return split_words(line)
        except ValueError as err:
            return str(err)

    pieces = ["a", "b=", " ", "\t", "\r", "\n", "'", '"', "\\", "#", "é", "\x0b", "x=1", "''"]
    rng = random.Random(43)
    lines = ["".join(rng.choice(pieces) for _ in range(rng.randint(0, 12))) for _ in range(30_000)]
    lines += ['a "b\\"c\\\\d\\e" f', "'a\\b' c#d", 'k="x y"z #c', '"\\', "\\", "a\\ b", '""', "x'"]
    differ = [(line, words(line), _shlex_words(line)) for line in lines if words(line) != _shlex_words(line)]
    assert differ == []
    assert {_shlex_words(line) for line in lines if isinstance(_shlex_words(line), str)} == {
        "No closing quotation",
        "No escaped character",
    }
