"""The mechanics of a VEC document: namespace and versions, elements by XML id, references
(IDREFs) checked against the type of what they name, and numbers with their units.

VEC reuses element names for different types (``Cavity``, ``Slot`` ... are contained in one
place and referenced in another) and puts the type of generic elements (``Specification``,
``Role``, ``Placement``, ``Unit``) in ``xsi:type``, so a reference is checked against the
``xsi:type`` (or name) of the element it names. :mod:`.vec` reads a harness out of it.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from decimal import Decimal
from pathlib import Path
from typing import Any

from lxml import etree

from cadkg.ingest.harness.xml_tree import (
    SI_PREFIXES,
    XmlDocument,
    child_text,
    element_name,
    first_child,
    kind_of,
)

__all__ = ["EXPECTED", "VEC_NAMESPACE", "VEC_VERSIONS", "VecDocument"]

VEC_NAMESPACE = "http://www.prostep.org/ecad-if/2011/vec"
"""The namespace of every VEC schema (1.1 to 2.1): the version is only in ``VecVersion``."""

VEC_VERSIONS = ("1.1", "1.2", "2.0", "2.1")
"""The VEC versions read (any revision: 1.1.3, 2.0.1 ...)."""

EXPECTED = "a VEC file: <vec:VecContent> with a <VecVersion> and a HarnessDescription document"
_PREFIX = {None: Decimal(1)} | {name.capitalize(): factor for name, factor in SI_PREFIXES.items()}
_VERSION = re.compile(r"^(?P<major>\d+)\.(?P<minor>\d+)(?:\.\d+)?$")


class VecDocument(XmlDocument):
    """A parsed VEC document: its version, its elements by XML id and its units."""

    def __init__(self, path: Path, root: Any) -> None:
        super().__init__(path, root)
        self.version = self._version()
        self.ids = self.index_ids()

    # -- references ------------------------------------------------------------------------------

    def refs(self, owner: Any, name: str, kinds: Iterable[str] | None, *, required: bool = True) -> list[Any]:
        """The elements the IDREF(S) child ``name`` of ``owner`` names, each of one of ``kinds``
        (of any kind for None)."""
        child = first_child(owner, name)
        tokens = (child.text or "").split() if child is not None else []
        allowed = tuple(kinds) if kinds is not None else None
        expected = f"the id of a {' or '.join(allowed)}" if allowed else "the id of an element of the file"
        if not tokens:
            if not required:
                return []
            self.error(f"<{element_name(owner)}> has no <{name}>", owner, expected=expected)
        found = []
        for token in tokens:
            target = self.ids.get(token)
            if target is None or (allowed is not None and kind_of(target) not in allowed):
                what = "nothing in the file" if target is None else f"a {kind_of(target)}"
                self.error(
                    f"<{name}> of <{element_name(owner)}> names {what}", child, found=token, expected=expected
                )
            found.append(target)
        return found

    def ref(self, owner: Any, name: str, kinds: Iterable[str] | None, *, required: bool = True) -> Any:
        """The one element the IDREF child ``name`` names (None when absent and not required)."""
        found = self.refs(owner, name, kinds, required=required)
        return found[0] if found else None

    # -- whole file ------------------------------------------------------------------------------
    def _version(self) -> str:
        root = self.root
        if element_name(root) != "VecContent" or etree.QName(root).namespace != VEC_NAMESPACE:
            self.error("not a VEC document", root, found=f"<{root.tag}>", expected=EXPECTED)
        raw = child_text(root, "VecVersion") or ""
        match = _VERSION.match(raw)
        if match is None or f"{match['major']}.{match['minor']}" not in VEC_VERSIONS:
            self.error(
                "unknown VEC version",
                first_child(root, "VecVersion") if first_child(root, "VecVersion") is not None else root,
                found=raw or "no <VecVersion>",
                expected=f"<VecVersion> {', '.join(v + '.x' for v in VEC_VERSIONS)}",
            )
        return raw

    # -- numbers and units ------------------------------------------------------------------------
    def number(self, element: Any, name: str) -> float | None:
        """The number (xs:double) in the child ``name``; None when there is none."""
        child = first_child(element, name)
        if child is None:
            return None
        return self.double(child, "a number such as 625.08")

    def unit_factor(self, unit: Any, exponent: int, quantity: str, owner: Any) -> Decimal:
        """What one ``unit`` is in metres (``exponent`` 1) or mm² (``exponent`` 2)."""
        name, prefix = child_text(unit, "SiUnitName"), child_text(unit, "SiPrefix")
        found_exponent = child_text(unit, "Exponent") or "1"
        if (
            kind_of(unit) == "SIUnit"
            and name == "Metre"
            and prefix in _PREFIX
            and found_exponent == str(exponent)
        ):
            factor = _PREFIX[prefix] ** exponent
            return factor * Decimal(10**6) if exponent == 2 else factor
        described = " ".join(p for p in (prefix, name or child_text(unit, "OtherUnitName")) if p)
        self.error(
            f"<{element_name(owner)}> is not given in a unit of {quantity}",
            owner,
            found=f"{described or kind_of(unit)}" + (f" ^{found_exponent}" if found_exponent != "1" else ""),
            expected="an SIUnit Metre (with an optional prefix)"
            + (" with Exponent 2" if exponent == 2 else ""),
        )

    def measure(self, element: Any | None, exponent: int = 1) -> Decimal | None:
        """A NumericalValue in metres (``exponent`` 1) or mm² (2); None for no element."""
        if element is None:
            return None
        value = self.decimal(element, "ValueComponent")
        unit = self.ref(element, "UnitComponent", ("SIUnit", "OtherUnit", "ImperialUnit", "USUnit", "Unit"))
        quantity = "length" if exponent == 1 else "area"
        return value * self.unit_factor(unit, exponent, quantity, element)
