"""Reader of component model XML: where each pin's screw and hole sit on a commercial part.

The XML (D3.1, Figure 4, right) comes as a file of its own or embedded in a cell of the
component list, so :func:`parse_models_fragment` takes text and a line offset and the
file reader is a thin wrapper around it. Poses are in metres and radians, relative to
the model's origin. The input is untrusted: no DTD, no entities, no network.
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
    "ChildPlacement",
    "ComponentModel",
    "Couple",
    "looks_like_component_models",
    "parse_models_fragment",
    "read_component_models",
]

_EXPECTED = '<data> holding <code name="..."> models with <couple> and <child> elements'
_ROLES = ("root", "child", "terminal")
_POS = ("x", "y", "z")
_ROT = ("R", "P", "Y")
_SUBITEMS = {"couple": ("screw", "hole"), "child": ("relative",)}
_NUMBER = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?")
# Checked on the text before parsing: even with entity expansion off, a DOCTYPE can
# pull in external subsets or declare entities whose meaning we would silently drop.


@dataclass(frozen=True, slots=True)
class Couple:
    """One pin of the model: where its screw and its hole are."""

    name: str
    screw: Placement | None
    hole: Placement | None
    line: int


@dataclass(frozen=True, slots=True)
class ChildPlacement:
    """Another model mounted on this one (an auxiliary contact on a breaker)."""

    name: str
    relative: Placement
    line: int


@dataclass(frozen=True, slots=True)
class ComponentModel:
    """One ``<code>`` element: a commercial part's size, pins and mounted children."""

    code: str
    commercial: str | None
    dimensions: tuple[float, float, float] | None
    role: str | None
    couples: tuple[Couple, ...]
    children: tuple[ChildPlacement, ...]
    line: int

    @property
    def key(self) -> str:
        """What the commercial codes of the WRI table match."""
        return self.commercial or self.code


def read_component_models(path: str | Path) -> list[ComponentModel]:
    """Read a component model XML file.

    Raises
    ------
    IngestError
        On an empty or binary file, a DOCTYPE or entity declaration, malformed XML,
        an unknown element, a missing or malformed number, a model given twice, or a
        model mounted in itself through its children; located at file:line.
    """
    text = read_text(path, expected=_EXPECTED)
    return parse_models_fragment(text, path, 0)


def looks_like_component_models(head: bytes) -> bool:
    """Whether the first bytes of a file look like component model XML (for the registry)."""
    text = head.decode("utf-8", errors="replace").removeprefix("\ufeff")
    # A component list also holds '<data' and '<code' (in its XML Data cells), but not first.
    return text.lstrip().startswith("<") and "<data" in text and "<code" in text


def parse_models_fragment(text: str, path: str | Path, line_offset: int) -> list[ComponentModel]:
    """Parse ``<data>`` XML text; line ``n`` of ``text`` is reported as ``n + line_offset``."""
    return _Parser(path, line_offset).models(text)


class _Parser:
    def __init__(self, path: str | Path, line_offset: int) -> None:
        self.path = path
        self.offset = line_offset

    def error(
        self, reason: str, line: int | None, found: object | None = None, expected: str | None = None
    ) -> IngestError:
        return IngestError(
            self.path,
            reason,
            line=None if line is None else line + self.offset,
            found=found,
            expected=expected,
        )

    def at(self, element: etree._Element) -> int | None:
        line = element.sourceline
        return int(line) if line is not None else None

    def models(self, text: str) -> list[ComponentModel]:
        root = parse_untrusted_xml(
            self.path, text, what="component model XML", expected=_EXPECTED, line_offset=self.offset
        )
        if root.tag != "data":
            raise self.error(
                "the root element is not <data>", self.at(root), found=f"<{root.tag}>", expected=_EXPECTED
            )
        models: list[ComponentModel] = []
        seen: dict[str, int] = {}
        for element in self.children(root, ("code",)):
            model = self.model(element)
            if model.key in seen:
                raise self.error(
                    f"model {model.key!r} given twice (first on line {seen[model.key]})",
                    self.at(element),
                    expected="each commercial code once",
                )
            seen[model.key] = model.line
            models.append(model)
        if not models:
            raise self.error("no <code> model inside <data>", self.at(root), expected=_EXPECTED)
        cycle = _mounted_in_itself(models)
        if cycle is not None:
            chain, line = cycle
            # ``line`` is a ChildPlacement's, already shifted by the offset.
            raise IngestError(
                self.path,
                f"model {chain[0]!r} is mounted in itself: {' → '.join(chain)}",
                line=line,
                expected="child models that do not hold the model they are mounted on",
            )
        return models

    def children(self, parent: etree._Element, allowed: tuple[str, ...]) -> list[etree._Element]:
        return element_children(
            parent,
            allowed,
            lambda reason, child, expected: self.error(reason, self.at(child), expected=expected),
        )

    def name(self, element: etree._Element) -> str:
        name = (element.get("name") or "").strip()
        if not name:
            raise self.error(f"<{element.tag}> without a name attribute", self.at(element))
        return name

    def number(self, raw: str, what: str, line: int | None) -> float:
        text = raw.strip()
        value = float(text) if _NUMBER.fullmatch(text) else math.nan
        if not math.isfinite(value):
            raise self.error(
                f"not a finite number in {what}", line, found=text, expected="a decimal number, e.g. 0.0085"
            )
        return value

    def model(self, element: etree._Element) -> ComponentModel:
        line = self.at(element)
        code = self.name(element)
        role = element.get("parent")
        if role is not None and role.strip() not in _ROLES:
            raise self.error(
                f"unknown parent role of model {code!r}", line, found=role, expected="root, child or terminal"
            )
        dims = {a: element.get(a) for a in ("xdim", "ydim", "zdim")}
        given = [a for a, v in dims.items() if v is not None]
        dimensions: tuple[float, float, float] | None = None
        if given and len(given) < 3:
            missing = ", ".join(a for a, v in dims.items() if v is None)
            raise self.error(
                f"model {code!r} gives {', '.join(given)} but not {missing}",
                line,
                expected="all of xdim, ydim, zdim or none",
            )
        if given:
            x, y, z = (self.number(v or "", f"{a} of model {code!r}", line) for a, v in dims.items())
            if min(x, y, z) < 0:
                raise self.error(
                    f"negative dimension of model {code!r}", line, found=(x, y, z), expected="sizes >= 0 m"
                )
            dimensions = (x, y, z)
        couples: list[Couple] = []
        children: list[ChildPlacement] = []
        first_line: dict[str, int] = {}
        for child in self.children(element, ("couple", "child")):
            name = self.name(child)
            subitems = self.subitems(child, f"{child.tag} {name!r} of model {code!r}")
            if child.tag == "child":
                relative = subitems.get("relative")
                if relative is None:
                    raise self.error(
                        f"child {name!r} of model {code!r} has no relative placement",
                        self.at(child),
                        expected='<subitem name="relative">',
                    )
                children.append(ChildPlacement(name, relative, self.line(child)))
                continue
            if name in first_line:
                raise self.error(
                    f"couple {name!r} given twice in model {code!r} (first on line {first_line[name]})",
                    self.at(child),
                    expected="each pin once per model",
                )
            first_line[name] = self.line(child)
            couples.append(Couple(name, subitems.get("screw"), subitems.get("hole"), self.line(child)))
        commercial = (element.get("commercial") or "").strip() or None
        return ComponentModel(
            code=code,
            commercial=commercial,
            dimensions=dimensions,
            role=role.strip() if role is not None else None,
            couples=tuple(couples),
            children=tuple(children),
            line=self.line(element),
        )

    def line(self, element: etree._Element) -> int:
        return (self.at(element) or 1) + self.offset

    def subitems(self, parent: etree._Element, owner: str) -> dict[str, Placement]:
        allowed = _SUBITEMS[str(parent.tag)]
        placements: dict[str, Placement] = {}
        for subitem in self.children(parent, ("subitem",)):
            kind = self.name(subitem)
            if kind not in allowed:
                raise self.error(
                    f"unknown subitem {kind!r} in {owner}",
                    self.at(subitem),
                    found=kind,
                    expected=" or ".join(allowed),
                )
            if kind in placements:
                raise self.error(f"subitem {kind!r} given twice in {owner}", self.at(subitem))
            placements[kind] = self.placement(subitem, f"subitem {kind!r} of {owner}")
        return placements

    def placement(self, subitem: etree._Element, owner: str) -> Placement:
        values: dict[str, float] = {}
        for element in self.children(subitem, ("pos", "rot")):
            axis = self.name(element)
            names = _POS if element.tag == "pos" else _ROT
            if axis not in names:
                raise self.error(
                    f"unknown <{element.tag}> name {axis!r} in {owner}",
                    self.at(element),
                    found=axis,
                    expected=", ".join(names),
                )
            where = f"<{element.tag} name={axis!r}> of {owner}"
            if axis in values:
                raise self.error(f"{where} given twice", self.at(element))
            if len(element):
                raise self.error(f"{where} holds elements, not a number", self.at(element))
            values[axis] = self.number(element.text or "", where, self.at(element))
        missing = [a for a in (*_POS, *_ROT) if a not in values]
        if missing:
            raise self.error(
                f"{owner} lacks {', '.join(missing)}",
                self.at(subitem),
                expected="<pos> x, y, z and <rot> R, P, Y",
            )
        return Placement(
            xyz=(values["x"], values["y"], values["z"]),
            rpy=(values["R"], values["P"], values["Y"]),
            line=self.line(subitem),
        )


def _mounted_in_itself(models: list[ComponentModel]) -> tuple[list[str], int] | None:
    """A chain of models, each a child of the one before, back to the first, with the line of
    the ``<child>`` that closes it; None when no model of the file holds itself."""
    by_key = {model.key: model for model in models}
    state: dict[str, bool] = {}  # True while on the current chain, False once left
    for first in by_key:
        if first in state:
            continue
        chain = [first]
        state[first] = True
        # Iterative, so a long chain of children cannot exhaust Python's recursion limit.
        pending = [iter(by_key[first].children)]
        while pending:
            child = next(pending[-1], None)
            if child is None:
                state[chain.pop()] = False
                pending.pop()
            elif state.get(child.name):
                return [*chain[chain.index(child.name) :], child.name], child.line
            elif child.name in by_key and child.name not in state:
                chain.append(child.name)
                state[child.name] = True
                pending.append(iter(by_key[child.name].children))
    return None
