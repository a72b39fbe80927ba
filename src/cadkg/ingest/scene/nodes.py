"""The scene graph both scene encodings parse into: nodes with a type, a DEF name, field values
as written and node-valued fields, and the reading of field values as numbers and strings.

X3D (:mod:`.x3d`) and VRML97 (:mod:`.vrml`) are parsed into the same :class:`Node` tree, which
:mod:`.walk` turns into items.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from cadkg.errors import IngestError
from cadkg.ingest.scene.records import Floats, Ints

__all__ = [
    "MAX_NESTING",
    "Field",
    "Node",
    "ParsedFile",
    "Parser",
    "floats_of",
    "ints_of",
    "strings_of",
    "vector_of",
]

# Parsers and the walk recurse once per nesting level; this keeps them far from Python's
# recursion limit on hostile input, and no CAD export nests this deep.
MAX_NESTING = 100
_FLOAT = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d{1,3})?")
_INT = re.compile(r"[+-]?(?:\d{1,18}|0[xX][0-9a-fA-F]{1,15})")
_SPLIT = re.compile(r"[\s,]+")
_QUOTED = re.compile(r'"((?:[^"\\]|\\.)*)"', re.DOTALL)
_ESCAPE = re.compile(r"\\(.)", re.DOTALL)


@dataclass(frozen=True, slots=True)
class Field:
    """A field's value as written: an X3D attribute (``str``) or VRML tokens (``list``)."""

    line: int
    raw: str | list[str]


@dataclass(eq=False, slots=True)
class Node:
    """One node of a parsed scene file; a USE is a node whose ``use_of`` is the DEF'd node."""

    type: str
    source: str
    line: int
    def_name: str | None = None
    use_of: Node | None = None
    # The line of the first DEF of a name this node gives again (read leniently; see parse_x3d).
    redefines: int | None = None
    fields: dict[str, Field] = field(default_factory=dict)
    nodes: dict[str, list[Node]] = field(default_factory=dict)


@dataclass(frozen=True, slots=True)
class ParsedFile:
    """The top-level nodes of one file and its DEF names with their lines."""

    roots: list[Node]
    defs: dict[str, int]


Parser = Callable[[Path], ParsedFile]


# --- field values --------------------------------------------------------------------------------------


def _tokens(value: Field) -> list[str]:
    if isinstance(value.raw, str):
        return [t for t in _SPLIT.split(value.raw) if t]
    return value.raw


def _bad_number(node: Node, name: str, value: Field, token: str, expected: str) -> IngestError:
    return IngestError(
        node.source, f"bad number in {name!r} of {node.type}", line=value.line, found=token, expected=expected
    )


def floats_of(node: Node, name: str, default: tuple[float, ...] = ()) -> Floats:
    """The numbers of a field (all finite); ``default`` when the field is absent."""
    value = node.fields.get(name)
    if value is None:
        return np.array(default, dtype=np.float64)
    tokens = _tokens(value)
    expected = "a decimal number such as 0.25 or -1e-3"
    for token in tokens:
        if not _FLOAT.fullmatch(token):
            raise _bad_number(node, name, value, token, expected)
    numbers = np.array(tokens, dtype=np.float64)
    finite = np.isfinite(numbers)
    if not finite.all():
        raise _bad_number(node, name, value, tokens[int(finite.argmin())], "a finite number")
    return numbers


def vector_of(node: Node, name: str, default: tuple[float, ...]) -> Floats:
    """A field of exactly ``len(default)`` numbers (an SFVec3f, an SFRotation ...)."""
    numbers = floats_of(node, name, default)
    if numbers.size != len(default):
        value = node.fields[name]
        found = value.raw if isinstance(value.raw, str) else " ".join(value.raw)
        raise IngestError(
            node.source,
            f"{name!r} of {node.type} has {numbers.size} number(s)",
            line=value.line,
            found=found[:60],
            expected=f"{len(default)} numbers",
        )
    return numbers


def ints_of(node: Node, name: str) -> Ints:
    """The integers of a field (an MFInt32); empty when absent."""
    value = node.fields.get(name)
    if value is None:
        return np.empty(0, dtype=np.int64)
    tokens = _tokens(value)
    for token in tokens:
        if not _INT.fullmatch(token):
            raise _bad_number(node, name, value, token, "an integer such as 3 or -1")
    if any("x" in t or "X" in t for t in tokens):
        return np.array([int(t, 16) if "x" in t or "X" in t else int(t) for t in tokens], dtype=np.int64)
    return np.array(tokens, dtype=np.int64)


def strings_of(node: Node, name: str) -> list[str]:
    """An MFString: VRML string tokens, or an X3D attribute of quoted strings (one bare string allowed)."""
    value = node.fields.get(name)
    if value is None:
        return []
    if not isinstance(value.raw, str):
        return list(value.raw)
    if '"' not in value.raw:
        bare = value.raw.strip()
        return [bare] if bare else []
    return [_ESCAPE.sub(r"\1", m) for m in _QUOTED.findall(value.raw)]
