"""The records of a wire harness description, shared by the KBL, VEC and harness text readers.

The readers return these frozen dataclasses, so one mapping (:mod:`cadkg.mapping.harness`)
turns any source into the same triples. Every record names its harness by ``harness`` (the
harness record's ``ident``); identifiers (``ident``) are unique within one harness and become
the last part of the thing's IRI: a KBL or VEC file's XML ids, a text description's names.
Labels are what people call the thing (a connector's designation, a wire number); they may
repeat. Lengths are metres (``Decimal`` where the ontology keeps decimals), diameters metres,
sections mm², positions metres in REP 103 axes (x forward, y left, z up).

``modules`` says in which variants of a modular (150 %) harness a thing is: in every variant
that chooses one of these modules (by module ident), or in every variant when empty. The
readers resolve their format's rules (a module's controlled parts, completion parts of module
lists, assemblies, the wires a connector holds, the routings a segment carries) into it, so
choosing a variant is one test per thing (see :func:`in_variant`).
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal

__all__ = [
    "Harness",
    "HarnessCable",
    "HarnessConfiguration",
    "HarnessConnector",
    "HarnessFixing",
    "HarnessModule",
    "HarnessNode",
    "HarnessPart",
    "HarnessProtection",
    "HarnessRecord",
    "HarnessSegment",
    "HarnessWire",
    "WireEnd",
    "WireRoute",
    "in_variant",
]

Position = tuple[float, float, float]
"""x, y, z in metres, REP 103 axes (x forward, y left, z up)."""


def in_variant(modules: tuple[str, ...], chosen: frozenset[str] | None) -> bool:
    """Whether a thing of ``modules`` is in the variant of the ``chosen`` modules (None: all)."""
    return chosen is None or not modules or not chosen.isdisjoint(modules)


@dataclass(frozen=True, slots=True)
class Harness:
    """The harness itself: ``ident`` is its part number (KBL) or declared name (text)."""

    ident: str
    description: str | None
    file_format: str
    line: int


@dataclass(frozen=True, slots=True)
class HarnessPart:
    """What every thing of a harness begins with: its harness (by ident), its ident in the
    harness, and its label."""

    harness: str
    ident: str
    label: str


@dataclass(frozen=True, slots=True)
class HarnessConnector(HarnessPart):
    """A connector occurrence (or a component box acting as one) and its cavity names, in order;
    ``label`` is its designation (``XA.G46.1``)."""

    kind: str
    cavities: tuple[str, ...]
    description: str | None
    line: int
    modules: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class HarnessNode(HarnessPart):
    """A point of the topology; ``connectors`` sit on it (by connector ident)."""

    connectors: tuple[str, ...]
    line: int
    position: Position | None = None
    modules: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class HarnessSegment(HarnessPart):
    """A stretch of bundle between two nodes (by node ident).

    ``length_source`` says where the length comes from when the format has several: ``physical``
    or ``virtual`` (KBL), ``curve`` (the length of the centre curve), ``chord`` (the straight
    line between the nodes); None where the format has one length only.
    """

    start: str
    end: str
    length_m: Decimal | None
    diameter_m: float | None
    section_mm2: Decimal | None
    line: int
    length_source: str | None = None
    modules: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class WireEnd:
    """Where a wire end is: a cavity of a connector."""

    connector: str
    cavity: str


@dataclass(frozen=True, slots=True)
class WireRoute:
    """One routing of a wire: the segments it runs through, in path order from the wire's first
    end (a segment twice where the path runs through it again), and the variants it is for."""

    ident: str
    segments: tuple[str, ...]
    modules: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class HarnessWire(HarnessPart):
    """A single wire or a core of a cable: its ends in wire order, and its routings (several
    only where variants route it differently)."""

    ends: tuple[WireEnd, ...]
    routes: tuple[WireRoute, ...]
    section_mm2: Decimal | None
    colour: str | None
    length_m: Decimal | None
    diameter_m: float | None
    cable: str | None
    signal: str | None
    line: int
    modules: tuple[str, ...] = ()

    @property
    def route(self) -> tuple[str, ...]:
        """The segments of the wire's first routing (its only one but in a 150 % harness)."""
        return self.routes[0].segments if self.routes else ()


@dataclass(frozen=True, slots=True)
class HarnessCable(HarnessPart):
    """A multi-core cable; its cores are :class:`HarnessWire` records naming it as ``cable``."""

    length_m: Decimal | None
    diameter_m: float | None
    line: int
    modules: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class HarnessFixing(HarnessPart):
    """A clip, tie or bracket, placed on nodes or segments (by ident)."""

    description: str | None
    nodes: tuple[str, ...]
    segments: tuple[str, ...]
    line: int
    modules: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class HarnessProtection(HarnessPart):
    """Tape, tube or sleeve along segments (by ident)."""

    description: str | None
    segments: tuple[str, ...]
    length_m: Decimal | None
    line: int
    modules: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class HarnessModule(HarnessPart):
    """What a variant of a modular harness is put together from: a KBL module (or a harness-level
    option code), a VEC variant configuration. ``label`` is the name users choose it by (a KBL
    module's part number); modules of one ``family`` exclude each other."""

    kind: str
    description: str | None
    control: str | None
    family: str | None
    family_label: str | None
    family_description: str | None
    line: int


@dataclass(frozen=True, slots=True)
class HarnessConfiguration(HarnessPart):
    """A named set of modules (a KBL harness configuration: a derivative such as a maximal kit)."""

    modules: tuple[str, ...]
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
    | HarnessModule
    | HarnessConfiguration
)
"""Any record a harness reader returns."""
