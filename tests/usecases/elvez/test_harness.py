"""The harness structure and harness components readers: the example's harnesses, located errors."""

from __future__ import annotations

from collections.abc import Callable
from decimal import Decimal
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.usecases.elvez.harness_components import HarnessComponent, read_harness_components
from cadkg.usecases.elvez.harness_structure import CableSpec, read_harness_structure
from tests.conftest import ROOT

EXAMPLE = ROOT / "examples" / "elvez-cell"

Write = Callable[[str, str | bytes], Path]


def test_structure_of_the_three_harnesses() -> None:
    harnesses = read_harness_structure(EXAMPLE / "harness-structure.xml")
    assert [(h.number, h.main_connector, sum(len(b.cables) for b in h.branches)) for h in harnesses] == [
        (1, "C10", 6),
        (2, "C20", 10),
        (3, "C30", 11),
    ]
    assert [b.connector for b in harnesses[2].branches] == ["C31", "C32", "C33"]
    last = harnesses[2].branches[2]
    assert last.capacitors == ("K33",)
    assert last.cables[-1] == CableSpec("W311", main_pin=12, pin=3, line=51)


def test_components_in_metres() -> None:
    components = {c.name: c for c in read_harness_components(EXAMPLE / "harness-components.csv")}
    assert len(components) == 39
    kinds = [c.kind for c in components.values()]
    assert (kinds.count("cable"), kinds.count("connector"), kinds.count("capacitor")) == (27, 11, 1)
    assert components["W101"] == HarnessComponent(
        name="W101",
        kind="cable",
        rgb=(255, 0, 0),
        diameter_m=Decimal("0.0016"),
        length_m=Decimal("0.420"),
        dimensions_m=None,
        description=None,
        line=5,
    )
    c10 = components["C10"]
    assert c10.dimensions_m == (Decimal("0.040"), Decimal("0.025"), Decimal("0.018"))
    assert (c10.rgb, c10.description) == ((30, 30, 30), "WH1 main connector (6 ways)")
    assert components["K33"].rgb is None


def test_components_with_semicolons_and_decimal_commas(write: Write) -> None:
    path = write(
        "c.csv",
        "name;type;red;green;blue;diameter_mm;length_mm;x_mm;y_mm;z_mm\nW1;cable;1;2;3;1,5;300;;;\n",
    )
    (cable,) = read_harness_components(path)
    assert (cable.rgb, cable.diameter_m, cable.length_m) == ((1, 2, 3), Decimal("0.0015"), Decimal("0.300"))


HARNESS_HEAD = '<harness_structure>\n<harness number="1" main_connector="C1">\n'


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("<harness_structure/>", r"s\.xml:1: no <harness> in <harness_structure>"),
        (HARNESS_HEAD + "</harness>\n</harness_structure>", r"s\.xml:2: harness 1 has no <branch>"),
        (
            HARNESS_HEAD + '<branch connector="C2">\n</branch>\n</harness>\n</harness_structure>',
            r"s\.xml:3: branch of connector 'C2' has no <cable>",
        ),
        (
            HARNESS_HEAD + '<branch connector="C2">\n<cable name="W1" main_pin="1" pin="x"/>\n</branch>\n'
            "</harness>\n</harness_structure>",
            r"s\.xml:4: 'pin' of <cable> is not a whole number of at least 1 \(found 'x'",
        ),
        (
            HARNESS_HEAD + '<branch connector="C2">\n<cable name="W1" main_pin="1" pin="1"/>\n'
            '<cable name="W2" main_pin="1" pin="2"/>\n</branch>\n</harness>\n</harness_structure>',
            r"s\.xml:5: cavity 1 of connector 'C1' already holds cable 'W1' \(line 4\)",
        ),
        (
            HARNESS_HEAD + '<branch connector="C2">\n<cable name="W1" main_pin="1" pin="1"/>\n'
            '<cable name="W1" main_pin="2" pin="2"/>\n</branch>\n</harness>\n</harness_structure>',
            r"s\.xml:5: name 'W1' is used twice \(first on line 4\)",
        ),
        (
            HARNESS_HEAD + '<branch connector="C1">\n<cable name="W1" main_pin="1" pin="2"/>\n</branch>\n'
            "</harness>\n</harness_structure>",
            r"s\.xml:3: connector 'C1' is used twice \(first on line 2\)",
        ),
        (
            HARNESS_HEAD + '<branch connector="C 2">\n</branch>\n</harness>\n</harness_structure>',
            r"s\.xml:3: malformed 'connector' of <branch> \(found 'C 2'",
        ),
        (
            '<harness_structure>\n<harness number="0" main_connector="C1">\n</harness>\n</harness_structure>',
            r"s\.xml:2: 'number' of <harness> is not a whole number of at least 1",
        ),
        (
            HARNESS_HEAD
            + '<branch connector="C2">\n<wire name="W1"/>\n</branch>\n</harness>\n</harness_structure>',
            r"s\.xml:4: unexpected element <wire> inside <branch>",
        ),
    ],
)
def test_structure_errors(write: Write, text: str, message: str) -> None:
    with pytest.raises(IngestError, match=message):
        read_harness_structure(write("s.xml", text))


HEADER = "name,type,red,green,blue,diameter_mm,length_mm,x_mm,y_mm,z_mm\n"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (HEADER, r"c\.csv:1: no component rows after the header"),
        (
            "name,type,red,green,blue,diameter_mm,length_mm\nW1,cable,1,2,3,1,2\n",
            r"c\.csv:1: missing column 'x_mm'",
        ),
        (
            HEADER.replace("\n", ",weight\n") + "W1,cable,1,2,3,1,2,,,,3\n",
            r"c\.csv:1: unknown column \(found 'weight'",
        ),
        (HEADER + "W1,wire,1,2,3,1,2,,,\n", r"c\.csv:2: unknown type of 'W1' \(found 'wire', expected cable"),
        (
            HEADER + "W1,cable,1,2,300,1,2,,,\n",
            r"c\.csv:2: colour of 'W1' is not three whole numbers 0 to 255",
        ),
        (HEADER + "W1,cable,,,,1,2,,,\n", r"c\.csv:2: cable 'W1' has no colour"),
        (HEADER + "W1,cable,1,2,3,,2,,,\n", r"c\.csv:2: cable 'W1' needs diameter_mm and length_mm"),
        (HEADER + "W1,cable,1,2,3,1,2,1,1,1\n", r"c\.csv:2: cable 'W1' has x_mm, y_mm or z_mm"),
        (HEADER + "C1,connector,1,2,3,,,1,1,\n", r"c\.csv:2: connector 'C1' needs x_mm, y_mm and z_mm"),
        (
            HEADER + "W1,cable,1,2,3,-1,2,,,\n",
            r"c\.csv:2: diameter_mm of 'W1' is not a length in millimetres",
        ),
        (HEADER + "W1,cable,1,2,3,1,2 m,,,\n", r"c\.csv:2: length_mm of 'W1' is not a length in millimetres"),
        (
            HEADER + "W1,cable,1,2,3,1,2,,,\n\nW1,cable,1,2,3,1,2,,,\n",
            r"c\.csv:4: component 'W1' given twice \(first on line 2\)",
        ),
        (HEADER + "W 1,cable,1,2,3,1,2,,,\n", r"c\.csv:2: malformed name \(found 'W 1'"),
    ],
)
def test_component_errors(write: Write, text: str, message: str) -> None:
    with pytest.raises(IngestError, match=message):
        read_harness_components(write("c.csv", text))
