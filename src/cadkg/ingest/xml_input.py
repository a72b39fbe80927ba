"""Parsing untrusted XML: one place that decides what an input file may not do.

Factory files arrive from outside; a document type or an entity declaration could
expand to gigabytes or reach the network, so they are refused with the line they
are on, before lxml sees them, and the parser itself resolves nothing.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable
from pathlib import Path

from lxml import etree

from cadkg.errors import IngestError
from cadkg.ingest.text import xml_document

__all__ = ["attributes_of", "element_children", "parse_untrusted_xml", "read_xml_file"]

_DECLARATIONS = re.compile(rb"<!(DOCTYPE|ENTITY)", re.IGNORECASE)
_ENTITY = re.compile(rb"<!(ENTITY)", re.IGNORECASE)
_TOO_DEEP = re.compile(r"Excessive depth in document: (\d+)")
# lxml's ``attrib.items()`` (and ``values()``) looks each value up again from the element's
# first attribute, a time that grows with the square of their number; its ``keys()`` and XPath's
# attribute axis walk them once, in the same order. Below a few dozen the square costs less
# than an XPath call.
_VALUES = etree.XPath("@*", smart_strings=False)
_FEW_ATTRIBUTES = 32


def parse_untrusted_xml(
    path: str | Path,
    data: bytes | str,
    *,
    what: str,
    expected: str,
    line_offset: int = 0,
    allow_doctype: bool = False,
) -> etree._Element:
    """The root element of ``data``, parsed without DTDs, entities or network access.

    ``what`` names the format in messages ("KBL", "route-design XML"); ``line_offset``
    is added to every line (XML embedded in a cell of another file); ``allow_doctype``
    lets a plain ``<!DOCTYPE>`` through (X3D files carry one), entities stay refused.

    Raises
    ------
    IngestError
        On a declaration that is refused, or malformed XML, with its line.
    """
    encoded = data.encode("utf-8") if isinstance(data, str) else data
    declaration = (_ENTITY if allow_doctype else _DECLARATIONS).search(encoded)
    if declaration is not None:
        raise IngestError(
            path,
            f"<!{declaration.group(1).decode().upper()}> is not allowed in {what}",
            found=declaration.group(0).decode(),
            line=line_offset + encoded.count(b"\n", 0, declaration.start()) + 1,
            expected="plain XML without entity declarations"
            if allow_doctype
            else "plain XML without a document type or entity declarations",
        )
    parser = etree.XMLParser(
        resolve_entities=False,
        no_network=True,
        load_dtd=False,
        huge_tree=False,
        remove_comments=True,
        remove_pis=True,
        # Text already decoded by the reader wins over the document's own encoding label.
        encoding="utf-8" if isinstance(data, str) else None,
    )
    try:
        return etree.fromstring(encoded, parser)
    except etree.XMLSyntaxError as err:
        line = err.lineno if isinstance(err.lineno, int) and err.lineno > 0 else 1
        depth = _TOO_DEEP.match(err.msg)
        if depth is not None:  # libxml2 would suggest lifting its limit; for untrusted files it stays
            reason = f"elements nest deeper than {depth.group(1)} levels"
        else:
            reason = f"malformed XML: {err.msg}"
        raise IngestError(path, reason, line=line_offset + line, expected=expected) from None


def read_xml_file(path: str | Path, *, root: str | None = None, what: str, expected: str) -> etree._Element:
    """The root element of the XML file ``path``, which must be ``<root>`` when one is given.

    Raises
    ------
    IngestError
        On an unreadable, empty or binary file, a refused declaration, malformed XML, or
        another root element.
    """
    try:
        data = Path(path).read_bytes()
    except OSError as err:
        raise IngestError(path, f"cannot read the file: {err.strerror}") from err
    element = parse_untrusted_xml(
        path, xml_document(path, data, expected=expected), what=what, expected=expected
    )
    if root is not None and element.tag != root:
        raise IngestError(
            path,
            f"the root element is not <{root}>",
            line=element.sourceline,
            found=f"<{element.tag}>",
            expected=expected,
        )
    return element


def attributes_of(element: etree._Element) -> dict[str, str]:
    """The attributes of ``element``, name (``{namespace}local`` when namespaced) to value, in
    document order: what ``dict(element.attrib)`` holds, in time linear in their number."""
    attrib = element.attrib
    if len(attrib) <= _FEW_ATTRIBUTES:
        return dict(attrib.items())
    return dict(zip(attrib.keys(), _VALUES(element), strict=True))


def element_children(
    parent: etree._Element,
    allowed: Iterable[str],
    error: Callable[[str, etree._Element, str], IngestError],
) -> list[etree._Element]:
    """The element children of ``parent`` (comments and processing instructions skipped).

    Any other element name raises ``error(reason, child, expected)``, which locates it the way
    the calling reader counts lines.
    """
    allowed = tuple(allowed)
    found = []
    for child in parent:
        if not isinstance(child.tag, str):
            continue
        if child.tag not in allowed:
            raise error(
                f"unexpected element <{child.tag}> inside <{parent.tag}>",
                child,
                " or ".join(f"<{a}>" for a in allowed),
            )
        found.append(child)
    return found
