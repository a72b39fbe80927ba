"""The mechanics of a KBL document: namespaces and versions, element lookup, XML ids and
the references (IDREFs) between elements, and numbers with their units.

:mod:`.kbl` reads a harness out of it.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping
from decimal import Decimal
from pathlib import Path
from typing import Any

from lxml import etree

from cadkg.ingest.harness.xml_tree import (
    SI_PREFIXES,
    XmlDocument,
    child_elements,
    child_text,
    element_name,
    first_child,
)

__all__ = [
    "EXPECTED",
    "KBL_NAMESPACE",
    "KBL_VERSIONS",
    "KblDocument",
    "child_elements",
    "child_text",
    "element_name",
    "first_child",
]

KBL_NAMESPACE = "http://www.prostep.org/Car_electric_container/KBL2.3/KBLSchema"
"""The namespace of every KBL schema from 2.3 on (2.4 kept it)."""

KBL_VERSIONS = ("2.3 SR-1", "2.4", "2.4 SR-1")
"""The ``version_id`` values read, those of the schemas cadkg was written against."""

EXPECTED = "a KBL file: <kbl:KBL_container version_id=...> holding a <Harness>"
_PREFIX = {None: Decimal(1)} | {name: SI_PREFIXES[name] for name in ("kilo", "centi", "milli", "micro")}
_NAMED_LENGTH = {"m": Decimal(1), "cm": Decimal("0.01"), "mm": Decimal("0.001")}
_NAMED_AREA_MM2 = {"mm2": Decimal(1), "mm²": Decimal(1), "sqmm": Decimal(1), "m2": Decimal(10**6)}


def _key(version: str) -> str:
    return re.sub(r"[\s_-]", "", version).upper()


_VERSION_KEYS = {_key(v): v for v in KBL_VERSIONS}


class KblDocument(XmlDocument):
    """A parsed KBL container: its version, its elements by XML id and its units."""

    def __init__(self, path: Path, root: Any) -> None:
        super().__init__(path, root)
        self.version = self._version()
        self.ids = self.index_ids()
        self.units = {u.get("id"): u for u in child_elements(root, "Unit")}

    # -- references ------------------------------------------------------------------------------
    def ref(
        self, owner: Any, name: str, table: dict[str, Any], expected: str, *, many: bool = False
    ) -> list[Any]:
        """The entries of ``table`` that the IDREF(S) child ``name`` of ``owner`` names."""
        child = first_child(owner, name)
        tokens = (child.text or "").split() if child is not None else []
        if not tokens:
            self.error(f"<{element_name(owner)}> has no <{name}>", owner, expected=f"the id of {expected}")
        if len(tokens) > 1 and not many:
            self.error(
                f"<{name}> names more than one element", child, found=" ".join(tokens), expected="one id"
            )
        resolved = []
        for token in tokens:
            if token not in table:
                what = (
                    "nothing in the file" if token not in self.ids else f"a <{element_name(self.ids[token])}>"
                )
                self.error(
                    f"<{name}> of <{element_name(owner)}> names {what}",
                    child,
                    found=token,
                    expected=f"the id of {expected}",
                )
            resolved.append(table[token])
        return resolved

    # -- whole file ------------------------------------------------------------------------------
    def _version(self) -> str:
        root = self.root
        if element_name(root) != "KBL_container" or etree.QName(root).namespace != KBL_NAMESPACE:
            self.error("not a KBL container", root, found=f"<{root.tag}>", expected=EXPECTED)
        raw = (root.get("version_id") or "").strip()
        version = _VERSION_KEYS.get(_key(raw))
        if version is None:
            self.error(
                "unknown KBL version",
                root,
                found=raw or "no version_id",
                expected=f"version_id {' or '.join(KBL_VERSIONS)}",
            )
        return str(version)

    # -- numbers and units ------------------------------------------------------------------------
    def _value(self, element: Any) -> tuple[Decimal, Any]:
        value = self.decimal(element, "Value_component")
        unit = self.ref(element, "Unit_component", self.units, "a <Unit>")[0]
        return value, unit

    def length(self, element: Any | None) -> Decimal | None:
        """A length in metres from a numerical value with a length unit."""
        return self._measure(element, None, lambda prefix: prefix, _NAMED_LENGTH, "length", "metres")

    def area(self, element: Any | None) -> Decimal | None:
        """An area in mm² from a numerical value with an area unit."""
        return self._measure(
            element, "square", lambda prefix: (prefix * 1000) ** 2, _NAMED_AREA_MM2, "area", "square metres"
        )

    def _measure(
        self,
        element: Any | None,
        dimension: str | None,
        si_factor: Callable[[Decimal], Decimal],
        named_factors: Mapping[str, Decimal],
        quantity: str,
        si_unit: str,
    ) -> Decimal | None:
        """A value in cadkg's unit: an SI unit (metre with ``dimension`` and a prefix whose factor
        ``si_factor`` turns into cadkg's unit) or one of the ``named_factors``."""
        if element is None:
            return None
        value, unit = self._value(element)
        name, prefix, found_dimension = (
            child_text(unit, "Si_unit_name"),
            child_text(unit, "Si_prefix"),
            child_text(unit, "Si_dimension"),
        )
        if name == "metre" and found_dimension == dimension and prefix in _PREFIX:
            return value * si_factor(_PREFIX[prefix])
        named = (child_text(unit, "Unit_name") or "").lower()
        if name is None and named in named_factors:
            return value * named_factors[named]
        self.error(
            f"<{element_name(element)}> is not given in a unit of {quantity}",
            element,
            found=_describe(unit),
            expected=f"a <Unit> of {si_unit} (with an optional prefix)",
        )


def _describe(unit: Any) -> str:
    parts: Iterable[str | None] = (
        child_text(unit, "Si_prefix"),
        child_text(unit, "Si_unit_name"),
        child_text(unit, "Si_dimension"),
        child_text(unit, "Unit_name"),
    )
    return " ".join(p for p in parts if p) or f"<Unit id={unit.get('id')!r}> without a name"
