"""Reader of the wiring harness configuration (``WH_configuration.xml``).

``<data>`` holds ``<wiring_harness id first_connector tray>``; each has ``<end_connector
label>`` children (the end of a branch, which the assembly sequence names to route its cables)
holding ``<cable Row1 Col1 [Row2 Col2]>LABEL</cable>``: the cavity (row, column, from 0) of the
cable in the first connector and, when given, in the end connector. ``tray`` is ``BOX.TRAY``
(``B3.1``; a tray without a dot is tray 1 of that box).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from cadkg.usecases.elvez.files.xml_fields import XmlReader, element_names

__all__ = [
    "EndConnector",
    "HarnessCable",
    "WiringHarness",
    "looks_like_harness_configuration",
    "read_harness_configuration",
    "split_tray",
]

_EXPECTED = "<data> of <wiring_harness id first_connector tray> with <end_connector label> and <cable>"


@dataclass(frozen=True, slots=True)
class HarnessCable:
    label: str
    first_cavity: tuple[int, int]
    end_cavity: tuple[int, int] | None
    line: int


@dataclass(frozen=True, slots=True)
class EndConnector:
    label: str
    cables: tuple[HarnessCable, ...]
    line: int


@dataclass(frozen=True, slots=True)
class WiringHarness:
    """A harness: its id (``1``), first connector (``WH1``), tray, end connectors in file order."""

    id: str
    first_connector: str
    tray: str
    end_connectors: tuple[EndConnector, ...]
    line: int


def split_tray(tray: str) -> tuple[str, str]:
    """``B3.1`` → ``("B3", "1")``; ``B3`` → ``("B3", "1")``; ``""`` → ``("", "")``."""
    if not tray:
        return "", ""
    box, _, ident = tray.partition(".")
    return box, ident or "1"


def looks_like_harness_configuration(head: bytes) -> bool:
    """Whether a file starts with ``<data>`` holding a ``<wiring_harness>``."""
    return element_names(head) == ["data", "wiring_harness"]


def read_harness_configuration(path: str | Path) -> list[WiringHarness]:
    """Read the harnesses in file order.

    Raises
    ------
    IngestError
        On an unknown element or attribute, a harness id or end connector given twice, a
        cable given twice, a cable without a label, a row without its column (or the other way
        round) or one that is not a whole number; each at its line.
    """
    return _Reader(path).read()


class _Reader(XmlReader):
    def __init__(self, path: str | Path) -> None:
        super().__init__(path, _EXPECTED)
        self.cables: dict[str, int] = {}

    def read(self) -> list[WiringHarness]:
        harnesses: dict[str, WiringHarness] = {}
        for element in self.children(self.root("data"), ("wiring_harness",)):
            self.attributes(element, ("id", "first_connector"), ("tray",))
            ident = self.text(element, "id")
            if ident in harnesses:
                raise self.twice(f"harness {ident}", harnesses[ident].line, element, "each harness id once")
            ends: dict[str, EndConnector] = {}
            for end in self.children(element, ("end_connector",)):
                self.attributes(end, ("label",))
                label = self.text(end, "label")
                if label in ends:
                    first = ends[label].line
                    raise self.error(
                        f"end connector {label} given twice in harness {ident} (first on line {first})", end
                    )
                cables = tuple(self.cable(c) for c in self.children(end, ("cable",)))
                ends[label] = EndConnector(label, cables, int(end.sourceline or 0))
            harnesses[ident] = WiringHarness(
                ident,
                self.text(element, "first_connector"),
                self.text(element, "tray"),
                tuple(ends.values()),
                int(element.sourceline or 0),
            )
        return list(harnesses.values())

    def cable(self, element: etree._Element) -> HarnessCable:
        self.attributes(element, ("Row1", "Col1"), ("Row2", "Col2"))
        label = (element.text or "").strip()
        line = int(element.sourceline or 0)
        if not label:
            raise self.error(
                "<cable> without a label", element, expected="<cable Row1=... Col1=...>CA1</cable>"
            )
        if label in self.cables:
            raise self.twice(f"cable {label}", self.cables[label], element, "each cable in one harness, once")
        self.cables[label] = line
        end = None
        if element.get("Row2") is not None or element.get("Col2") is not None:
            self.attributes(element, ("Row1", "Col1", "Row2", "Col2"))
            end = (self.integer(element, "Row2"), self.integer(element, "Col2"))
        return HarnessCable(label, (self.integer(element, "Row1"), self.integer(element, "Col1")), end, line)
