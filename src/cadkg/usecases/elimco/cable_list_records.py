"""The records of an ELIMCO cable list: the harness, its wires end to end, shield terminations."""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal

__all__ = ["CableListEnd", "CableListHarness", "CableListRecord", "CableListWire", "ShieldTermination"]


@dataclass(frozen=True, slots=True)
class CableListEnd:
    """One end of a wire: connector (``ZONA``), contact (``BORNIA``) and contact part (``CNX``)."""

    connector: str
    contact: str | None
    contact_part: str | None


@dataclass(frozen=True, slots=True)
class CableListHarness:
    """The harness the list describes (``PN``, ``REV``, ``IND`` of its first row)."""

    part_number: str
    revision: str | None
    index: str | None
    line: int
    location: str


@dataclass(frozen=True, slots=True)
class CableListWire:
    """A conductor between two contacts, merged from its one or two rows.

    ``rows`` are the spreadsheet rows (or CSV lines) that list it, the one giving its
    direction first; ``length_m`` is ``LONGITUD`` converted from millimetres.
    """

    harness: str
    name: str
    cable: str
    wire_type: str | None
    length_m: Decimal | None
    origin: CableListEnd
    destination: CableListEnd
    symbol: str | None
    order: str | None
    gauge: str | None
    construction: str | None
    route: str | None
    remark: str | None
    check: str | None
    rows: tuple[int, ...]
    location: str


@dataclass(frozen=True, slots=True)
class ShieldTermination:
    """Where the screen of a cable is terminated: one contact of one connector.

    ``cable`` is the part of the shield group (``SH``, e.g. ``A4351-1669/1``) before the
    slash, or the row's ``CABLE`` when no row names a shield group. ``length_m`` is the
    row's ``LONGITUD`` as read (the cable's or the drain wire's length).
    """

    harness: str
    name: str
    shield: str | None
    cable: str
    connector: str
    contact: str
    wire_type: str | None
    length_m: Decimal | None
    rows: tuple[int, ...]
    location: str


CableListRecord = CableListHarness | CableListWire | ShieldTermination
"""Any record :func:`read_elimco_cable_list` returns."""
