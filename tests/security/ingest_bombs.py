"""Input files that would take gigabytes to read, in variants drawn from a seeded generator.

Each class holds one way of making a small file expand: a workbook whose parts are named in
a namespace or with a prefix binding a scan might not expect, a string shown in many cells, a
scene whose DEF'd groups are USEd again on every level, and text too large to hold. The
variants change what a recogniser would look at (namespaces, prefixes, sizes, depths, kinds),
not what the reading costs.
"""

from __future__ import annotations

import random
import zipfile
from collections.abc import Callable
from pathlib import Path

from tests.ingest.biff import write_xls
from tests.ingest.workbooks import write_ods, write_zip

__all__ = ["BOMBS", "Bomb"]

# (file, the kind a manifest would give it or None, the profile of its cell)
Bomb = tuple[Path, str | None, str]

_TRANSITIONAL = "http://schemas.openxmlformats.org/spreadsheetml/2006/main"
_STRICT = "http://purl.oclc.org/ooxml/spreadsheetml/main"
_R = "http://schemas.openxmlformats.org/officeDocument/2006/relationships"
_R_STRICT = "http://purl.oclc.org/ooxml/officeDocument/relationships"
_PACKAGE = "http://schemas.openxmlformats.org/package/2006/relationships"
# Workbooks are read as what a manifest would call them: the sniff reads them too (see the tests).
_SHEET_KIND = "connection-list"


def _xlsx(
    path: Path, rng: random.Random, sheet: list[tuple[bytes, int]], strings: list[tuple[bytes, int]] | None
) -> Path:
    main = rng.choice([_TRANSITIONAL, _STRICT])
    r_space = rng.choice([_R, _R_STRICT])
    prefix = rng.choice(["r", "rel", "x"])
    # The r: prefix bound to another namespace on the sheet element, the id under another prefix.
    rebound = rng.random() < 0.4
    attribute = f'{prefix}:id="rId1"'
    if rebound:
        attribute = f'r:id="rId1" xmlns:r="urn:example:{rng.randrange(1000)}" {prefix}2:id="rId1"'
        prefix = f"{prefix}2"
    workbook = (
        f'<?xml version="1.0"?><workbook xmlns="{main}" xmlns:{prefix}="{r_space}"><sheets>'
        f'<sheet name="S{rng.randrange(99)}" sheetId="1" {attribute}/></sheets></workbook>'
    ).encode()
    kind_base = r_space if rng.random() < 0.5 else _R
    rels = [f'<Relationship Id="rId1" Type="{kind_base}/worksheet" Target="worksheets/sheet1.xml"/>']
    if strings is not None:
        rels.append(f'<Relationship Id="rId2" Type="{kind_base}/sharedStrings" Target="sharedStrings.xml"/>')
    rels_prefix = rng.choice(["", "p:"])
    space = f'xmlns{":p" if rels_prefix else ""}="{_PACKAGE}"'
    rels_xml = f'<?xml version="1.0"?><{rels_prefix}Relationships {space}>'
    rels_xml += "".join(r.replace("<Relationship", f"<{rels_prefix}Relationship") for r in rels)
    rels_xml += f"</{rels_prefix}Relationships>"
    head = f'<?xml version="1.0"?><worksheet xmlns="{main}"><sheetData>'.encode()
    members = [
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
                    f'<?xml version="1.0"?><Relationships xmlns="{_PACKAGE}"><Relationship Id="rId1" '
                    f'Type="{kind_base}/officeDocument" Target="xl/workbook.xml"/></Relationships>'.encode(),
                    1,
                )
            ],
        ),
        ("xl/workbook.xml", [(workbook, 1)]),
        ("xl/_rels/workbook.xml.rels", [(rels_xml.encode(), 1)]),
        ("xl/worksheets/sheet1.xml", [(head, 1), *sheet, (b"</sheetData></worksheet>", 1)]),
    ]
    if strings is not None:
        members.append(("xl/sharedStrings.xml", strings))
    return write_zip(path, members)


def _far_cell(directory: Path, rng: random.Random) -> Bomb:
    """One value far down and right: the library builds the sheet as a block from A1."""
    row = rng.randrange(300_000, 1_048_577)
    column = rng.choice(["XFD", "ZZ", "AMJ", "XAA"])
    cells = (
        f'<row r="1"><c r="A1" t="inlineStr"><is><t>Label</t></is></c></row>'
        f'<row r="{row}"><c r="{column}{row}"><v>1</v></c></row>'
    ).encode()
    return _xlsx(directory / f"far-{rng.randrange(10**6)}.xlsx", rng, [(cells, 1)], None), _SHEET_KIND, ""


def _shared_string(directory: Path, rng: random.Random) -> Bomb:
    """One long shared string shown in every cell of a sheet, each within a sheet's limits."""
    length = rng.randrange(16_000, 32_768)
    cells = rng.randrange(25_000, 40_000)
    width = rng.choice([1, 8, 30])
    strings = [
        (
            b'<?xml version="1.0"?><sst xmlns="'
            + _TRANSITIONAL.encode()
            + b'" count="1" uniqueCount="1"><si><t>',
            1,
        ),
        (rng.choice([b"x", b"ab", b"\xc3\xa8"]) * (length // 2), 2),
        (b"</t></si></sst>", 1),
    ]
    rows = []
    for row in range(1, cells // width + 1):
        rows.append(b'<row r="%d">' % row + b'<c t="s"><v>0</v></c>' * width + b"</row>")
    return (
        _xlsx(directory / f"shared-{rng.randrange(10**6)}.xlsx", rng, [(b"".join(rows), 1)], strings),
        _SHEET_KIND,
        "",
    )


def _xls_shared_string(directory: Path, rng: random.Random) -> Bomb:
    """The same in a legacy XLS: an SST of one long string and LABELSST cells showing it."""
    text = rng.choice(["x", "é"]) * rng.randrange(16_000, 32_768)
    width = rng.choice([1, 8, 30])
    cells = [(n // width, n % width, text) for n in range(rng.randrange(25_000, 40_000))]
    return write_xls(directory / f"shared-{rng.randrange(10**6)}.xls", [("S", cells)]), _SHEET_KIND, ""


def _ods_repeat(directory: Path, rng: random.Random) -> Bomb:
    """ODS: one long text repeated over columns and rows, the table: prefix bound where a scan
    might not look for it."""
    text = rng.choice(["y", "ü"]) * rng.randrange(20_000, 65_536)
    columns = rng.randrange(8_000, 16_000)
    rows = rng.choice([1, 2, 5])
    table = "urn:oasis:names:tc:opendocument:xmlns:table:1.0"
    office = "urn:oasis:names:tc:opendocument:xmlns:office:1.0"
    textns = "urn:oasis:names:tc:opendocument:xmlns:text:1.0"
    rebind = rng.choice(["", f' xmlns:table="urn:example:{rng.randrange(99)}"'])
    spaces = rng.choice(["", '<text:s text:c="60000"/>'])
    content = (
        f'<?xml version="1.0"?><office:document-content xmlns:office="{office}" xmlns:table="{table}" '
        f'xmlns:text="{textns}"><office:body><office:spreadsheet><table:table table:name="S">'
        f'<table:table-row table:number-rows-repeated="{rows}"{rebind}>'
        f'<table:table-cell table:number-columns-repeated="{columns}" office:value-type="string">'
        f"<text:p>{text}{spaces}</text:p></table:table-cell></table:table-row>"
        f"</table:table></office:spreadsheet></office:body></office:document-content>"
    ).encode()
    path = write_ods(directory / f"repeat-{rng.randrange(10**6)}.ods", [("S", [["a"]])])
    with zipfile.ZipFile(path) as archive:
        members = [(info, archive.read(info)) for info in archive.infolist()]
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for info, data in members:
            archive.writestr(info, content if info.filename == "content.xml" else data)
    return path, _SHEET_KIND, ""


def _scene(directory: Path, rng: random.Random) -> Bomb:
    """A scene whose every level USEs the DEF'd group below it two or three times."""
    levels = rng.randrange(16, 22)
    fan = rng.choice([2, 3]) if levels < 19 else 2
    leaf = rng.choice(['<Sphere radius="1"/>', '<Box size="1 1 1"/>', '<Cylinder radius="1" height="2"/>'])
    group = rng.choice(["Group", "Transform"])
    parts = ['<?xml version="1.0" encoding="UTF-8"?>\n<X3D profile="Immersive" version="3.3"><Scene>\n']
    parts.append('<Transform DEF="root">\n')
    parts.append(f'<Group DEF="L0"><Shape>{leaf}</Shape></Group>\n')
    for level in range(1, levels + 1):
        uses = "".join(
            f'<Transform translation="{n} 0 0"><{group} USE="L{level - 1}"/></Transform>' for n in range(fan)
        )
        parts.append(f'<Group DEF="L{level}">{uses}</Group>\n')
    parts.append("</Transform></Scene></X3D>\n")
    elvez = rng.random() < 0.7
    path = directory / f"{'platform' if elvez else 'scene'}{rng.randrange(10**6)}_cad.x3d"
    path.write_text("".join(parts))
    return path, "elvez-scene" if elvez else "x3d", "elvez" if elvez else "iema"


def _sparse_text(directory: Path, rng: random.Random) -> Bomb:
    """A text export gigabytes long (sparse: it takes no disk), of a kind read whole."""
    suffix, kind = rng.choice(
        [(".csv", "connection-list"), (".kbl", "kbl"), (".xml", "pin-info"), (".wri", "wri")]
    )
    path = directory / f"big-{rng.randrange(10**6)}{suffix}"
    with path.open("wb") as handle:
        handle.write(b"Numero filo;Componente:pin;Componente:pin\n")
        handle.truncate(rng.randrange(2, 4) << 30)
    return path, kind, "elimco" if kind == "pin-info" else ""


BOMBS: dict[str, Callable[[Path, random.Random], Bomb]] = {
    "xlsx-far-cell": _far_cell,
    "xlsx-shared-string": _shared_string,
    "xls-shared-string": _xls_shared_string,
    "ods-repeated-text": _ods_repeat,
    "x3d-def-use": _scene,
    "sparse-text": _sparse_text,
}
