"""Inputs shaped to make every reader do the most work per byte, and what reading them costs.

Every reader kind the registry declares has a seed here: one of the project's own small sound
files (or one made the way the reader tests make theirs). Each family turns that seed into a
file of about a given size that keeps the seed's skeleton (its header, its root, its sheet)
and multiplies one thing a reader pays for: many tiny rows, the same row again and again, one
very long row or value, many columns or attributes, deep nesting, numbers thousands of digits
long, references to one definition, a workbook's far or shared cells. The files are made in
the run from a seeded generator; nothing big is committed.

:func:`measure` reads each file as a build does (``read_limited`` with the reader's stream or
read function, in a limited child) from a fresh process, each case in a process forked for it,
so the child's peak is its own: the peak resident size above the process it was forked from,
less what reading the seed took, per byte of input, and its CPU seconds (less the seed's) per
MiB. ``python -m tests.security.reader_attacks [KiB]`` prints the table.
"""

from __future__ import annotations

import json
import os
import random
import re
import struct
import sys
import zipfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any
from xml.sax.saxutils import escape, quoteattr

from lxml import etree

from tests.ingest.biff import grid, write_xls
from tests.ingest.workbooks import run_child, write_ods, write_zip

__all__ = ["FAMILIES", "SEEDS", "Attack", "Measured", "Seed", "attacks", "measure", "table"]

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
DATA = ROOT / "tests" / "data"

_NUMBERS = re.compile(r"[-+.\d eE,]+")
# Long enough that int() refuses it (4,300 digits) and float() makes it infinite.
_DIGITS = 5000


@dataclass(frozen=True)
class Seed:
    """The sound file a reader's attacks start from, and how its content is shaped."""

    path: Path | None  # None: made by :func:`_labelling_seed`
    form: str  # "text", "xml", "vrml", "stl" or "workbook"
    suffix: str = ""  # the suffix the attack files get (default: the seed's)


@dataclass(frozen=True)
class Attack:
    kind: str
    family: str
    path: Path


_IEMA = EXAMPLES / "iema-switchgear"
_ELVEZ = EXAMPLES / "elvez-cell"
_ELIMCO = EXAMPLES / "elimco-bench"

SEEDS: dict[str, tuple[Seed, ...]] = {
    "assignments": (Seed(_IEMA / "assignments.csv", "text"),),
    "bill-of-materials": (
        Seed(_IEMA / "distinta-componenti.xlsx", "workbook", ".xlsx"),
        Seed(_IEMA / "distinta-componenti.xlsx", "workbook", ".xls"),
        Seed(_IEMA / "distinta-componenti.xlsx", "workbook", ".ods"),
    ),
    "cable-info": (Seed(_ELIMCO / "cable_info.xml", "xml"),),
    "component-list": (Seed(_IEMA / "component-list.csv", "text"),),
    "component-model": (Seed(DATA / "cells" / "mini" / "models.xml", "xml"),),
    "connection-list": (
        Seed(DATA / "cells" / "mini" / "connections.tsv", "text"),
        Seed(_IEMA / "lista-cablaggio.csv", "text"),
        Seed(_IEMA / "lista-cablaggio.xlsx", "workbook", ".xlsx"),
        Seed(_IEMA / "lista-cablaggio.xlsx", "workbook", ".xls"),
        Seed(_IEMA / "lista-cablaggio.xlsx", "workbook", ".ods"),
        Seed(None, "xml", ".xml"),
    ),
    "elimco-cable-list": (
        Seed(_ELIMCO / "cable-list.xlsx", "workbook", ".xlsx"),
        Seed(_ELIMCO / "cable-list.xlsx", "workbook", ".ods"),
    ),
    "elvez-components": (Seed(_ELVEZ / "Components_definition.csv", "text"),),
    "elvez-definitions": (Seed(_ELVEZ / "Jigs_definition_v2.xml", "xml"),),
    "elvez-harnesses": (Seed(_ELVEZ / "WH_configuration.xml", "xml"),),
    "elvez-ids": (Seed(_ELVEZ / "platform_ids.wri", "text"),),
    "elvez-mesh": (Seed(_ELVEZ / "stl" / "platform" / "0011.STL", "stl"),),
    "elvez-scene": (Seed(_ELVEZ / "platform_cad.x3d", "xml"),),
    "elvez-sequence": (Seed(_ELVEZ / "Assembly_sequence.csv", "text"),),
    "harness-text": (Seed(EXAMPLES / "vw-harness" / "door-l.harness", "text"),),
    "hose": (Seed(EXAMPLES / "enki-hose" / "hoses.csv", "text"),),
    "kbl": (Seed(DATA / "kbl" / "two-core-fixing-tape.kbl", "xml"),),
    "marker-table": (
        Seed(_IEMA / "qr-markers.ods", "workbook", ".ods"),
        Seed(_IEMA / "qr-markers.ods", "workbook", ".xlsx"),
        Seed(_IEMA / "qr-markers.ods", "workbook", ".xls"),
    ),
    "parts-management": (Seed(_IEMA / "pins.xml", "xml"),),
    "path-info": (Seed(_ELIMCO / "path_info.xml", "xml"),),
    "pin-info": (Seed(_ELIMCO / "pin_info.xml", "xml"),),
    "terminal-diagram": (
        Seed(_IEMA / "terminals.xlsx", "workbook", ".xlsx"),
        Seed(_IEMA / "terminals.xlsx", "workbook", ".xls"),
        Seed(_IEMA / "terminals.xlsx", "workbook", ".ods"),
    ),
    "terminal-schema": (
        Seed(DATA / "cells" / "mini" / "terminals.csv", "text"),
        Seed(_IEMA / "schema-morsetti.ods", "workbook", ".ods"),
        Seed(_IEMA / "schema-morsetti.ods", "workbook", ".xlsx"),
    ),
    "vec": (Seed(DATA / "vec" / "harness-1.1.vec", "xml"),),
    "vrml": (Seed(DATA / "readers" / "scene" / "cell.wrl", "vrml"),),
    "wri": (Seed(EXAMPLES / "bad-cell" / "ids.wri", "text"),),
    "x3d": (Seed(DATA / "readers" / "scene" / "cell.x3d", "xml"),),
}
"""Every reader kind's seeds; a kind the registry declares without one fails a test."""

_TEXT = ("tiny-rows", "repeated-rows", "long-row", "many-columns", "long-numbers", "open-quote")
_XML = (
    "tiny-rows",
    "repeated-rows",
    "long-value",
    "many-attributes",
    "deep-nesting",
    "nested-200",
    "long-numbers",
    "long-integers",
)
_SCENE = ("def-use",)
_VRML = ("tiny-nodes", "deep-nesting", "def-use", "long-numbers", "many-points", "long-token")
_STL = ("many-triangles", "ascii-facets", "long-numbers", "count-lie", "long-row")
_WORKBOOK = ("tiny-rows", "repeated-rows", "long-cells", "many-columns", "long-numbers", "sparse-far")
_XLSX_ONLY = ("shared-strings", "huge-index")


# Modules an attack's path imports that reading the seed does not: the ELVEZ platform seed has
# no primitive shape, its attacks a Box, whose mesh is built with trimesh (0.3 s to import, a
# cost once per read and not per byte). Imported before the forks like the seed's own.
_WARM: dict[str, tuple[str, ...]] = {"elvez-scene": ("trimesh",)}


def _families(kind: str, seed: Seed) -> tuple[str, ...]:
    if seed.form == "text":
        return _TEXT
    if seed.form == "xml":
        return _XML + (_SCENE if kind in ("x3d", "elvez-scene") else ())
    if seed.form == "vrml":
        return _VRML
    if seed.form == "stl":
        return _STL
    return _WORKBOOK + (_XLSX_ONLY if seed.suffix == ".xlsx" else ())


def _suffix(seed: Seed) -> str:
    return seed.suffix or (seed.path.suffix if seed.path is not None else "")


FAMILIES: dict[str, tuple[str, ...]] = {
    kind: tuple(f"{_suffix(s).lstrip('.').lower()}-{f}" for s in seeds for f in _families(kind, s))
    for kind, seeds in SEEDS.items()
}
"""Every kind's families, named ``<suffix>-<shape>``: what the tests parametrize over."""


# --- text: CSV, TSV, WRI, the VW harness text ------------------------------------------------------


def _lines(seed: Path) -> list[str]:
    raw = seed.read_bytes()
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")
    return text.splitlines()


def _data_line(lines: Sequence[str]) -> str:
    """The seed's last line that is a row (not blank, not a comment)."""
    return next(line for line in reversed(lines) if line.strip() and not line.lstrip().startswith("#"))


def _delimiter(line: str) -> str:
    return next((d for d in ("\t", ";", ",") if d in line), " ")


def _numbered(line: str, n: int) -> str:
    """``line`` with its first run of digits replaced by ``n`` (a row of its own, not a copy)."""
    return re.sub(r"\d+", str(n), line, count=1) if re.search(r"\d", line) else f"{line}{n}"


def _noise(rng: random.Random, length: int) -> str:
    """``length`` characters that do not compress (hexadecimal digits)."""
    return rng.randbytes(max(0, length) // 2 + 1).hex().upper()[: max(0, length)]


def _fill(head: str, row: Callable[[int], str], size: int) -> str:
    parts, total, n = [head], len(head), 0
    while total < size:
        line = row(n) + "\n"
        parts.append(line)
        total += len(line)
        n += 1
    return "".join(parts)


def _text_attack(seed: Path, family: str, size: int, rng: random.Random) -> bytes:
    lines = _lines(seed)
    head = "\n".join(lines) + "\n"
    row = _data_line(lines)
    delimiter = _delimiter(row)
    fields = row.split(delimiter)
    if family == "tiny-rows":
        # The row cut to its first fields: the least text a reader still takes as a row.
        short = delimiter.join(fields[: max(2, len(fields) // 3)])
        text = _fill(head, lambda n: _numbered(short, 10_000 + n), size)
    elif family == "repeated-rows":
        text = _fill(head, lambda n: row, size)
    elif family == "long-row":
        longest = max(range(len(fields)), key=lambda i: len(fields[i]))
        grown = [*fields]
        grown[longest] += _noise(rng, size - len(head))
        text = head + delimiter.join(grown) + "\n"
    elif family == "many-columns":
        extra = max(1, (size - len(head)) // 4)
        header = lines[0] + "".join(f"{delimiter}c{i}" for i in range(extra // 6))
        text = "\n".join([header, *lines[1:]]) + "\n" + row + f"{delimiter}1" * (extra // 2) + "\n"
    elif family == "long-numbers":
        text = _fill(head, lambda n: re.sub(r"\d+", lambda m: str(n % 10 or 1) * _DIGITS, row), size)
    elif family == "open-quote":
        # A quoted field that never closes: a CSV parser takes the rest of the file as one field.
        text = _fill(head + '"' + row + "\n", lambda n: row, size)
    else:
        raise KeyError(family)
    return text.encode()


# --- XML: KBL, VEC, X3D, EPLAN and route-design exports ---------------------------------------------


def _labelling_seed(directory: Path) -> Path:
    from tests.ingest.test_eplan_exports import WIRE, WIRING_COLUMNS, _labelling

    second = [*WIRE]
    second[2], second[5], second[6] = "=-X1600:2:a", "=-Q1500.1:A2", "1500.52"
    path = directory / "labelling-seed.xml"
    path.write_bytes(_labelling({"Nome progetto": "DEMO", "Commessa": "1"}, WIRING_COLUMNS, [WIRE, second]))
    return path


def _parse(seed: Path) -> Any:
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, remove_blank_text=True)
    return etree.parse(str(seed), parser)


def _row(tree: Any) -> Any:
    """The element the file is a list of: the smallest child of the tag a parent holds most of."""
    best: tuple[int, int, Any] | None = None
    for parent in tree.getroot().iter():
        tags: dict[str, list[Any]] = {}
        for child in parent:
            if isinstance(child.tag, str):
                tags.setdefault(child.tag, []).append(child)
        for children in tags.values():
            smallest = min(children, key=lambda e: len(etree.tostring(e)))
            score = (len(children), -len(etree.tostring(smallest)))
            if best is None or score > best[:2]:
                best = (*score, smallest)
    assert best is not None, "a seed of one element"
    return best[2]


def _serialise(tree: Any) -> bytes:
    return etree.tostring(tree, xml_declaration=True, encoding="utf-8")


def _splice(tree: Any, row: Any, repeat: Callable[[int], bytes], size: int) -> bytes:
    """The document with ``repeat(n)`` for n = 0, 1, ... put after ``row`` until it is ``size``."""
    marker = etree.Comment("ATTACK")
    row.addnext(marker)
    before, after = _serialise(tree).split(b"<!--ATTACK-->", 1)
    marker.getparent().remove(marker)
    parts, total, n = [before], len(before) + len(after), 0
    while total < size:
        chunk = repeat(n)
        parts.append(chunk)
        total += len(chunk)
        n += 1
    parts.append(after)
    return b"".join(parts)


def _xml_attack(kind: str, seed: Path, family: str, size: int, rng: random.Random) -> bytes:
    tree = _parse(seed)
    row = _row(tree)
    plain = etree.tostring(row, with_tail=False)
    tag = etree.QName(row).localname
    start = plain.split(b">", 1)[0].split(b" ", 1)[0][1:]  # the tag as written (its prefix kept)
    if family == "tiny-rows":
        bare = etree.Element(row.tag, {k: v for k, v in list(row.attrib.items())[:2]})
        template = etree.tostring(bare)

        def tiny(n: int) -> bytes:
            return re.sub(rb'="([^"]*)"', lambda m: b'="' + m.group(1) + b"_%d" % n + b'"', template, count=1)

        return _splice(tree, row, tiny, size)
    if family == "repeated-rows":
        return _splice(tree, row, lambda n: plain, size)
    if family == "long-value":
        name = next(iter(row.attrib), None)
        value = _noise(rng, size)
        if name is None:
            row.text = value
        else:
            row.set(name, value)
        return _serialise(tree)
    if family == "many-attributes":
        # Put in as text: lxml looks through an element's attributes at each one it sets.
        row.set("attacked", "1")
        many = b" ".join(b'a%d="1"' % i for i in range(size // 10))
        return _serialise(tree).replace(b'attacked="1"', many, 1)
    if family == "deep-nesting":
        depth = max(1, size // (2 * len(start) + 5))
        chain = (b"<%s>" % start) * depth + (b"</%s>" % start) * depth
        return _splice(tree, row, lambda n: chain, len(_serialise(tree)) + 1)
    if family == "nested-200":
        chain = (b"<%s>" % start) * 200 + plain + (b"</%s>" % start) * 200
        return _splice(tree, row, lambda n: chain, size)
    if family == "long-numbers":
        # Every number of the row thousands of digits long, and the row again until the size.
        for element in row.iter():
            if not isinstance(element.tag, str):
                continue
            for name, value in element.attrib.items():
                if _NUMBERS.fullmatch(value) and re.search(r"\d", value):
                    element.set(name, re.sub(r"\d+", "9" * _DIGITS, value))
            if element.text and _NUMBERS.fullmatch(element.text.strip()) and re.search(r"\d", element.text):
                element.text = re.sub(r"\d+", "9" * _DIGITS, element.text)
        copy = etree.tostring(row, with_tail=False)
        return _splice(tree, row, lambda n: copy, size)
    if family == "long-integers":
        # Every whole number written as an element's text (counts, degrees, indices), anywhere.
        for element in tree.getroot().iter():
            if isinstance(element.tag, str) and element.text and element.text.strip().isdigit():
                element.text = "9" * _DIGITS
        return _serialise(tree)
    if family == "def-use":
        # One DEF'd shape, USEd over and over in one flat group.
        shape = b'<Group DEF="ATTACKED"><Shape><Box size="1 1 1"/></Shape></Group>'
        use = b'<Transform translation="1 0 0"><Group USE="ATTACKED"/></Transform>'
        scene = tree.getroot().find(".//Scene")
        anchor = scene[len(scene) - 1] if scene is not None and len(scene) else row
        first = [True]

        def uses(n: int) -> bytes:
            if first[0]:
                first[0] = False
                return shape
            return use

        return _splice(tree, anchor, uses, size)
    raise KeyError((kind, family, tag))


# --- VRML97 -------------------------------------------------------------------------------------------


def _vrml_attack(seed: Path, family: str, size: int, rng: random.Random) -> bytes:
    head = seed.read_text(encoding="utf-8") + "\n"
    if family == "tiny-nodes":
        text = _fill(head, lambda n: f"DEF N{n} Transform {{ }}", size)
    elif family == "deep-nesting":
        depth = max(1, (size - len(head)) // 32)
        text = head + "Group { children [ " * depth + "] } " * depth + "\n"
    elif family == "def-use":
        text = _fill(
            head + "DEF ATTACKED Shape { geometry Box { size 1 1 1 } }\n",
            lambda n: "Transform { children [ USE ATTACKED ] }",
            size,
        )
    elif family == "long-numbers":
        text = _fill(head, lambda n: f"DEF L{n} Transform {{ translation {'9' * _DIGITS} 0 0 }}", size)
    elif family == "many-points":
        count = max(3, (size - len(head)) // 24)
        points = ", ".join(f"{n % 97} {n % 89} {n % 83}" for n in range(count))
        faces = ", ".join(f"{n} {n + 1} {n + 2} -1" for n in range(0, count - 2, 3))
        text = (
            head
            + "DEF MESH Transform { children [ Shape { geometry IndexedFaceSet { coord Coordinate { point [ "
            + points
            + " ] } coordIndex [ "
            + faces
            + " ] } } ] }\n"
        )
    elif family == "long-token":
        text = head + "DEF " + "X" * max(1, size - len(head)) + " Transform { }\n"
    else:
        raise KeyError(family)
    return text.encode()


# --- STL ---------------------------------------------------------------------------------------------


def _stl_attack(seed: Path, family: str, size: int, rng: random.Random) -> bytes:
    if family == "many-triangles":
        count = max(1, (size - 84) // 50)
        facets = b"".join(
            struct.pack("<12fH", 0, 0, 1, n, 0, 0, n + 1, 0, 0, n, 1, 0, 0) for n in range(count)
        )
        return b"\0" * 80 + struct.pack("<I", count) + facets
    if family == "count-lie":
        # A header that claims four thousand million triangles, and one.
        return b"\0" * 80 + struct.pack("<I", 0xFFFFFFFF) + struct.pack("<12fH", *[0.0] * 12, 0)

    def facet(n: int, number: str = "") -> str:
        x = number or str(n)
        return (
            f"facet normal 0 0 1\nouter loop\nvertex {x} 0 0\nvertex {x} 1 0\nvertex 0 {x} 0\n"
            "endloop\nendfacet\n"
        )

    if family == "ascii-facets":
        text = _fill("solid attacked\n", facet, size - 20) + "endsolid attacked\n"
    elif family == "long-numbers":
        text = _fill("solid attacked\n", lambda n: facet(n, "9" * _DIGITS), size - 20) + "endsolid attacked\n"
    elif family == "long-row":
        text = "solid attacked\nfacet normal 0 0 1 " + "0 " * (size // 2) + "\nendsolid attacked\n"
    else:
        raise KeyError(family)
    return text.encode()


# --- workbooks: XLSX, XLS, ODS ------------------------------------------------------------------------

Rows = list[list[object]]
_XLSX_MAIN = "http://schemas.openxmlformats.org/spreadsheetml/2006/main"


def _seed_rows(seed: Path) -> tuple[str, Rows]:
    import python_calamine

    book = python_calamine.CalamineWorkbook.from_path(str(seed))
    for name in book.sheet_names:
        rows = book.get_sheet_by_name(name).to_python()
        if rows:
            return name, [list(r) for r in rows]
    raise AssertionError(f"{seed}: no sheet with a value")


def _cell_size(value: object) -> int:
    return len(str(value)) + 30


def _workbook_rows(rows: Rows, family: str, size: int, rng: random.Random) -> tuple[Rows, bool]:
    """The rows of a workbook attack, and whether its last value sits far from the others."""
    data = next(r for r in reversed(rows) if any(v not in ("", None) for v in r))
    out = [list(r) for r in rows]
    total = 0  # what is added to the seed's rows

    def extend(make: Callable[[int], list[object]]) -> None:
        nonlocal total
        n = 0
        while total < size:
            row = make(n)
            out.append(row)
            total += sum(_cell_size(v) for v in row)
            n += 1

    if family == "tiny-rows":
        extend(lambda n: [_numbered(str(v), 10_000 + n) if i == 0 else v for i, v in enumerate(data[:2])])
    elif family == "repeated-rows":
        extend(lambda n: list(data))
    elif family == "long-cells":
        # Each cell within the 32,767 characters a cell may hold.
        extend(lambda n: [_noise(rng, 32_000) for _ in data])
    elif family == "many-columns":
        width = min(16_000, max(1, size // 40))
        out[0] = [*out[0], *(f"c{i}" for i in range(width))]
        out.append([*data, *([1] * width)])
    elif family == "long-numbers":
        extend(lambda n: [("9" * 300 + ".5" if isinstance(v, float) else v) for v in data])
        out.append(["1e308", 1e308, float("1e308"), "9" * _DIGITS])
    elif family == "sparse-far":
        return out, True
    elif family in ("shared-strings", "huge-index"):
        extend(lambda n: [str(v) or "x" for v in data])
    else:
        raise KeyError(family)
    return out, False


def _column(index: int) -> str:
    letters = ""
    index += 1
    while index:
        index, rest = divmod(index - 1, 26)
        letters = chr(65 + rest) + letters
    return letters


def _write_xlsx(path: Path, name: str, rows: Rows, far: bool, shared: bool, huge: bool = False) -> Path:
    strings: dict[str, int] = {}
    parts = [f'<?xml version="1.0"?><worksheet xmlns="{_XLSX_MAIN}"><sheetData>']
    for r, row in enumerate(rows, start=1):
        cells = []
        for c, value in enumerate(row):
            if value in ("", None):
                continue
            ref = f"{_column(c)}{r}"
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                cells.append(f'<c r="{ref}"><v>{value!r}</v></c>')
            elif shared:
                index = str(strings.setdefault(str(value), len(strings)))
                if huge and r > len(rows) // 2:  # an index into the strings thousands of digits long
                    index = "9" * _DIGITS
                cells.append(f'<c r="{ref}" t="s"><v>{index}</v></c>')
            else:
                cells.append(f'<c r="{ref}" t="inlineStr"><is><t>{escape(str(value))}</t></is></c>')
        parts.append(f'<row r="{r}">{"".join(cells)}</row>')
    if far:
        parts.append('<row r="1048576"><c r="XFD1048576"><v>1</v></c></row>')
    parts.append("</sheetData></worksheet>")
    rel = "http://schemas.openxmlformats.org/officeDocument/2006/relationships"
    package = "http://schemas.openxmlformats.org/package/2006/relationships"
    members: list[tuple[str, list[tuple[bytes, int]]]] = [
        (
            "[Content_Types].xml",
            [
                (
                    b'<?xml version="1.0"?><Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types"/>',
                    1,
                )
            ],
        ),
        (
            "_rels/.rels",
            [
                (
                    f'<?xml version="1.0"?><Relationships xmlns="{package}"><Relationship Id="rId1" '
                    f'Type="{rel}/officeDocument" Target="xl/workbook.xml"/></Relationships>'.encode(),
                    1,
                )
            ],
        ),
        (
            "xl/workbook.xml",
            [
                (
                    f'<?xml version="1.0"?><workbook xmlns="{_XLSX_MAIN}" xmlns:r="{rel}"><sheets>'
                    f'<sheet name={quoteattr(name)} sheetId="1" r:id="rId1"/></sheets></workbook>'.encode(),
                    1,
                )
            ],
        ),
        (
            "xl/_rels/workbook.xml.rels",
            [
                (
                    f'<?xml version="1.0"?><Relationships xmlns="{package}">'
                    f'<Relationship Id="rId1" Type="{rel}/worksheet" Target="worksheets/sheet1.xml"/>'
                    f'<Relationship Id="rId2" Type="{rel}/sharedStrings" Target="sharedStrings.xml"/>'
                    "</Relationships>".encode(),
                    1,
                )
            ],
        ),
        ("xl/worksheets/sheet1.xml", [("".join(parts).encode(), 1)]),
    ]
    if shared:
        sst = "".join(f"<si><t>{escape(s)}</t></si>" for s in strings)
        members.append(
            (
                "xl/sharedStrings.xml",
                [
                    (
                        f'<?xml version="1.0"?><sst xmlns="{_XLSX_MAIN}" count="{len(strings)}">'
                        f"{sst}</sst>".encode(),
                        1,
                    )
                ],
            )
        )
    return write_zip(path, members)


def _write_ods(path: Path, name: str, rows: Rows, far: bool) -> Path:
    office = "urn:oasis:names:tc:opendocument:xmlns:office:1.0"
    table = "urn:oasis:names:tc:opendocument:xmlns:table:1.0"
    textns = "urn:oasis:names:tc:opendocument:xmlns:text:1.0"
    parts = [
        f'<?xml version="1.0"?><office:document-content xmlns:office="{office}" xmlns:table="{table}" '
        f'xmlns:text="{textns}"><office:body><office:spreadsheet><table:table table:name={quoteattr(name)}>'
    ]
    for row in rows:
        cells = []
        for value in row:
            if value in ("", None):
                cells.append("<table:table-cell/>")
            elif isinstance(value, (int, float)) and not isinstance(value, bool):
                cells.append(
                    f'<table:table-cell office:value-type="float" office:value="{value!r}">'
                    f"<text:p>{value!r}</text:p></table:table-cell>"
                )
            else:
                cells.append(
                    '<table:table-cell office:value-type="string">'
                    f"<text:p>{escape(str(value))}</text:p></table:table-cell>"
                )
        parts.append(f"<table:table-row>{''.join(cells)}</table:table-row>")
    if far:
        parts.append(
            '<table:table-row table:number-rows-repeated="1048000"><table:table-cell/></table:table-row>'
            '<table:table-row><table:table-cell table:number-columns-repeated="16000"/>'
            '<table:table-cell office:value-type="float" office:value="1">'
            "<text:p>1</text:p></table:table-cell>"
            "</table:table-row>"
        )
    parts.append("</table:table></office:spreadsheet></office:body></office:document-content>")
    content = "".join(parts).encode()
    write_ods(path, [(name[:31], [["a"]])])
    with zipfile.ZipFile(path) as archive:
        members = [(info, archive.read(info)) for info in archive.infolist()]
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for info, data in members:
            archive.writestr(info, content if info.filename == "content.xml" else data)
    return path


def _write_xls(path: Path, name: str, rows: Rows, far: bool) -> Path:
    cells = grid([[None if v == "" else v for v in r[:255]] for r in rows[:65_000]])
    if far:
        cells.append((65_535, 255, 1.0))
    # Text cells beyond what BIFF8 holds in one record are cut, as Excel would refuse them.
    cells = [(r, c, v[:8000] if isinstance(v, str) else v) for r, c, v in cells]
    return write_xls(path, [(name[:31], cells)])


def _workbook_attack(seed: Seed, family: str, size: int, path: Path, rng: random.Random) -> Path:
    assert seed.path is not None
    name, rows = _seed_rows(seed.path)
    rows, far = _workbook_rows(rows, family, size, rng)
    if seed.suffix == ".xlsx":
        shared = family in ("shared-strings", "huge-index")
        return _write_xlsx(path, name, rows, far, shared, family == "huge-index")
    if seed.suffix == ".ods":
        return _write_ods(path, name, rows, far)
    return _write_xls(path, name, rows, far)


# --- all of them ---------------------------------------------------------------------------------------


def attacks(kind: str, directory: Path, size: int) -> list[Attack]:
    """The seed of ``kind`` (family ``seed``) and every attack on it, of about ``size`` bytes
    (a workbook's sheet XML or records before compression), written into ``directory``."""
    directory.mkdir(parents=True, exist_ok=True)
    out: list[Attack] = []
    for seed in SEEDS[kind]:
        source = seed.path if seed.path is not None else _labelling_seed(directory)
        suffix = _suffix(seed)
        label = suffix.lstrip(".").lower()
        for family in ("seed", *_families(kind, seed)):
            rng = random.Random(f"{kind}-{label}-{family}-{size}")
            path = directory / f"{kind}-{label}-{family}{suffix}"
            if family == "seed" and seed.form != "workbook":
                path.write_bytes(source.read_bytes())
            elif seed.form == "workbook":
                _workbook_attack(
                    seed,
                    "repeated-rows" if family == "seed" else family,
                    0 if family == "seed" else size,
                    path,
                    rng,
                )
            elif seed.form == "text":
                path.write_bytes(_text_attack(source, family, size, rng))
            elif seed.form == "xml":
                path.write_bytes(_xml_attack(kind, source, family, size, rng))
            elif seed.form == "vrml":
                path.write_bytes(_vrml_attack(source, family, size, rng))
            else:
                path.write_bytes(_stl_attack(source, family, size, rng))
            out.append(Attack(kind, f"{label}-{family}", path))
    return out


# --- measuring -----------------------------------------------------------------------------------------

# Run in a fresh process: every case is read in a process forked for it, whose only child is
# the limited child that reads the file, so RUSAGE_CHILDREN is that child's alone.
_MEASURE = r"""
import json, os, resource, sys, time
from cadkg.errors import CadkgError
from cadkg.limited import read_limited
from cadkg.registry import reader_for
from tests.security.reference_loop import reference_seconds

def rss():
    with open("/proc/self/status", "rb") as status:
        return next(int(line.split()[1]) for line in status if line.startswith(b"VmRSS:"))

def this_cpu():
    with open("/proc/self/stat") as stat:
        return int(stat.read().rsplit(")", 1)[1].split()[36])

def case(kind, path):
    reader = reader_for(kind)
    read = reader.stream or reader.read
    readable, writable = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(readable)
        # The read and the reference loop timed before and after it on one CPU, the one the
        # case starts on: on a shared machine one CPU can be twice as slow as the other for a
        # while (its sibling thread busy).
        os.sched_setaffinity(0, {this_cpu()})
        ahead = reference_seconds()
        before = rss()
        started = time.monotonic()
        records = 0
        try:
            for _ in read_limited(path, read, path):
                records += 1
            message = ""
        except CadkgError as err:
            message = str(err)
        except BaseException as err:
            message = "TRACEBACK " + type(err).__name__ + ": " + str(err)[:300]
        usage = resource.getrusage(resource.RUSAGE_CHILDREN)
        wall = time.monotonic() - started
        reference = (ahead + reference_seconds()) / 2
        found = {"message": message, "records": records, "wall": wall, "reference": reference,
                 "cpu": usage.ru_utime + usage.ru_stime, "peak": usage.ru_maxrss - before}
        with os.fdopen(writable, "w") as out:
            out.write(json.dumps(found))
        os._exit(0)
    os.close(writable)
    with os.fdopen(readable) as incoming:
        text = incoming.read()
    os.waitpid(pid, 0)
    return json.loads(text)

reference_seconds()  # the loop warmed here once: every case's fork starts warm
for kind, path, warm in json.loads(sys.argv[1]):
    if warm is not None:  # the reader's modules imported before the forks, as a build has them by then
        for module in warm:
            __import__(module)
        reader = reader_for(kind)
        try:
            list((reader.stream or reader.read)(path))
        except CadkgError:
            pass
    print(json.dumps({"kind": kind, "path": path, **case(kind, path)}), flush=True)
"""


@dataclass(frozen=True)
class Measured:
    """What reading one attack took, against what reading its seed took."""

    attack: Attack
    size: int  # bytes of the file
    message: str  # "" when it was read, else the one line it was refused with
    records: int
    peak: int  # bytes of peak resident memory above the seed's
    cpu: float  # CPU seconds above the seed's
    loops: float  # CPU time above the seed's in reference loops (tests.security.reference_loop)
    wall: float

    @property
    def bytes_per_byte(self) -> float:
        return self.peak / self.size

    @property
    def seconds_per_mib(self) -> float:
        return self.cpu / (self.size / (1 << 20))

    @property
    def loops_per_mib(self) -> float:
        return self.loops / (self.size / (1 << 20))


def measure(
    cases: Sequence[Attack], *, limit_mib: int = 256, cpu_s: int = 20, wall_s: int = 40, timeout: float = 600
) -> list[Measured]:
    """Every case read as a build reads it, in a fresh process (killed with its group past
    ``timeout``), under the given read limits; each family's figures less its seed's."""
    env = {
        **os.environ,
        "CADKG_READ_LIMIT_MIB": str(limit_mib),
        "CADKG_READ_CPU_S": str(cpu_s),
        "CADKG_READ_WALL_S": str(wall_s),
        "PYTHONPATH": os.pathsep.join([str(ROOT / "src"), str(ROOT), os.environ.get("PYTHONPATH", "")]),
    }
    spec = json.dumps(
        [(c.kind, str(c.path), _WARM.get(c.kind, ()) if c.family.endswith("-seed") else None) for c in cases]
    )
    out = run_child([sys.executable, "-c", _MEASURE, spec], timeout, "reading the attacks", env)
    found = {(r["kind"], r["path"]): r for r in map(json.loads, out.splitlines())}
    results, seeds = [], {}
    for attack in cases:
        got = found[(attack.kind, str(attack.path))]
        label = attack.family.rsplit("-", 1)[0] if attack.family.endswith("-seed") else None
        if label is not None:
            seeds[(attack.kind, label)] = got
            continue
        base = seeds.get(
            (attack.kind, attack.family.split("-", 1)[0]), {"peak": 0, "cpu": 0.0, "reference": 1.0}
        )
        size = attack.path.stat().st_size
        results.append(
            Measured(
                attack=attack,
                size=size,
                message=got["message"],
                records=got["records"],
                peak=max(0, got["peak"] - base["peak"]) * 1024,
                cpu=max(0.0, got["cpu"] - base["cpu"]),
                loops=max(0.0, got["cpu"] / got["reference"] - base["cpu"] / base["reference"]),
                wall=got["wall"],
            )
        )
    return results


def table(results: Sequence[Measured]) -> str:
    """The results as a Markdown table."""
    lines = [
        "| reader | family | bytes | bytes/byte | s/MiB | loops/MiB | outcome |",
        "| --- | --- | ---: | ---: | ---: | ---: | --- |",
    ]
    for r in results:
        outcome = (
            f"read, {r.records} records" if not r.message else "refused: " + r.message.split(": ", 1)[-1][:70]
        )
        lines.append(
            f"| {r.attack.kind} | {r.attack.family} | {r.size:,} | {r.bytes_per_byte:.1f} | "
            f"{r.seconds_per_mib:.2f} | {r.loops_per_mib:.0f} | {outcome} |"
        )
    return "\n".join(lines)


def _main(argv: Sequence[str]) -> None:
    import tempfile

    size = int(argv[0]) << 10 if argv else 64 << 10
    with tempfile.TemporaryDirectory() as directory:
        cases = [a for kind in sorted(SEEDS) for a in attacks(kind, Path(directory) / kind, size)]
        results = measure(cases, timeout=3600)
        print(table(results))
        worst: dict[str, tuple[Measured, Measured]] = {}
        for r in results:
            memory, time = worst.get(r.attack.kind, (r, r))
            worst[r.attack.kind] = (
                max(memory, r, key=lambda m: m.bytes_per_byte),
                max(time, r, key=lambda m: m.loops_per_mib),
            )
        print()
        print("| reader | worst bytes/byte (family) | worst loops/MiB (family, s/MiB) |")
        print("| --- | ---: | ---: |")
        for kind, (memory, time) in sorted(worst.items()):
            print(
                f"| {kind} | {memory.bytes_per_byte:.1f} ({memory.attack.family}) | "
                f"{time.loops_per_mib:.0f} ({time.attack.family}, {time.seconds_per_mib:.2f}) |"
            )


if __name__ == "__main__":
    _main(sys.argv[1:])
