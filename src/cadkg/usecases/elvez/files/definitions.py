"""Reader of the element definitions (``Jigs_definition_v2.xml``): the jigs, combs, boxes and
ATC stations a platform's WRI table names by commercial code.

``<data>`` holds one definition per model (``model`` = the WRI's third column):

- ``<jig model xdim ydim zdim xcol1 xcol2 ycol1 ycol2 [xcenter ycenter xcolli ycolli]>`` with
  ``<guide couple>`` (a ``<key length gap height height_corner xcol1 xcol2 ycol1 ycol2>`` and a
  ``<collision xdim ydim zdim>``, each placed by six ``<pos>``/``<rot>`` children) and
  ``<tape_spot id guide xdim ydim zdim>`` (placed the same way);
- ``<comb ...>`` as a jig without centre and taping spots;
- ``<box model xdim ydim zdim>`` with ``<tray id xdim ydim zdim>``;
- ``<ATC_station model xdim ydim zdim tool>`` with ``<tool_base>``, ``<tool_end>``,
  ``<tool_dim x y z>`` and, for a gripper, ``<finger_dim finger_thickness finger_width
  finger_height>`` and ``<gripper_nail>``.

Lengths in mm (records in metres), angles in radians. ``finger_length`` is read as
``finger_thickness`` (one real file writes it so), with a warning.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from cadkg.errors import IngestError, IngestWarning
from cadkg.geometry.poses import Pose, Vec3
from cadkg.usecases.elvez.files.xml_fields import XmlReader, element_names

__all__ = [
    "AtcTool",
    "Collision",
    "ElementDefinition",
    "Guide",
    "Key",
    "PlacedBox",
    "looks_like_element_definitions",
    "read_element_definitions",
]

_EXPECTED = "<data> of element definitions: <jig>, <comb>, <box> and <ATC_station> with a model attribute"
_KINDS = ("jig", "comb", "box", "ATC_station")
_SIZE = ("xdim", "ydim", "zdim")
_EXTENTS = ("xcol1", "xcol2", "ycol1", "ycol2")
_CENTRE = ("xcenter", "ycenter", "xcolli", "ycolli")


@dataclass(frozen=True, slots=True)
class Key:
    """A guide's key (cable slot): its corner pose in the element frame and its sizes."""

    length: float
    gap: float
    height: float
    height_corner: float
    extents: tuple[float, float, float, float]
    corner: Pose
    line: int


@dataclass(frozen=True, slots=True)
class PlacedBox:
    """A box feature placed by its corner: a collision box, a taping spot, a tray."""

    id: str
    size: Vec3
    corner: Pose
    line: int
    guide: str = ""  # a taping spot's guide


Collision = PlacedBox


@dataclass(frozen=True, slots=True)
class Guide:
    couple: str
    key: Key
    collision: PlacedBox | None
    line: int


@dataclass(frozen=True, slots=True)
class AtcTool:
    """What an ATC station holds: the tool's kind, parked base, end, sizes and nail."""

    kind: str
    base: Pose
    end: Pose
    size: Vec3
    fingers: Vec3 | None
    nail: Pose | None


@dataclass(frozen=True, slots=True)
class ElementDefinition:
    """One definition: ``kind`` is jig, comb, box or ATC_station; lengths in metres."""

    kind: str
    model: str
    size: Vec3
    extents: tuple[float, float, float, float] | None
    centre: tuple[float, float] | None
    footprint: tuple[float, float] | None
    guides: tuple[Guide, ...]
    tape_spots: tuple[PlacedBox, ...]
    trays: tuple[PlacedBox, ...]
    tool: AtcTool | None
    line: int


def looks_like_element_definitions(head: bytes) -> bool:
    """Whether a file starts with ``<data>`` holding a jig, comb, box or ATC station."""
    names = element_names(head)
    return len(names) == 2 and names[0] == "data" and names[1] in _KINDS


def read_element_definitions(path: str | Path) -> list[ElementDefinition]:
    """Read the element definitions, in file order.

    Raises
    ------
    IngestError
        On an unknown element or attribute, a missing or malformed number, a model given twice,
        a guide couple, taping spot or tray id given twice in one definition, a guide without a
        key, a taping spot naming no guide of its jig; each at its line.
    """
    return _Reader(path).read()


def _three(values: tuple[float, ...]) -> Vec3:
    return (values[0], values[1], values[2])


def _four(values: tuple[float, ...]) -> tuple[float, float, float, float]:
    return (values[0], values[1], values[2], values[3])


class _Reader(XmlReader):
    def __init__(self, path: str | Path) -> None:
        super().__init__(path, _EXPECTED)

    def read(self) -> list[ElementDefinition]:
        root = self.root("data")
        found: dict[str, int] = {}
        definitions = []
        for element in self.children(root, _KINDS):
            model = self.text(element, "model")
            if model in found:
                raise self.twice(f"model {model}", found[model], element, "each model once", verb="defined")
            definition = self.definition(element)
            found[model] = definition.line
            definitions.append(definition)
        return definitions

    def definition(self, element: etree._Element) -> ElementDefinition:
        kind = str(element.tag)
        optional: tuple[str, ...] = {
            "jig": _CENTRE,
            "ATC_station": ("tool",),
        }.get(kind, ())
        required = ("model", *_SIZE, *(_EXTENTS if kind in ("jig", "comb") else ()))
        self.attributes(element, required, optional)
        children = {
            "jig": ("guide", "tape_spot"),
            "comb": ("guide",),
            "box": ("tray",),
            "ATC_station": ("tool_base", "tool_end", "tool_dim", "finger_dim", "gripper_nail"),
        }[kind]
        parts = self.children(element, children)
        guides = self.guides([p for p in parts if p.tag == "guide"])
        couples = {g.couple for g in guides}
        tape_spots = self.boxes([p for p in parts if p.tag == "tape_spot"], "id", ("guide",))
        for spot in tape_spots:
            if spot.guide not in couples:
                raise IngestError(
                    self.path,
                    f"taping spot {spot.id} names guide {spot.guide!r}, which model "
                    f"{self.text(element, 'model')} does not define",
                    line=spot.line,
                    expected=f"one of its guide couples: {', '.join(sorted(couples)) or 'none'}",
                )
        centre = footprint = None
        if kind == "jig":
            given = [key for key in _CENTRE if element.get(key) is not None]
            if given:
                self.attributes(element, (*required, *_CENTRE))
                cx, cy, fx, fy = self.lengths(element, _CENTRE)
                centre, footprint = (cx, cy), (fx, fy)
        return ElementDefinition(
            kind=kind,
            model=self.text(element, "model"),
            size=_three(self.lengths(element, _SIZE, minimum=0.0)),
            extents=_four(self.lengths(element, _EXTENTS)) if kind in ("jig", "comb") else None,
            centre=centre,
            footprint=footprint,
            guides=guides,
            tape_spots=tape_spots,
            trays=self.boxes([p for p in parts if p.tag == "tray"], "id"),
            tool=self.tool(element) if kind == "ATC_station" else None,
            line=int(element.sourceline or 0),
        )

    def guides(self, elements: list[etree._Element]) -> tuple[Guide, ...]:
        guides: dict[str, Guide] = {}
        for element in elements:
            self.attributes(element, ("couple",))
            couple = self.text(element, "couple")
            if couple in guides:
                raise self.twice(
                    f"guide couple {couple}", guides[couple].line, element, "each couple once per definition"
                )
            self.children(element, ("key", "collision"))
            key = self.one(element, "key", required=True)
            assert key is not None
            self.attributes(key, ("length", "gap", "height", "height_corner", *_EXTENTS))
            length, gap, height, corner_height = self.lengths(
                key, ("length", "gap", "height", "height_corner"), minimum=0.0
            )
            collision = self.one(element, "collision", required=False)
            guides[couple] = Guide(
                couple=couple,
                key=Key(
                    length,
                    gap,
                    height,
                    corner_height,
                    _four(self.lengths(key, _EXTENTS)),
                    self.pose(key),
                    int(key.sourceline or 0),
                ),
                collision=self.box(collision, "") if collision is not None else None,
                line=int(element.sourceline or 0),
            )
        return tuple(guides.values())

    def box(self, element: etree._Element, ident: str, extra: tuple[str, ...] = ()) -> PlacedBox:
        self.attributes(element, (*(("id",) if ident else ()), *_SIZE, *extra))
        return PlacedBox(
            id=self.text(element, "id") if ident else "",
            size=_three(self.lengths(element, _SIZE, minimum=0.0)),
            corner=self.pose(element),
            line=int(element.sourceline or 0),
            guide=self.text(element, "guide") if "guide" in extra else "",
        )

    def boxes(
        self, elements: list[etree._Element], ident: str, extra: tuple[str, ...] = ()
    ) -> tuple[PlacedBox, ...]:
        found: dict[str, PlacedBox] = {}
        for element in elements:
            box = self.box(element, ident, extra)
            if box.id in found:
                raise self.twice(
                    f"<{element.tag}> id {box.id}", found[box.id].line, element, "each id once per definition"
                )
            found[box.id] = box
        return tuple(found.values())

    def tool(self, element: etree._Element) -> AtcTool:
        base, end = (self.one(element, name, required=True) for name in ("tool_base", "tool_end"))
        size = self.one(element, "tool_dim", required=True)
        assert base is not None and end is not None and size is not None
        self.attributes(size, ("x", "y", "z"))
        fingers = self.one(element, "finger_dim", required=False)
        nail = self.one(element, "gripper_nail", required=False)
        return AtcTool(
            kind=self.text(element, "tool"),
            base=self.pose(base),
            end=self.pose(end),
            size=_three(self.lengths(size, ("x", "y", "z"), minimum=0.0)),
            fingers=self.fingers(fingers) if fingers is not None else None,
            nail=self.pose(nail) if nail is not None else None,
        )

    def fingers(self, element: etree._Element) -> Vec3:
        thickness = "finger_thickness"
        if element.get(thickness) is None and element.get("finger_length") is not None:
            thickness = "finger_length"
            warnings.warn(
                IngestWarning(
                    self.path,
                    "finger_length of <finger_dim> read as finger_thickness",
                    line=int(element.sourceline or 0),
                ),
                stacklevel=2,
            )
        self.attributes(element, (thickness, "finger_width", "finger_height"))
        return _three(self.lengths(element, (thickness, "finger_width", "finger_height"), minimum=0.0))
