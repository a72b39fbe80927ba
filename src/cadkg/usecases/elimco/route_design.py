"""Readers of the route-design application's files: pin_info.xml, cable_info.xml, path_info.xml.

ELIMCO's route-design application (D3.1, Figures 14-20) saves the pins placed on the
2D drawing, the cables to route and the routes drawn between the pins as three XML
files. The reference shows their content but not their syntax, so the schema is ours
(docs/formats/route-design.md): one element per pin, cable or path, its values as
attributes, lengths and positions in the unit of the root's ``units`` attribute
(``mm``, the drawing's unit, by default; or ``m``). Records carry metres.

The input is untrusted: no DTD, no entities, no network; unknown elements and
attributes are errors, because a misspelt attribute would otherwise be dropped silently.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from pathlib import Path

from lxml import etree

from cadkg.errors import IngestError
from cadkg.ingest.text import read_text, small_integer
from cadkg.ingest.xml_input import attributes_of, element_children, parse_untrusted_xml

__all__ = [
    "ROLES",
    "BenchPinSpec",
    "RouteCable",
    "RoutePathSpec",
    "looks_like_cable_info",
    "looks_like_path_info",
    "looks_like_pin_info",
    "read_cable_info",
    "read_path_info",
    "read_pin_info",
]

ROLES = ("initial", "intermediate", "final")
_UNITS = {"mm": Decimal("0.001"), "m": Decimal(1)}
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
_PROLOG = re.compile(rb"^(?:\s+|<\?.*?\?>|<!--.*?-->)*", re.DOTALL)
_ROOT = re.compile(rb"<([A-Za-z_][\w.-]*)")
# Segment lengths are rounded one by one in the application: their sum may differ
# from the total by this much (metres) without either being wrong.
_SUM_TOLERANCE_M = Decimal("0.001")


@dataclass(frozen=True, slots=True)
class BenchPinSpec:
    """A pin placed on the workbench (pin_info.xml), at ``x``/``y`` in the drawing frame.

    ``x_m``/``y_m`` are the position in metres; ``x``/``y`` as written, in ``units``. A
    double pin is two pins ``double_distance_m`` apart between which the wires pass;
    ``connector_distance_m`` is how far from its connector an initial or final pin stands.
    """

    name: str
    role: str
    x: float
    y: float
    units: str
    x_m: float
    y_m: float
    double: bool
    double_distance_m: float | None
    connector_distance_m: float | None
    line: int


@dataclass(frozen=True, slots=True)
class RouteCable:
    """A cable to route (cable_info.xml): from its initial to its final connector."""

    name: str
    initial: str
    final: str
    length_m: Decimal | None
    line: int


@dataclass(frozen=True, slots=True)
class RoutePathSpec:
    """The route of one cable (path_info.xml): initial pin, intermediate pins in order, final pin.

    ``segment_lengths_m`` are the lengths between consecutive pins (empty while the route
    is not drawn); ``total_length_m`` is their sum when they are given.
    """

    index: int
    cable: str
    initial: str
    final: str
    intermediates: tuple[str, ...]
    segment_lengths_m: tuple[Decimal, ...]
    total_length_m: Decimal | None
    cable_length_m: Decimal | None
    line: int

    @property
    def pins(self) -> tuple[str, ...]:
        """Every pin of the route, in order."""
        return (self.initial, *self.intermediates, self.final)


def read_pin_info(path: str | Path) -> list[BenchPinSpec]:
    """Read pin_info.xml: ``<pin_info units="mm"><pin name= role= x= y= .../></pin_info>``.

    Raises
    ------
    IngestError
        On an empty or binary file, a DOCTYPE or entity declaration, malformed XML, an
        unknown element, attribute, role, pin type or unit, a missing or malformed
        number, a double pin without its distance (or a simple one with it), a
        connector distance on an intermediate pin, a pin given twice, or no pin;
        located at file:line.
    """
    doc = _Document(path, "pin_info", "pin")
    pins: list[BenchPinSpec] = []
    seen: dict[str, int] = {}
    for element in doc.items():
        attrs = doc.attributes(
            element, ("name", "role", "x", "y"), ("type", "double_distance", "connector_distance")
        )
        line = doc.line(element)
        name = attrs["name"]
        if name in seen:
            raise doc.error(f"pin {name!r} given twice (first on line {seen[name]})", line)
        seen[name] = line
        role = doc.choice(attrs["role"], ROLES, "role", name, line)
        kind = doc.choice(attrs.get("type", "simple"), ("simple", "double"), "type", name, line)
        x = doc.number(attrs["x"], "x", name, line)
        y = doc.number(attrs["y"], "y", name, line)
        if kind == "double" and "double_distance" not in attrs:
            raise doc.error(
                f"double pin {name!r} without double_distance",
                line,
                expected="the distance between its two pins",
            )
        if kind == "simple" and "double_distance" in attrs:
            raise doc.error(
                f"double_distance on simple pin {name!r}",
                line,
                found=attrs["double_distance"],
                expected='type="double", or no double_distance',
            )
        double_distance = doc.optional_length(attrs, "double_distance", name, line, positive=True)
        if role == "intermediate" and "connector_distance" in attrs:
            raise doc.error(
                f"connector_distance on intermediate pin {name!r}",
                line,
                expected="it only on initial and final pins, which stand at a connector",
            )
        connector = doc.optional_length(attrs, "connector_distance", name, line)
        pins.append(
            BenchPinSpec(
                name=name,
                role=role,
                x=x,
                y=y,
                units=doc.units,
                # Through Decimal, so 2002 mm is 2.002 m and not 2.0020000000000002.
                x_m=float(Decimal(attrs["x"]) * doc.scale),
                y_m=float(Decimal(attrs["y"]) * doc.scale),
                double=kind == "double",
                double_distance_m=None if double_distance is None else float(double_distance),
                connector_distance_m=None if connector is None else float(connector),
                line=line,
            )
        )
    return pins


def read_cable_info(path: str | Path) -> list[RouteCable]:
    """Read cable_info.xml: ``<cable_info units="mm"><cable name= initial= final= length=/></cable_info>``.

    Raises
    ------
    IngestError
        On an empty or binary file, a DOCTYPE or entity declaration, malformed XML, an
        unknown element or attribute, a malformed length, a cable whose two connectors
        are one, a cable given twice, or no cable; located at file:line.
    """
    doc = _Document(path, "cable_info", "cable")
    cables: list[RouteCable] = []
    seen: dict[str, int] = {}
    for element in doc.items():
        attrs = doc.attributes(element, ("name", "initial", "final"), ("length",))
        line = doc.line(element)
        name = attrs["name"]
        if name in seen:
            raise doc.error(f"cable {name!r} given twice (first on line {seen[name]})", line)
        seen[name] = line
        if attrs["initial"] == attrs["final"]:
            raise doc.error(
                f"cable {name!r} starts and ends at one connector",
                line,
                found=attrs["initial"],
                expected="two different connectors",
            )
        length = doc.optional_length(attrs, "length", name, line, positive=True)
        cables.append(RouteCable(name, attrs["initial"], attrs["final"], length, line))
    return cables


def read_path_info(path: str | Path) -> list[RoutePathSpec]:
    """Read path_info.xml: ``<path index= cable= initial= final= ...>`` with ``<intermediate pin=/>``
    and ``<segment from= to= length=/>`` children.

    Raises
    ------
    IngestError
        On an empty or binary file, a DOCTYPE or entity declaration, malformed XML, an
        unknown element or attribute, a malformed index or length, an index or cable
        given twice, a pin visited twice, segments that do not run from pin to pin
        along the route, or segment lengths whose sum is not the total length; located
        at file:line.
    """
    doc = _Document(path, "path_info", "path")
    paths: list[RoutePathSpec] = []
    indices: dict[int, int] = {}
    cables: dict[str, int] = {}
    for element in doc.items():
        attrs = doc.attributes(
            element, ("index", "cable", "initial", "final"), ("total_length", "cable_length")
        )
        line = doc.line(element)
        raw_index = attrs["index"]
        index = small_integer(raw_index)
        if index is None:
            raise doc.error("not a path index", line, found=raw_index, expected="a whole number from 0")
        if index in indices:
            raise doc.error(f"path {index} given twice (first on line {indices[index]})", line)
        indices[index] = line
        cable = attrs["cable"]
        if cable in cables:
            raise doc.error(
                f"cable {cable!r} has a second path (first on line {cables[cable]})",
                line,
                expected="one path per cable",
            )
        cables[cable] = line
        intermediates: list[str] = []
        segments: list[tuple[etree._Element, dict[str, str]]] = []
        for child in doc.children(element, ("intermediate", "segment")):
            if child.tag == "intermediate":
                if segments:
                    raise doc.error(
                        "<intermediate> after a <segment>",
                        doc.line(child),
                        expected="the intermediate pins first, then the segments",
                    )
                intermediates.append(doc.attributes(child, ("pin",), ())["pin"])
            else:
                segments.append((child, doc.attributes(child, ("from", "to", "length"), ())))
        pins = (attrs["initial"], *intermediates, attrs["final"])
        for position, pin in enumerate(pins):
            if pin in pins[:position]:
                raise doc.error(
                    f"path {index} visits pin {pin!r} twice", line, expected="each pin once along a route"
                )
        lengths = _check_segments(doc, index, pins, segments)
        total = doc.optional_length(attrs, "total_length", f"path {index}", line, positive=True)
        if lengths:
            added = sum(lengths, Decimal(0))
            if total is not None and abs(added - total) > _SUM_TOLERANCE_M:
                raise doc.error(
                    f"the segment lengths of path {index} add up to {_text(added / doc.scale)}, "
                    "not its total_length",
                    line,
                    found=attrs["total_length"],
                    expected=f"{_text(added / doc.scale)} (the sum of the segment lengths)",
                )
            total = total if total is not None else added
        cable_length = doc.optional_length(attrs, "cable_length", f"path {index}", line, positive=True)
        paths.append(
            RoutePathSpec(
                index=index,
                cable=cable,
                initial=attrs["initial"],
                final=attrs["final"],
                intermediates=tuple(intermediates),
                segment_lengths_m=tuple(lengths),
                total_length_m=total,
                cable_length_m=cable_length,
                line=line,
            )
        )
    return paths


def _check_segments(
    doc: _Document, index: int, pins: tuple[str, ...], segments: list[tuple[etree._Element, dict[str, str]]]
) -> list[Decimal]:
    if not segments:
        return []
    if len(segments) != len(pins) - 1:
        raise doc.error(
            f"path {index} has {len(segments)} segment(s) for {len(pins)} pins",
            doc.line(segments[0][0]),
            expected=f"{len(pins) - 1}: one segment between each two consecutive pins",
        )
    lengths = []
    for (element, attrs), start, end in zip(segments, pins, pins[1:], strict=False):
        if (attrs["from"], attrs["to"]) != (start, end):
            raise doc.error(
                f"segment of path {index} out of route order",
                doc.line(element),
                found=f"{attrs['from']} to {attrs['to']}",
                expected=f"{start} to {end}",
            )
        lengths.append(doc.length(attrs["length"], "length", f"segment {start}-{end}", doc.line(element)))
    return lengths


def looks_like_pin_info(head: bytes) -> bool:
    """Whether the root element of the XML that ``head`` starts is ``<pin_info>``."""
    return _root_tag(head) == b"pin_info"


def looks_like_cable_info(head: bytes) -> bool:
    """Whether the root element of the XML that ``head`` starts is ``<cable_info>``."""
    return _root_tag(head) == b"cable_info"


def looks_like_path_info(head: bytes) -> bool:
    """Whether the root element of the XML that ``head`` starts is ``<path_info>``."""
    return _root_tag(head) == b"path_info"


def _root_tag(head: bytes) -> bytes | None:
    head = head.removeprefix(b"\xef\xbb\xbf")
    prolog = _PROLOG.match(head)
    match = _ROOT.match(head, prolog.end() if prolog else 0)
    return match.group(1) if match else None


def _text(value: Decimal) -> str:
    return format(value.normalize(), "f")


class _Document:
    """One route-design XML file: its root ``root`` holding ``item`` elements."""

    def __init__(self, path: str | Path, root: str, item: str) -> None:
        self.path = path
        self.item = item
        self.expected = f'<{root} units="mm"> holding <{item}> elements'
        text = read_text(path, expected=self.expected)
        self.root = parse_untrusted_xml(path, text, what="route-design XML", expected=self.expected)
        if self.root.tag != root:
            raise self.error(
                f"the root element is not <{root}>",
                self.line(self.root),
                found=f"<{self.root.tag}>",
                expected=self.expected,
            )
        attrs = self.attributes(self.root, (), ("units", "drawing", "harness", "version"))
        self.units = attrs.get("units", "mm")
        if self.units not in _UNITS:
            raise self.error(
                "unknown unit", self.line(self.root), found=self.units, expected="mm (the default) or m"
            )
        self.scale = _UNITS[self.units]

    def error(
        self, reason: str, line: int | None, found: object | None = None, expected: str | None = None
    ) -> IngestError:
        return IngestError(self.path, reason, line=line, found=found, expected=expected)

    @staticmethod
    def line(element: etree._Element) -> int:
        return int(element.sourceline or 0)

    def items(self) -> list[etree._Element]:
        found = self.children(self.root, (self.item,))
        if not found:
            raise self.error(
                f"no <{self.item}> inside <{self.root.tag}>", self.line(self.root), expected=self.expected
            )
        return found

    def children(self, parent: etree._Element, allowed: Iterable[str]) -> list[etree._Element]:
        return element_children(
            parent,
            allowed,
            lambda reason, child, expected: self.error(reason, self.line(child), expected=expected),
        )

    def attributes(
        self, element: etree._Element, required: tuple[str, ...], optional: tuple[str, ...]
    ) -> dict[str, str]:
        """The element's attributes, stripped; raises on a missing, empty or unknown one."""
        values = {k: v.strip() for k, v in attributes_of(element).items()}
        for name in values:
            if name not in required and name not in optional:
                raise self.error(
                    f"unknown attribute {name!r} of <{element.tag}>",
                    self.line(element),
                    expected=", ".join((*required, *optional)) or "no attributes",
                )
        for name in (*required, *optional):
            if name in values and not values[name]:
                raise self.error(f"empty attribute {name!r} of <{element.tag}>", self.line(element))
        missing = [n for n in required if n not in values]
        if missing:
            raise self.error(
                f"<{element.tag}> without {', '.join(missing)}",
                self.line(element),
                expected=f"the attributes {', '.join(required)}",
            )
        if element.text and element.text.strip():
            raise self.error(
                f"text inside <{element.tag}>",
                self.line(element),
                found=element.text.strip()[:40],
                expected="values as attributes",
            )
        return values

    def choice(self, value: str, allowed: tuple[str, ...], what: str, name: str, line: int) -> str:
        if value not in allowed:
            raise self.error(f"unknown {what} of {name!r}", line, found=value, expected=" or ".join(allowed))
        return value

    def number(self, raw: str, what: str, name: str, line: int) -> float:
        value = float(raw) if _NUMBER.fullmatch(raw) else math.nan
        if not math.isfinite(value):
            raise self.error(
                f"not a number: {what} of {name}",
                line,
                found=raw,
                expected=f"a decimal number of {self.units}",
            )
        return value

    def length(self, raw: str, what: str, name: str, line: int, *, positive: bool = False) -> Decimal:
        """A length in metres from a number in the document's unit."""
        try:
            value = Decimal(raw) if _NUMBER.fullmatch(raw) else Decimal("NaN")
        except InvalidOperation:
            value = Decimal("NaN")
        # A finite but absurd exponent (1e999999) would print as a megabyte of digits.
        if not value.is_finite() or abs(value.adjusted()) > 30 or value < 0 or (positive and value == 0):
            raise self.error(
                f"not a length: {what} of {name}",
                line,
                found=raw,
                expected=f"a {'positive' if positive else 'non-negative'} number of {self.units}",
            )
        return (value * self.scale).normalize()

    def optional_length(
        self, attrs: dict[str, str], key: str, name: str, line: int, *, positive: bool = False
    ) -> Decimal | None:
        """The length attribute ``key`` in metres, None where the element leaves it out."""
        return self.length(attrs[key], key, name, line, positive=positive) if key in attrs else None
