"""The wiring harness configuration, the components definition and the assembly sequence:
their shapes as the cell writes them (CRLF, trailing ';', empty cells, comments) and located errors."""

from __future__ import annotations

import warnings
from collections.abc import Callable
from pathlib import Path

import pytest

from cadkg.errors import IngestError, IngestWarning
from cadkg.usecases.elvez.files.components import looks_like_components, read_components
from cadkg.usecases.elvez.files.harnesses import (
    looks_like_harness_configuration,
    read_harness_configuration,
    split_tray,
)
from cadkg.usecases.elvez.files.sequence import SpotRef, looks_like_sequence, parse_spots, read_sequence

Write = Callable[[str, str | bytes], Path]
HEADER = "Type;Model;Reference;Label;Color;length;Diameter;x;y;z;Type"
OPEN = '<wiring_harness id="1" first_connector="W"><end_connector label="G">\n'
CLOSE = "</end_connector></wiring_harness>"


# -- harnesses ----------------------------------------------------------------------------------------


def test_harnesses_with_cavities_in_order(write: Write) -> None:
    text = """<?xml version="1.0"?>
<data>
    <wiring_harness id="1" first_connector="WH1" tray="B3.1">
        <end_connector label="GR11">
            <cable Row1="2" Col1="0">CA2</cable>
\t    <cable Row1="0" Col1="0">CA1</cable>
\t</end_connector>
        <end_connector label="GR12">
            <cable Row1="1" Col1="0" Row2="0" Col2="1">CA3</cable>
        </end_connector>
    </wiring_harness>
    <wiring_harness id="2" first_connector="WH2" tray="B3">
    </wiring_harness>
</data>
"""
    first, second = read_harness_configuration(write("WH_configuration.xml", text))
    assert (first.id, first.first_connector, first.tray, first.line) == ("1", "WH1", "B3.1", 3)
    assert [
        (e.label, [(c.label, c.first_cavity, c.end_cavity, c.line) for c in e.cables])
        for e in first.end_connectors
    ] == [
        ("GR11", [("CA2", (2, 0), None, 5), ("CA1", (0, 0), None, 6)]),
        ("GR12", [("CA3", (1, 0), (0, 1), 9)]),
    ]
    assert (second.end_connectors, split_tray(second.tray)) == ((), ("B3", "1"))
    assert split_tray("B3.2") == ("B3", "2") and split_tray("") == ("", "")


@pytest.mark.parametrize(
    ("body", "line", "reason"),
    [
        (
            '<wiring_harness id="1" first_connector="W"/>\n<wiring_harness id="1" first_connector="V"/>',
            4,
            "harness 1 given twice (first on line 3)",
        ),
        (
            OPEN + '<cable Row1="0" Col1="0">C</cable>\n<cable Row1="1" Col1="0">C</cable>' + CLOSE,
            5,
            "cable C given twice (first on line 4)",
        ),
        (
            OPEN + '<cable Row1="0">C</cable>' + CLOSE,
            4,
            "<cable> without a 'Col1' attribute",
        ),
        (
            OPEN + '<cable Row1="0" Col1="0" Row2="1">C</cable>' + CLOSE,
            4,
            "<cable> without a 'Col2' attribute",
        ),
        (
            OPEN + '<cable Row1="-1" Col1="0">C</cable>' + CLOSE,
            4,
            "'Row1' of <cable> is not a whole number of at least 0",
        ),
        (
            OPEN + '<cable Row1="0" Col1="0"> </cable>' + CLOSE,
            4,
            "<cable> without a label",
        ),
        ('<wiring_harness first_connector="W"/>', 3, "<wiring_harness> without a 'id' attribute"),
        ("<harness/>", 3, "unexpected element <harness> inside <data>"),
    ],
)
def test_harness_errors(write: Write, body: str, line: int, reason: str) -> None:
    with pytest.raises(IngestError) as info:
        read_harness_configuration(write("wh.xml", f'<?xml version="1.0"?>\n<data>\n{body}\n</data>\n'))
    assert (info.value.line, info.value.reason) == (line, reason)


def test_harness_sniffing() -> None:
    assert looks_like_harness_configuration(b'<?xml version="1.0"?>\n<data>\n    <wiring_harness id="1"')
    assert not looks_like_harness_configuration(b"<data><jig model='1'/>")


# -- components ---------------------------------------------------------------------------------------


def test_components_as_the_cell_writes_them(write: Write) -> None:
    rows = [
        HEADER,
        "Connector;LUM1;111;WH1;White;;;32.9;14.64;46.55;",
        "Cable;;;CA1;Yellow;500;5.1;;;;",
        "",
        "device;CAP1;333;K1;Teal;;;;;;capacitor",
    ]
    path = write("Components_definition.csv", "\ufeff" + "\r\n".join(rows) + "\r\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", IngestWarning)
        connector, cable, device = read_components(path)
    assert (connector.kind, connector.model, connector.reference, connector.label) == (
        "connector",
        "LUM1",
        "111",
        "WH1",
    )
    assert (connector.colour, connector.rgb, connector.size) == (
        "White",
        (255, 255, 255),
        (0.0329, 0.01464, 0.04655),
    )
    assert (connector.length, connector.diameter) == (None, None)
    assert (cable.kind, cable.rgb, cable.length, cable.diameter, cable.size) == (
        "cable",
        (255, 255, 0),
        0.5,
        0.0051,
        None,
    )
    assert (device.kind, device.device_type, device.rgb, device.line) == ("device", "capacitor", None, 5)
    assert [str(w.message).split(": ", 1)[1] for w in caught] == [
        "colour 'Teal' of K1 has no red, green, blue values"
    ]


@pytest.mark.parametrize(
    ("row", "reason"),
    [
        ("Wire;;;W1;Red;1;1;;;;", "unknown component type"),
        ("Cable;;;;Red;1;1;;;;", "a component without a label"),
        ("Cable;;;CA1;Red;500;5.1;;;;", "label CA1 given twice (first on line 2)"),
        ("Cable;;;CA2;Red;five;5.1;;;;", "length is not a number of millimetres"),
        ("Connector;M;1;WH9;Red;;;1;2;;", "size of WH9 given in part"),
        ("Cable;;;CA3;Red;1;1;;;;;extra", "12 cells in the row"),
    ],
)
def test_component_errors(write: Write, row: str, reason: str) -> None:
    path = write("c.csv", "\n".join([HEADER, "Cable;;;CA1;Red;500;5.1;;;;", row]) + "\n")
    with pytest.raises(IngestError) as info:
        read_components(path)
    assert (info.value.line, info.value.reason) == (3, reason)


def test_components_need_their_header(write: Write) -> None:
    with pytest.raises(IngestError, match="no components header"):
        read_components(write("c.csv", "name,type\nW1,cable\n"))
    assert looks_like_components(HEADER.encode() + b"\r\n")
    assert looks_like_components((HEADER + ";").encode())
    assert not looks_like_components(b"name,type,red,green,blue\n")


# -- sequence -----------------------------------------------------------------------------------------


def test_every_operation_code_and_its_spots(write: Write) -> None:
    rows = [
        "Order;Type of operation;Label;Spot",
        "1;EC;WH1;C1.1.L",
        "2;pc;WH1;J8.1.r",
        "3;RC;GR11;J4.1-J3.1-J2.1",
        "4;T;WH1;J1.1-J2.1-J2.1",
        "5;TJ;WH1-WH2;J3.1",
    ]
    steps = read_sequence(write("Assembly_sequence.csv", "\r\n".join(rows) + "\r\n"))
    assert [(s.order, s.code, s.labels, s.line) for s in steps] == [
        (1, "EC", ("WH1",), 2),
        (2, "pc", ("WH1",), 3),
        (3, "RC", ("GR11",), 4),
        (4, "T", ("WH1",), 5),
        (5, "TJ", ("WH1", "WH2"), 6),
    ]
    assert steps[0].spots == (SpotRef("C1", "1", "L"),)
    assert steps[1].spots == (SpotRef("J8", "1", "r"),)
    assert steps[2].spots == (SpotRef("J4", "1"), SpotRef("J3", "1"), SpotRef("J2", "1"))
    assert [s.jig for s in steps[3].spots] == ["J1", "J2", "J2"]
    assert steps[4].spots == (SpotRef("J3", "1"),)


@pytest.mark.parametrize(
    ("code", "spot"),
    [
        ("EC", "C1.1"),
        ("PC", "J8.1.X"),
        ("EC", "C1.1.L-C2.1.L"),
        ("RC", "J4.1.L"),
        ("RC", "J4.1-"),
        ("TJ", "J3.1-J4.1"),
        ("T", ""),
    ],
)
def test_malformed_spots(code: str, spot: str) -> None:
    assert parse_spots(code, spot) is None


@pytest.mark.parametrize(
    ("row", "reason", "found"),
    [
        ("1;SC;WH1;C1.1.L", "unknown operation code", "SC"),
        ("x;EC;WH1;C1.1.L", "Order is not a whole number from 1", "x"),
        ("0;EC;WH1;C1.1.L", "Order is not a whole number from 1", "0"),
        ("1;EC;;C1.1.L", "EC without a label", None),
        ("1;RC;GR11;J4-J3", "malformed spot of RC", "J4-J3"),
    ],
)
def test_sequence_errors(write: Write, row: str, reason: str, found: str | None) -> None:
    path = write("s.csv", "Order;Type of operation;Label;Spot\n" + row + "\n")
    with pytest.raises(IngestError) as info:
        read_sequence(path)
    assert (info.value.line, info.value.reason, info.value.found) == (2, reason, found)


def test_sequence_sniffing() -> None:
    assert looks_like_sequence(b"Order;Type of operation;Label;Spot\r\n1;EC;WH1;C1.1.L\r\n")
    assert not looks_like_sequence(b"index,operation,components,spots,tool\n")
