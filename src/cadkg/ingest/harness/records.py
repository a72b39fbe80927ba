"""The records of a wire harness description, shared by the KBL and harness text readers.

Both readers return these frozen dataclasses, so one mapping
(:mod:`cadkg.mapping.harness`) turns either source into the same triples. Every
record names its harness by ``harness`` (the harness record's ``ident``); identifiers are
unique within one harness and become the last part of the thing's IRI. Lengths are metres
(``Decimal`` where the ontology keeps decimals), diameters metres, sections mm².
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal

__all__ = [
    "Harness",
    "HarnessCable",
    "HarnessConnector",
    "HarnessFixing",
    "HarnessNode",
    "HarnessProtection",
    "HarnessRecord",
    "HarnessSegment",
    "HarnessWire",
    "WireEnd",
]


@dataclass(frozen=True, slots=True)
class Harness:
    """The harness itself: ``ident`` is its part number (KBL) or declared name (text)."""

    ident: str
    description: str | None
    file_format: str
    line: int


@dataclass(frozen=True, slots=True)
class HarnessConnector:
    """A connector occurrence (or a component box acting as one) and its cavity names, in order."""

    harness: str
    ident: str
    kind: str
    cavities: tuple[str, ...]
    description: str | None
    line: int


@dataclass(frozen=True, slots=True)
class HarnessNode:
    """A point of the topology; ``connectors`` sit on it (by connector ident)."""

    harness: str
    ident: str
    label: str
    connectors: tuple[str, ...]
    line: int


@dataclass(frozen=True, slots=True)
class HarnessSegment:
    """A stretch of bundle between two nodes (by node ident)."""

    harness: str
    ident: str
    label: str
    start: str
    end: str
    length_m: Decimal | None
    diameter_m: float | None
    section_mm2: Decimal | None
    line: int


@dataclass(frozen=True, slots=True)
class WireEnd:
    """Where a wire end is: a cavity of a connector."""

    connector: str
    cavity: str


@dataclass(frozen=True, slots=True)
class HarnessWire:
    """A single wire or a core of a cable: its ends in wire order, and the segments it runs through."""

    harness: str
    ident: str
    label: str
    ends: tuple[WireEnd, ...]
    route: tuple[str, ...]
    section_mm2: Decimal | None
    colour: str | None
    length_m: Decimal | None
    diameter_m: float | None
    cable: str | None
    signal: str | None
    line: int


@dataclass(frozen=True, slots=True)
class HarnessCable:
    """A multi-core cable; its cores are :class:`HarnessWire` records naming it as ``cable``."""

    harness: str
    ident: str
    length_m: Decimal | None
    diameter_m: float | None
    line: int


@dataclass(frozen=True, slots=True)
class HarnessFixing:
    """A clip, tie or bracket, placed on nodes or segments (by ident)."""

    harness: str
    ident: str
    description: str | None
    nodes: tuple[str, ...]
    segments: tuple[str, ...]
    line: int


@dataclass(frozen=True, slots=True)
class HarnessProtection:
    """Tape, tube or sleeve along segments (by ident)."""

    harness: str
    ident: str
    description: str | None
    segments: tuple[str, ...]
    length_m: Decimal | None
    line: int


HarnessRecord = (
    Harness
    | HarnessConnector
    | HarnessNode
    | HarnessSegment
    | HarnessWire
    | HarnessCable
    | HarnessFixing
    | HarnessProtection
)
"""Any record a harness reader returns."""
