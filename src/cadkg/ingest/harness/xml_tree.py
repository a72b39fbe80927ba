"""Reading a parsed KBL or VEC tree: children by local name (any prefix), their texts, the
``xsi:type`` that VEC puts on generic elements, elements by XML id, located errors and numbers."""

from __future__ import annotations

import math
from decimal import Decimal, InvalidOperation
from pathlib import Path
from typing import Any, NoReturn

from lxml import etree

from cadkg.errors import IngestError

__all__ = [
    "SI_PREFIXES",
    "XSI_TYPE",
    "XmlDocument",
    "child_elements",
    "child_text",
    "element_name",
    "first_child",
    "kind_of",
]

XSI_TYPE = "{http://www.w3.org/2001/XMLSchema-instance}type"

SI_PREFIXES = {
    "kilo": Decimal(1000),
    "deci": Decimal("0.1"),
    "centi": Decimal("0.01"),
    "milli": Decimal("0.001"),
    "micro": Decimal("0.000001"),
}
"""The factors of the SI prefixes that lengths and areas of a harness file come with, by name
(KBL spells them in lower case, VEC capitalised)."""


def element_name(element: Any) -> str:
    return str(etree.QName(element).localname)


def kind_of(element: Any) -> str:
    """The element's type: the local part of its ``xsi:type`` when it has one, else its name."""
    declared = element.get(XSI_TYPE)
    return declared.rpartition(":")[2] if declared else element_name(element)


def child_elements(element: Any, name: str) -> list[Any]:
    return [c for c in element if isinstance(c.tag, str) and element_name(c) == name]


def first_child(element: Any, name: str) -> Any | None:
    found = child_elements(element, name)
    return found[0] if found else None


def child_text(element: Any, name: str) -> str | None:
    child = first_child(element, name)
    if child is None or child.text is None:
        return None
    value = child.text.strip()
    # KBL writers put /NULL where a value is unknown.
    return value if value and value != "/NULL" else None


class XmlDocument:
    """A parsed harness file: located errors, its elements by XML id, checked decimals."""

    def __init__(self, path: Path, root: Any) -> None:
        self.path = path
        self.root = root

    def error(
        self, reason: str, element: Any, found: object | None = None, expected: str | None = None
    ) -> NoReturn:
        raise IngestError(self.path, reason, line=element.sourceline, found=found, expected=expected)

    def index_ids(self) -> dict[str, Any]:
        """Every element with an ``id`` attribute, by it; an id given twice is an error."""
        ids: dict[str, Any] = {}
        for element in self.root.iter():
            if not isinstance(element.tag, str):
                continue
            ident = element.get("id")
            if ident is None:
                continue
            if ident in ids:
                self.error(
                    "XML id given twice",
                    element,
                    found=ident,
                    expected=f"unique ids (first on line {ids[ident].sourceline})",
                )
            ids[ident] = element
        return ids

    def double(self, element: Any, expected: str) -> float:
        """The finite number (xs:double) ``element`` holds."""
        text = (element.text or "").strip()
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not math.isfinite(value):
            self.error(
                f"bad number in <{element_name(element)}>",
                element,
                found=text or "nothing",
                expected=expected,
            )
        return value

    def decimal(self, element: Any, name: str) -> Decimal:
        """The number in the child ``name`` of a numerical value ``element``."""
        raw = child_text(element, name)
        try:
            value = Decimal(raw or "")
        except InvalidOperation:
            value = Decimal("NaN")
        exponent = value.as_tuple().exponent
        # 1e999999999 would be written out as a gigabyte of digits in the graph.
        if not value.is_finite() or not isinstance(exponent, int) or not -30 <= exponent <= 30:
            self.error(
                f"bad number in <{element_name(element)}>",
                first_child(element, name) if raw is not None else element,
                found=raw or "nothing",
                expected="a number such as 625.08",
            )
        return value
