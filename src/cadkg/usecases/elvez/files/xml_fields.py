"""Reading the ELVEZ cell's XML files: safe parsing, numbers, poses, located errors.

The element definitions and the harness configuration are small files written by hand (with
comments, mixed tabs and spaces), so the readers are strict about what matters: an unknown
element or attribute, a missing or malformed number is an error naming the file and line. The
input is untrusted: a document type or an entity declaration is refused before parsing, and
nothing is ever fetched.

Lengths are millimetres and angles radians in these files; records hold metres and radians.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable
from decimal import Decimal
from pathlib import Path

from lxml import etree

from cadkg.errors import IngestError
from cadkg.geometry.frames import quaternion_from_rpy
from cadkg.geometry.poses import Pose
from cadkg.ingest.text import read_text
from cadkg.ingest.xml_input import element_children, parse_untrusted_xml

__all__ = ["XmlReader", "element_names", "metres", "rotation_xyz"]

_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d{1,3})?")
_TAG = re.compile(rb"<(/?)([A-Za-z_][\w.-]*)")
_POSITION = ("x", "y", "z")
_ROTATION = ("R", "P", "Y")


def metres(millimetres: str) -> float:
    """A number of millimetres as written, in metres: ``"5.1"`` → 0.0051 (the double nearest
    the exact quotient, not 5.1 · 0.001 = 0.0050999999999999995)."""
    return float(Decimal(millimetres) / 1000)


def element_names(head: bytes, count: int = 2) -> list[str]:
    """The names of the first ``count`` elements opened in the first bytes of an XML file (for
    content sniffing); the declaration, comments and processing instructions are skipped."""
    body = re.sub(rb"<!--.*?(-->|$)|<\?.*?(\?>|$)", b"", head.removeprefix(b"\xef\xbb\xbf"), flags=re.DOTALL)
    names = [m.group(2).decode("ascii") for m in _TAG.finditer(body) if not m.group(1)]
    return names[:count]


def rotation_xyz(roll: float, pitch: float, yaw: float) -> Pose:
    """The rotation of R about x, then P about the new y, then Y about the newest z
    (``Rx(R)·Ry(P)·Rz(Y)``), as the element definitions compose their angles."""
    return (
        Pose(orientation=quaternion_from_rpy(roll, 0.0, 0.0))
        * Pose(orientation=quaternion_from_rpy(0.0, pitch, 0.0))
        * Pose(orientation=quaternion_from_rpy(0.0, 0.0, yaw))
    )


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

    def twice(
        self, what: str, first: int, element: etree._Element, expected: str, *, verb: str = "given"
    ) -> IngestError:
        """``what`` (``"harness 3"``) met again at ``element``, having been met first on line ``first``."""
        return self.error(f"{what} {verb} twice (first on line {first})", element, expected=expected)

    def root(self, name: str) -> etree._Element:
        """Parse the file and return its root, which must be ``<name>``."""
        text = read_text(self.path, expected=self.expected)
        root = parse_untrusted_xml(self.path, text, what=f"<{name}> XML", expected=self.expected)
        if root.tag != name:
            raise self.error(
                f"the root element is not <{name}>", root, found=f"<{root.tag}>", expected=self.expected
            )
        return root

    def children(self, parent: etree._Element, allowed: Iterable[str]) -> list[etree._Element]:
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
        self, element: etree._Element, required: Iterable[str], optional: Iterable[str] = ()
    ) -> None:
        """Check that ``element`` has every required attribute and no unknown one."""
        required, optional = tuple(required), tuple(optional)
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
        return self._number(element, self.text(element, key), f"{key!r} of <{element.tag}>", minimum)

    def _number(self, element: etree._Element, raw: str, what: str, minimum: float | None = None) -> float:
        value = float(raw) if _NUMBER.fullmatch(raw) else math.nan
        if not math.isfinite(value):
            raise self.error(
                f"{what} is not a number", element, found=raw, expected="a decimal number, e.g. 12.5"
            )
        if minimum is not None and value < minimum:
            raise self.error(
                f"{what} is below {minimum:g}",
                element,
                found=raw,
                expected=f"a number of at least {minimum:g}",
            )
        return value

    def length(self, element: etree._Element, key: str, *, minimum: float | None = None) -> float:
        """A length attribute in millimetres, as metres."""
        self.number(element, key, minimum=minimum)
        return metres(self.text(element, key))

    def lengths(
        self, element: etree._Element, keys: Iterable[str], *, minimum: float | None = None
    ) -> tuple[float, ...]:
        return tuple(self.length(element, key, minimum=minimum) for key in keys)

    def integer(self, element: etree._Element, key: str, *, minimum: int = 0) -> int:
        raw = self.text(element, key)
        if not re.fullmatch(r"[+-]?\d{1,9}", raw) or int(raw) < minimum:
            raise self.error(
                f"{key!r} of <{element.tag}> is not a whole number of at least {minimum}",
                element,
                found=raw,
                expected=f"an integer >= {minimum}",
            )
        return int(raw)

    def pose(self, element: etree._Element, allowed: Iterable[str] = ()) -> Pose:
        """A pose written as six children ``<pos name="x|y|z">`` (mm) and ``<rot name="R|P|Y">``
        (rad), in any order; angles composed as :func:`rotation_xyz`."""
        values: dict[str, float] = {}
        written: dict[str, str] = {}
        for child in self.children(element, ("pos", "rot", *allowed)):
            if child.tag not in ("pos", "rot"):
                continue
            self.attributes(child, ("name",))
            name = self.text(child, "name")
            names = _POSITION if child.tag == "pos" else _ROTATION
            if name not in names:
                raise self.error(
                    f"unknown {child.tag} name {name!r} in <{element.tag}>",
                    child,
                    found=name,
                    expected=" or ".join(names),
                )
            if name in values:
                raise self.error(f"<{child.tag} name={name!r}> given twice in <{element.tag}>", child)
            written[name] = (child.text or "").strip()
            values[name] = self._number(child, written[name], f"<{child.tag} name={name!r}>")
        missing = [n for n in (*_POSITION, *_ROTATION) if n not in values]
        if missing:
            raise self.error(
                f"<{element.tag}> has no {', '.join(missing)}",
                element,
                expected='six children: <pos name="x|y|z"> in mm and <rot name="R|P|Y"> in rad',
            )
        position = (metres(written["x"]), metres(written["y"]), metres(written["z"]))
        return Pose(position, rotation_xyz(values["R"], values["P"], values["Y"]).orientation)
