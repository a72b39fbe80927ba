"""Reader of the robot's tools: ATC slot, tool frames and size of each gripper or taping gun.

Each ``<tool>`` names the ATC slot it is parked in, the pose of its tool-changer (wrist)
frame in its base frame, the pose of its action frame (finger pads, taping nozzle) in the
wrist frame, and its dimensions (D3.1 section 4.3, Table 2 ``tool_info``). See
docs/formats/elvez-tools.md.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from cadkg.usecases.elvez.xml_fields import Placement, Units, XmlReader, first_element_name

__all__ = ["ROOT", "ToolSpec", "looks_like_tools", "read_tools"]

ROOT = "tools"
_EXPECTED = '<tools length_unit="mm" angle_unit="deg"> holding <tool name="..." type="..." atc_slot="...">'
# Tool names prefix the tool's frame ids (gripper_left_wrist), so they follow ROS frame ids.
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


@dataclass(frozen=True, slots=True)
class ToolSpec:
    """One tool: sizes in metres, placements in metres and radians."""

    name: str
    kind: str
    atc_slot: str
    dimensions: tuple[float, float, float]
    base_to_wrist: Placement
    wrist_to_action: Placement
    line: int


def looks_like_tools(head: bytes) -> bool:
    """Whether the file's first element is ``<tools>``."""
    return first_element_name(head) == ROOT


def read_tools(path: str | Path) -> list[ToolSpec]:
    """Read the tool list.

    Raises
    ------
    IngestError
        On an empty or binary file, malformed XML, a document type or entity declaration, a
        root other than ``<tools>``, unknown units, elements or attributes, a missing or
        malformed number or name, a tool given twice or two tools parked in one slot.
    """
    reader = XmlReader(path, _EXPECTED)
    root = reader.root(ROOT)
    reader.attributes(root, ("length_unit", "angle_unit"))
    units = reader.units(root)
    tools: list[ToolSpec] = []
    names: dict[str, int] = {}
    slots: dict[str, str] = {}
    for element in reader.children(root, ("tool",)):
        tool = _tool(reader, element, units)
        if tool.name in names:
            raise reader.error(
                f"tool {tool.name!r} given twice (first on line {names[tool.name]})",
                element,
                expected="each tool name once",
            )
        if tool.atc_slot in slots:
            raise reader.error(
                f"ATC slot {tool.atc_slot!r} already holds tool {slots[tool.atc_slot]!r}",
                element,
                found=tool.atc_slot,
                expected="one tool per ATC slot",
            )
        names[tool.name] = tool.line
        slots[tool.atc_slot] = tool.name
        tools.append(tool)
    if not tools:
        raise reader.error("no <tool> in <tools>", root, expected=_EXPECTED)
    return tools


def _tool(reader: XmlReader, element: etree._Element, units: Units) -> ToolSpec:
    reader.attributes(element, ("name", "type", "atc_slot"))
    name = reader.text(element, "name")
    if not _NAME.match(name):
        raise reader.error(
            "malformed tool name",
            element,
            found=name,
            expected="letters, digits and _, starting with a letter (it names the tool's frames)",
        )
    reader.children(element, ("dimensions", "base_to_wrist", "wrist_to_action"))
    parts = {}
    for part in ("dimensions", "base_to_wrist", "wrist_to_action"):
        found = reader.one(element, part, required=True)
        assert found is not None
        parts[part] = found
    return ToolSpec(
        name=name,
        kind=reader.text(element, "type"),
        atc_slot=reader.text(element, "atc_slot"),
        dimensions=reader.size(parts["dimensions"], units),
        base_to_wrist=reader.placement(parts["base_to_wrist"], units),
        wrist_to_action=reader.placement(parts["wrist_to_action"], units),
        line=int(element.sourceline or 0),
    )
