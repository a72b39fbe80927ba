"""The tools reader: the example's three tools in metres and radians, and located errors."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path

import pytest

from cadkg.errors import IngestError
from cadkg.usecases.elvez.tools import read_tools
from cadkg.usecases.elvez.xml_fields import Placement
from tests.conftest import ROOT

TOOLS = ROOT / "examples" / "elvez-cell" / "tools.xml"

Write = Callable[[str, str | bytes], Path]


def test_example_tools() -> None:
    tools = read_tools(TOOLS)
    assert [(t.name, t.kind, t.atc_slot) for t in tools] == [
        ("gripper_left", "gripper", "ATC1"),
        ("gripper_right", "gripper", "ATC2"),
        ("taping_gun", "taping_gun", "ATC3"),
    ]
    gun = tools[2]
    assert gun.line == 16
    assert gun.dimensions == pytest.approx((0.12, 0.08, 0.2))
    assert gun.base_to_wrist.xyz == pytest.approx((0.0, 0.0, 0.2))
    assert gun.base_to_wrist.rpy == pytest.approx((math.pi, 0.0, 0.0))
    assert gun.wrist_to_action.xyz == pytest.approx((0.04, 0.0, 0.16))
    assert gun.wrist_to_action.rpy == pytest.approx((0.0, -math.pi / 2, 0.0))
    assert gun.wrist_to_action.line == 19


def test_metres_and_radians(write: Write) -> None:
    path = write(
        "t.xml",
        '<tools length_unit="m" angle_unit="rad">\n<tool name="g" type="gripper" atc_slot="S1">\n'
        '<dimensions x="0.1" y="0.1" z="0.1"/>\n'
        '<base_to_wrist x="0" y="0" z="0.1" roll="3" pitch="0" yaw="0"/>\n'
        '<wrist_to_action x="0" y="0" z="0.2" roll="0" pitch="0" yaw="0"/>\n</tool>\n</tools>',
    )
    (tool,) = read_tools(path)
    assert tool.base_to_wrist == Placement((0.0, 0.0, 0.1), (3.0, 0.0, 0.0), 4)


TOOL = (
    '<tool name="{name}" type="gripper" atc_slot="{slot}">\n<dimensions x="1" y="1" z="1"/>\n'
    '<base_to_wrist x="0" y="0" z="1" roll="0" pitch="0" yaw="0"/>\n'
    '<wrist_to_action x="0" y="0" z="1" roll="0" pitch="0" yaw="0"/>\n</tool>\n'
)
HEAD = '<tools length_unit="mm" angle_unit="deg">\n'


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (HEAD + "</tools>", r"t\.xml:1: no <tool> in <tools>"),
        (
            '<tools length_unit="inch" angle_unit="deg">\n</tools>',
            r"t\.xml:1: unknown or missing length_unit",
        ),
        (
            HEAD + TOOL.format(name="g", slot="A1") + TOOL.format(name="g", slot="A2") + "</tools>",
            r"t\.xml:7: tool 'g' given twice \(first on line 2\)",
        ),
        (
            HEAD + TOOL.format(name="g1", slot="A1") + TOOL.format(name="g2", slot="A1") + "</tools>",
            r"t\.xml:7: ATC slot 'A1' already holds tool 'g1'",
        ),
        (HEAD + TOOL.format(name="2 fingers", slot="A1") + "</tools>", r"t\.xml:2: malformed tool name"),
        (
            HEAD + '<tool name="g" type="gripper">\n</tool>\n</tools>',
            r"t\.xml:2: <tool> without a 'atc_slot' attribute",
        ),
        (
            HEAD + '<tool name="g" type="gripper" atc_slot="A1">\n<dimensions x="1" y="1" z="1"/>\n'
            '<base_to_wrist x="0" y="0" z="1" roll="0" pitch="0" yaw="0"/>\n</tool>\n</tools>',
            r"t\.xml:2: <tool> has no <wrist_to_action>",
        ),
        (
            HEAD + TOOL.format(name="g", slot="A1").replace('z="1" roll', 'z="one" roll', 1) + "</tools>",
            r"t\.xml:4: 'z' of <base_to_wrist> is not a number \(found 'one'",
        ),
        (
            HEAD + TOOL.format(name="g", slot="A1").replace("</tool>", "<gripper/>\n</tool>") + "</tools>",
            r"t\.xml:6: unexpected element <gripper> inside <tool>",
        ),
        ("<tool_set/>", r"t\.xml:1: the root element is not <tools>"),
    ],
)
def test_located_errors(write: Write, text: str, message: str) -> None:
    with pytest.raises(IngestError, match=message):
        read_tools(write("t.xml", text))
