"""Strict reading of the ELVEZ cell's XML files: safe parsing, units, numbers, placements.

The element models, the harness structure and the tool list are small XML files written
by people or by scripts, so every reader is strict: an unknown element or attribute, a
missing or malformed number is a located error. The input is untrusted: a document type
or an entity declaration is refused before parsing, and nothing is ever fetched.

Lengths and angles carry their unit on the root element (``length_unit="mm"``,
``angle_unit="deg"``); records hold metres and radians.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from cadkg.errors import IngestError
from cadkg.ingest.placement import Placement
from cadkg.ingest.text import read_text
from cadkg.ingest.xml_input import element_children, parse_untrusted_xml

__all__ = [
    "Placement",
    "Units",
    "XmlReader",
    "first_element_name",
]

_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d{1,3})?")
_LENGTH_UNITS = {"mm": 0.001, "m": 1.0}
_ANGLE_UNITS = {"deg": math.pi / 180.0, "rad": 1.0}
_FIRST_ELEMENT = re.compile(rb"<([A-Za-z_][\w.-]*)")
_POSITION = ("x", "y", "z")
_ROTATION = ("roll", "pitch", "yaw")


def first_element_name(head: bytes) -> str | None:
    """The name of the first element in the first bytes of an XML file (for content sniffing).

    The XML declaration, comments and processing instructions before it are skipped.
    """
    body = head.removeprefix(b"\xef\xbb\xbf")
    position = 0
    while True:
        start = body.find(b"<", position)
        if start < 0:
            return None
        for opening, closing in ((b"<?", b"?>"), (b"<!--", b"-->")):
            if body.startswith(opening, start):
                end = body.find(closing, start + len(opening))
                if end < 0:
                    return None
                position = end + len(closing)
                break
        else:
            match = _FIRST_ELEMENT.match(body, start)
            return match.group(1).decode("ascii") if match else None


@dataclass(frozen=True, slots=True)
class Units:
    """Factors from the file's units to metres and radians."""

    length: float
    angle: float


class XmlReader:
    """Parses one file and reports its errors at ``file:line``."""

    def __init__(self, path: str | Path, expected: str) -> None:
        self.path = path
        self.expected = expected

    def error(
        self, reason: str, element: etree._Element | None = None, *, found: object = None, expected: str = ""
    ) -> IngestError:
        line = element.sourceline if element is not None else None
        return IngestError(
            self.path,
            reason,
            line=int(line) if line is not None else None,
            found=found,
            expected=expected or None,
        )

    def root(self, name: str) -> etree._Element:
        """Parse the file and return its root, which must be ``<name>``."""
        text = read_text(self.path, expected=self.expected)
        root = parse_untrusted_xml(self.path, text, what=f"<{name}> XML", expected=self.expected)
        if root.tag != name:
            raise self.error(
                f"the root element is not <{name}>", root, found=f"<{root.tag}>", expected=self.expected
            )
        return root

    def children(self, parent: etree._Element, allowed: tuple[str, ...]) -> list[etree._Element]:
        """The element children of ``parent``; any other element name is an error."""
        return element_children(
            parent,
            allowed,
            lambda reason, child, expected: self.error(
                reason, child, found=f"<{child.tag}>", expected=expected
            ),
        )

    def one(self, parent: etree._Element, name: str, *, required: bool) -> etree._Element | None:
        """The single ``<name>`` child of ``parent`` (None when absent and not required)."""
        matches = [c for c in parent if isinstance(c.tag, str) and c.tag == name]
        if len(matches) > 1:
            raise self.error(
                f"<{name}> given twice in <{parent.tag}> (first on line {matches[0].sourceline})",
                matches[1],
                expected=f"one <{name}>",
            )
        if not matches:
            if required:
                raise self.error(f"<{parent.tag}> has no <{name}>", parent, expected=f"a <{name}> element")
            return None
        return matches[0]

    def attributes(
        self, element: etree._Element, required: tuple[str, ...], optional: tuple[str, ...] = ()
    ) -> None:
        """Check that ``element`` has every required attribute and no unknown one."""
        for key in element.attrib:
            if key not in required and key not in optional:
                known = ", ".join((*required, *optional)) or "none"
                raise self.error(
                    f"unknown attribute {key!r} of <{element.tag}>", element, found=key, expected=known
                )
        for key in required:
            value = element.get(key)
            if value is None or not value.strip():
                raise self.error(
                    f"<{element.tag}> without a {key!r} attribute", element, expected=f'{key}="..."'
                )

    def text(self, element: etree._Element, key: str) -> str:
        return (element.get(key) or "").strip()

    def number(self, element: etree._Element, key: str, *, minimum: float | None = None) -> float:
        """The attribute ``key`` of ``element`` as a finite number (at least ``minimum``)."""
        raw = self.text(element, key)
        value = float(raw) if _NUMBER.fullmatch(raw) else math.nan
        if not math.isfinite(value):
            raise self.error(
                f"{key!r} of <{element.tag}> is not a number",
                element,
                found=raw,
                expected="a decimal number, e.g. 12.5",
            )
        if minimum is not None and value < minimum:
            raise self.error(
                f"{key!r} of <{element.tag}> is below {minimum:g}",
                element,
                found=raw,
                expected=f"a number of at least {minimum:g}",
            )
        return value

    def integer(self, element: etree._Element, key: str, *, minimum: int = 1) -> int:
        raw = self.text(element, key)
        if not re.fullmatch(r"[+-]?\d{1,9}", raw) or int(raw) < minimum:
            raise self.error(
                f"{key!r} of <{element.tag}> is not a whole number of at least {minimum}",
                element,
                found=raw,
                expected=f"an integer >= {minimum}",
            )
        return int(raw)

    def units(self, root: etree._Element) -> Units:
        """The ``length_unit`` and ``angle_unit`` attributes of the root (both required)."""
        length = self.text(root, "length_unit")
        angle = self.text(root, "angle_unit")
        if length not in _LENGTH_UNITS:
            raise self.error("unknown or missing length_unit", root, found=length or None, expected="mm or m")
        if angle not in _ANGLE_UNITS:
            raise self.error(
                "unknown or missing angle_unit", root, found=angle or None, expected="deg or rad"
            )
        return Units(_LENGTH_UNITS[length], _ANGLE_UNITS[angle])

    def placement(self, element: etree._Element, units: Units, extra: tuple[str, ...] = ()) -> Placement:
        """x, y, z (lengths) and roll, pitch, yaw (angles) attributes, all required."""
        self.attributes(element, (*_POSITION, *_ROTATION), extra)
        x, y, z = (self.number(element, key) * units.length for key in _POSITION)
        roll, pitch, yaw = (self.number(element, key) * units.angle for key in _ROTATION)
        return Placement((x, y, z), (roll, pitch, yaw), int(element.sourceline or 0))

    def size(self, element: etree._Element, units: Units) -> tuple[float, float, float]:
        """x, y, z sizes (lengths, 0 or more), all required."""
        self.attributes(element, _POSITION)
        x, y, z = (self.number(element, key, minimum=0.0) * units.length for key in _POSITION)
        return (x, y, z)
