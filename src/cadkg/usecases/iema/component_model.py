"""Reader of component model XML (``Component_tf.xml``): where each pin's screw and hole sit.

The XML (D3.1, Figure 4, right) comes as a file of its own or embedded in a cell of the
component list, so :func:`parse_models_fragment` takes text and a line offset and the
file reader is a thin wrapper around it. Poses are in metres and radians, relative to
the model's origin (the corner of its box); angles compose about the moving axes X, then
Y, then Z, as the cell's software reads this file (docs/formats/component-model.md). The
input is untrusted: no DTD, no entities, no network.

Real files add to the couples ``<item name="marker|visual|corner">`` frames, give a model
twice (the later one counts, with a warning naming both lines) and mount a ``parent="child"``
model on the root item of its label with ``<child name="1">``; elements this reader does not
know are skipped with one warning per name.
"""

from __future__ import annotations

import math
import re
import warnings
from dataclasses import dataclass
from pathlib import Path

from lxml import etree

from cadkg.errors import IngestError, IngestWarning
from cadkg.ingest.placement import Placement
from cadkg.ingest.text import read_text
from cadkg.ingest.xml_input import element_children, parse_untrusted_xml

__all__ = [
    "ChildPlacement",
    "ComponentModel",
    "Couple",
    "ModelItem",
    "looks_like_component_models",
    "parse_models_fragment",
    "read_component_models",
]

_EXPECTED = '<data> holding <code name="..."> models with <couple> and <child> elements'
_ROLES = ("root", "child", "terminal")
_POS = ("x", "y", "z")
_ROT = ("R", "P", "Y")
_SUBITEMS = {"couple": ("screw", "hole"), "child": ("relative",)}
_CODE_CHILDREN = ("couple", "child", "item")
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
class ModelItem:
    """A named frame of the model (``<item name="marker">``): where the vision marker sits,
    the camera's view point, or ``corner``, which replaces the computed corner."""

    name: str
    placement: Placement
    line: int


@dataclass(frozen=True, slots=True)
class ComponentModel:
    """One ``<code>`` element: a commercial part's size, pins, mounted children and frames.

    ``mounting`` is where a ``parent="child"`` model's origin sits relative to the root item
    of its label (its ``<child name="1">``); ``children`` are the older form, a parent naming
    the models mounted on it.
    """

    code: str
    commercial: str | None
    dimensions: tuple[float, float, float] | None
    role: str | None
    couples: tuple[Couple, ...]
    children: tuple[ChildPlacement, ...]
    line: int
    items: tuple[ModelItem, ...] = ()
    mounting: Placement | None = None

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
        self.warned: set[str] = set()

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
        by_key: dict[str, ComponentModel] = {}
        for element in self.children(root, ("code",)):
            model = self.model(element)
            earlier = by_key.pop(model.key, None)
            if earlier is not None:
                # The cell's software keeps the later model whole: couples, size, role, items.
                self.warn(
                    f"model {model.key!r} given twice, on lines {earlier.line} and {model.line};"
                    f" the later one (line {model.line}) is read",
                    model.line - self.offset,
                    once=False,
                )
            by_key[model.key] = model
        models = list(by_key.values())
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
        if parent.tag in ("data", "subitem", "item"):
            return element_children(
                parent,
                allowed,
                lambda reason, child, expected: self.error(reason, self.at(child), expected=expected),
            )
        found = []
        for child in parent:
            if not isinstance(child.tag, str):
                continue
            if child.tag not in allowed:
                self.warn(f"unknown element <{child.tag}> inside <{parent.tag}> skipped", self.at(child))
                continue
            found.append(child)
        return found

    def warn(self, reason: str, line: int | None, *, once: bool = True) -> None:
        """An :class:`IngestWarning`; with ``once``, only the first of each reason in the file."""
        if once:
            if reason in self.warned:
                return
            self.warned.add(reason)
        where = None if line is None else line + self.offset
        warnings.warn(IngestWarning(self.path, reason, line=where), stacklevel=3)

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
            reason = f"unknown parent role {role.strip()!r} of model {code!r} read as none"
            self.warn(reason, line, once=False)
            role = None
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
        couples: dict[str, Couple] = {}
        children: list[ChildPlacement] = []
        items: dict[str, ModelItem] = {}
        mounting: Placement | None = None
        for child in self.children(element, _CODE_CHILDREN):
            name = self.name(child)
            owner = f"{child.tag} {name!r} of model {code!r}"
            if child.tag == "item":
                items[name] = ModelItem(name, self.placement(child, owner), self.line(child))
                continue
            subitems = self.subitems(child, owner)
            if child.tag == "child":
                relative = subitems.get("relative")
                if relative is None:
                    raise self.error(
                        f"child {name!r} of model {code!r} has no relative placement",
                        self.at(child),
                        expected='<subitem name="relative">',
                    )
                if role is not None and role.strip() == "child":
                    mounting = relative  # this model's own place on the root item of its label
                else:
                    children.append(ChildPlacement(name, relative, self.line(child)))
                continue
            if name in couples:
                self.warn(
                    f"couple {name!r} given twice in model {code!r}, on lines {couples[name].line} and"
                    f" {self.line(child)}; the later one is read",
                    self.at(child),
                    once=False,
                )
                del couples[name]
            couples[name] = Couple(name, subitems.get("screw"), subitems.get("hole"), self.line(child))
        commercial = (element.get("commercial") or "").strip() or None
        return ComponentModel(
            code=code,
            commercial=commercial,
            dimensions=dimensions,
            role=role.strip() if role is not None else None,
            couples=tuple(couples.values()),
            children=tuple(children),
            line=self.line(element),
            items=tuple(items.values()),
            mounting=mounting,
        )

    def line(self, element: etree._Element) -> int:
        return (self.at(element) or 1) + self.offset

    def subitems(self, parent: etree._Element, owner: str) -> dict[str, Placement]:
        allowed = _SUBITEMS[str(parent.tag)]
        placements: dict[str, Placement] = {}
        for subitem in self.children(parent, ("subitem",)):
            kind = name = self.name(subitem)
            if kind not in allowed and parent.tag == "couple":
                # The cell's software takes every subitem of a couple but the hole for its screw.
                kind = "screw"
                self.warn(f"subitem {name!r} of a couple read as its screw", self.at(subitem))
            elif kind not in allowed:
                raise self.error(
                    f"unknown subitem {kind!r} in {owner}",
                    self.at(subitem),
                    found=kind,
                    expected=" or ".join(allowed),
                )
            if kind in placements:
                raise self.error(f"subitem {kind!r} given twice in {owner}", self.at(subitem))
            placements[kind] = self.placement(subitem, f"subitem {name!r} of {owner}")
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
            moving_axes=True,
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
