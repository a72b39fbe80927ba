"""Reader of the harness structure: each harness's main connector, branches, cables and pins.

Every cable of a harness runs from a cavity of the harness's main connector to a cavity of
its branch's connector (D3.1 section 4.3, Table 2 ``wh_info`` and ``cable_info``). A branch
may also hold capacitors. Names are those of the components file. See
docs/formats/elvez-harness-structure.md.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from cadkg.usecases.elvez.xml_fields import XmlReader, first_element_name

__all__ = [
    "ROOT",
    "BranchSpec",
    "CableSpec",
    "HarnessSpec",
    "looks_like_harness_structure",
    "read_harness_structure",
]

ROOT = "harness_structure"
_EXPECTED = '<harness_structure> holding <harness number="..." main_connector="..."> with <branch> elements'
# Names are joined with ';' in the action plan, so they hold neither ';' nor white space.
_NAME = re.compile(r"^[^\s;,]+$")


@dataclass(frozen=True, slots=True)
class CableSpec:
    """A cable of a branch and the cavities its two ends are inserted in."""

    name: str
    main_pin: int
    pin: int
    line: int


@dataclass(frozen=True, slots=True)
class BranchSpec:
    connector: str
    cables: tuple[CableSpec, ...]
    capacitors: tuple[str, ...]
    line: int


@dataclass(frozen=True, slots=True)
class HarnessSpec:
    """One harness: its number, main connector and branches in file order."""

    number: int
    main_connector: str
    branches: tuple[BranchSpec, ...]
    line: int


def looks_like_harness_structure(head: bytes) -> bool:
    """Whether the file's first element is ``<harness_structure>``."""
    return first_element_name(head) == ROOT


def read_harness_structure(path: str | Path) -> list[HarnessSpec]:
    """Read a harness structure file.

    Raises
    ------
    IngestError
        On an empty or binary file, malformed XML, a document type or entity declaration, a
        root other than ``<harness_structure>``, unknown elements or attributes, a malformed
        name or pin number, a harness without branches or a branch without cables, and a
        harness number, connector, cable or connector cavity used twice.
    """
    return _Reader(path).read()


class _Reader(XmlReader):
    def __init__(self, path: str | Path) -> None:
        super().__init__(path, _EXPECTED)
        self.names: dict[str, int] = {}
        self.cavities: dict[tuple[str, int], tuple[str, int]] = {}

    def read(self) -> list[HarnessSpec]:
        root = self.root(ROOT)
        self.attributes(root, ())
        harnesses: list[HarnessSpec] = []
        numbers: dict[int, int] = {}
        for element in self.children(root, ("harness",)):
            self.attributes(element, ("number", "main_connector"))
            number = self.integer(element, "number")
            if number in numbers:
                raise self.error(
                    f"harness {number} given twice (first on line {numbers[number]})",
                    element,
                    expected="each harness number once",
                )
            numbers[number] = int(element.sourceline or 0)
            main = self.name(element, "main_connector", connector=True)
            branches = [self.branch(b, main) for b in self.children(element, ("branch",))]
            if not branches:
                raise self.error(
                    f"harness {number} has no <branch>", element, expected="one or more <branch>"
                )
            harnesses.append(HarnessSpec(number, main, tuple(branches), numbers[number]))
        if not harnesses:
            raise self.error("no <harness> in <harness_structure>", root, expected=_EXPECTED)
        return harnesses

    def name(self, element: etree._Element, key: str, *, connector: bool = False) -> str:
        value = self.text(element, key)
        if not _NAME.match(value):
            raise self.error(
                f"malformed {key!r} of <{element.tag}>",
                element,
                found=value,
                expected="a component name without spaces, ',' or ';'",
            )
        if value in self.names:
            raise self.error(
                f"{'connector' if connector else 'name'} {value!r} is used twice "
                f"(first on line {self.names[value]})",
                element,
                found=value,
                expected="each connector, cable and capacitor in one place of the structure",
            )
        self.names[value] = int(element.sourceline or 0)
        return value

    def branch(self, element: etree._Element, main: str) -> BranchSpec:
        self.attributes(element, ("connector",))
        connector = self.name(element, "connector", connector=True)
        cables: list[CableSpec] = []
        capacitors: list[str] = []
        for child in self.children(element, ("cable", "capacitor")):
            if child.tag == "capacitor":
                self.attributes(child, ("name",))
                capacitors.append(self.name(child, "name"))
                continue
            self.attributes(child, ("name", "main_pin", "pin"))
            name = self.name(child, "name")
            cable = CableSpec(
                name, self.integer(child, "main_pin"), self.integer(child, "pin"), int(child.sourceline or 0)
            )
            for end_connector, pin in ((main, cable.main_pin), (connector, cable.pin)):
                taken = self.cavities.get((end_connector, pin))
                if taken is not None:
                    raise self.error(
                        f"cavity {pin} of connector {end_connector!r} already holds cable "
                        f"{taken[0]!r} (line {taken[1]})",
                        child,
                        found=pin,
                        expected="one cable end per connector cavity",
                    )
                self.cavities[(end_connector, pin)] = (name, cable.line)
            cables.append(cable)
        if not cables:
            raise self.error(
                f"branch of connector {connector!r} has no <cable>", element, expected="one or more <cable>"
            )
        return BranchSpec(connector, tuple(cables), tuple(capacitors), int(element.sourceline or 0))
