"""Limits a workbook must keep before its sheets are read: checked on the XML, as it streams.

The workbook library builds each sheet as a dense block from A1 to its last cell and keeps
every shared string in memory. One cell in column XFD on each of 60,000 rows (a 100 KB file)
would make it allocate 30 GB; one inline string of a gigabyte compresses to a megabyte. So the
sheet parts of an XLSX/XLSM archive and the shared strings are scanned first, in chunks of
decompressed XML, and a workbook over a limit is refused at the cell that crosses it. The
scan also notes the formula errors (``#NAME?``) the library would read as empty cells. ODS
repeat counts are checked by :func:`check_ods_extent`.
"""

from __future__ import annotations

import re
import zipfile
from array import array
from collections.abc import Callable, Iterator
from pathlib import Path, PurePosixPath

from lxml import etree

from cadkg.errors import IngestError
from cadkg.ingest.xml_input import attributes_of

__all__ = [
    "MAX_CELLS",
    "MAX_COLUMNS",
    "MAX_ROWS",
    "MAX_TEXT",
    "MAX_WORKBOOK_TEXT",
    "TextBudget",
    "cell_address",
    "check_ods_extent",
    "column_letter",
    "scan_xlsx",
    "shared_string_error",
]

# The most rows and columns a sheet can hold, in Excel and in LibreOffice Calc.
MAX_ROWS = 1_048_576
MAX_COLUMNS = 16_384
# Cells a sheet may span from A1 to its last value: ~60,000 wires of a 32-column list, while
# the library's block for it (32 bytes a cell) stays under 70 MB.
MAX_CELLS = 1 << 21
# Characters a cell can hold in Excel; a run of XML text may be up to six bytes a character.
MAX_TEXT = 32_767
# The text of a workbook as the library builds it, each shared string counted at every cell
# that shows it and each repeated cell as often as it is repeated (in bytes of UTF-8, never
# fewer than its characters): 64 Mi is over 30 characters in each of MAX_CELLS cells, and one
# string of 32,767 characters shown in 30,000 cells (a 83 KB file) would be 980 Mi.
MAX_WORKBOOK_TEXT = 1 << 26
_MAX_TEXT_BYTES = 6 * MAX_TEXT
_MAX_STRINGS = MAX_CELLS
_MAX_TAG = 1 << 16
_MAX_PART = 256 << 20  # decompressed bytes of one sheet or the shared strings
_MAX_SMALL_PART = 16 << 20  # the workbook and its relationships
_CHUNK = 1 << 20
_PLAIN_SHEET_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_.]*$")
_TAG = re.compile(rb"<(/?)(?:[A-Za-z_][\w.-]*:)?([A-Za-z_][\w.-]*)((?:[^<>\"']|\"[^\"]*\"|'[^']*')*)(/?)>")
_REF = re.compile(rb"""\br\s*=\s*["']\s*([A-Za-z]*)(\d*)\s*["']""")
_ROW_NUMBER = re.compile(rb"""\br\s*=\s*["']\s*(\d+)\s*["']""")
_ERROR = re.compile(rb"""\bt\s*=\s*["']e["']""")
_SHARED = re.compile(rb"""\bt\s*=\s*["']s["']""")
_DIMENSION = re.compile(rb"""\bref\s*=\s*["']\s*([A-Za-z]+)(\d+)(?::([A-Za-z]+)(\d+))?\s*["']""")
_COUNT = re.compile(rb"""\buniqueCount\s*=\s*["']\s*(\d+)\s*["']""")
# Elements and attributes are told by their local names, whatever namespace their prefix is
# bound to: the library reads transitional and Strict OOXML alike, and a prefix bound to
# another namespace must not hide a part or a repeat count from the scan.
_CELLS = frozenset({"table-cell", "covered-table-cell"})


def column_letter(index: int) -> str:
    """``0`` → ``'A'``, ``25`` → ``'Z'``, ``26`` → ``'AA'`` (0-based column index)."""
    letters = ""
    index += 1
    while index:
        index, rest = divmod(index - 1, 26)
        letters = chr(ord("A") + rest) + letters
    return letters


def cell_address(sheet: str, row: int, column: int) -> str:
    """``'Sheet1!C7'`` for 1-based ``row`` 7 and 0-based ``column`` 2; odd sheet names are quoted."""
    name = sheet if _PLAIN_SHEET_NAME.match(sheet) else "'" + sheet.replace("'", "''") + "'"
    return f"{name}!{column_letter(column)}{row}"


def _column_index(letters: bytes) -> int:
    """0-based index of column ``letters``; past the last column when there are too many letters."""
    if len(letters) > 3:
        return MAX_COLUMNS
    index = 0
    for letter in letters.upper():
        index = index * 26 + letter - ord("A") + 1
    return index - 1


def _number(digits: bytes, limit: int) -> int:
    return int(digits) if len(digits) <= 8 else limit + 1


class TextBudget:
    """The text a workbook's sheets add up to as the library builds them, held to
    :data:`MAX_WORKBOOK_TEXT`."""

    def __init__(self) -> None:
        self.used = 0

    def spend(self, size: int) -> bool:
        """Count ``size`` more; whether the workbook is still within the limit."""
        self.used += size
        return self.used <= MAX_WORKBOOK_TEXT

    @staticmethod
    def refusal() -> tuple[str, str]:
        """(reason, expected) of the error of a workbook over the limit."""
        return (
            "the sheets' text, each shared string and repeated cell counted where it is shown,"
            " is more than cadkg reads of a workbook",
            f"at most {MAX_WORKBOOK_TEXT:,} bytes of text in a workbook",
        )


class _Limits:
    """Raises the located error of a workbook over a limit."""

    def __init__(self, path: str | Path, sheet: str, budget: TextBudget | None = None) -> None:
        self.path = path
        self.sheet = sheet
        self.budget = budget or TextBudget()

    def refuse(self, reason: str, row: int, column: int, expected: str) -> IngestError:
        row = min(max(row, 1), MAX_ROWS + 1)
        column = min(max(column, 0), MAX_COLUMNS)
        return IngestError(self.path, reason, cell=cell_address(self.sheet, row, column), expected=expected)


def _tags(
    archive: zipfile.ZipFile, member: str, limit: int, too_long: Callable[[str], IngestError]
) -> Iterator[tuple[bytes, bytes, bytes, bytes, bytes]]:
    """(closing slash, local name, attributes, self-closing slash, text before) of each tag of a
    part, read in chunks; a part, a tag or a run of text over its limit raises ``too_long``."""
    carry = b""
    total = 0
    with archive.open(member) as stream:
        while chunk := stream.read(_CHUNK):
            if not total and (b"<!DOCTYPE" in chunk or b"<!ENTITY" in chunk):
                # No workbook needs one, and an entity could stand for text the limits never see.
                raise too_long(f"the part {member} declares a document type or entities, which are refused")
            total += len(chunk)
            if total > limit:
                raise too_long(f"the part {member} is over {limit >> 20} MiB of XML")
            data = carry + chunk
            end = 0
            for match in _TAG.finditer(data):
                text = data[end : match.start()]
                if len(text) > _MAX_TEXT_BYTES:
                    raise too_long("a cell's text is longer than a cell can hold")
                yield match.group(1), match.group(2), match.group(3), match.group(4), text
                end = match.end()
            carry = data[end:]
            opened = carry.find(b"<")
            if (opened < 0 and len(carry) > _MAX_TEXT_BYTES) or opened > _MAX_TEXT_BYTES:
                raise too_long("a cell's text is longer than a cell can hold")
            if opened >= 0 and len(carry) - opened > _MAX_TAG:
                raise too_long("an element's tag is longer than 64 KiB")


def _scan_sheet(
    archive: zipfile.ZipFile, member: str, limits: _Limits, strings: array[int]
) -> dict[tuple[int, int], str]:
    """Check one sheet part; the formula errors it holds, by (1-based row, 0-based column).

    ``strings`` holds the length of each shared string, for the text the cells that show
    them add up to.
    """
    errors: dict[tuple[int, int], str] = {}
    row = column = last_row = last_column = cells = 0
    in_error = in_value = shared = False
    expected = f"at most {MAX_ROWS:,} rows, {MAX_COLUMNS:,} columns and {MAX_CELLS:,} cells from A1"

    def too_long(reason: str) -> IngestError:
        return limits.refuse(reason, row, column, f"at most {MAX_TEXT:,} characters a cell")

    for closing, name, attributes, empty, text in _tags(archive, member, _MAX_PART, too_long):
        if closing and name in (b"v", b"t"):
            size = len(text)
            if shared and name == b"v":
                index = text.strip()
                # An index past nine digits is past any table of strings (and int() refuses 4,300).
                size = (
                    strings[int(index)]
                    if index.isdigit() and len(index) <= 9 and int(index) < len(strings)
                    else 0
                )
            if not limits.budget.spend(size):
                reason, wanted = TextBudget.refusal()
                raise limits.refuse(reason, row, column, wanted)
        if in_value and name == b"v" and closing:
            errors[(row, column)] = text.decode("utf-8", "replace").strip()[:16]
        if closing:
            in_value = False
            continue
        if name == b"row":
            number = _ROW_NUMBER.search(attributes)
            row = _number(number.group(1), MAX_ROWS) if number else row + 1
            column = -1
            if row > MAX_ROWS:
                raise limits.refuse(
                    "a row is numbered beyond the last row a sheet can have (a damaged workbook)",
                    row,
                    0,
                    expected,
                )
        elif name == b"c":
            ref = _REF.search(attributes)
            if ref and ref.group(1):
                column = _column_index(ref.group(1))
                row = _number(ref.group(2), MAX_ROWS) if ref.group(2) else row
            else:
                column += 1
            cells += 1
            if row > MAX_ROWS or column >= MAX_COLUMNS:
                raise limits.refuse(
                    "a cell lies beyond the last row or column a sheet can have (a damaged workbook)",
                    row,
                    column,
                    expected,
                )
            in_error = bool(_ERROR.search(attributes))
            shared = bool(_SHARED.search(attributes))
            if not empty:
                last_row, last_column = max(last_row, row), max(last_column, column)
                if last_row * (last_column + 1) > MAX_CELLS or cells > MAX_CELLS:
                    raise limits.refuse(
                        "the sheet's cells span more than cadkg reads of a sheet", row, column, expected
                    )
        elif name == b"v":
            in_value = in_error and not empty
        elif name == b"dimension":
            _check_dimension(attributes, limits, expected)
    return errors


def _check_dimension(attributes: bytes, limits: _Limits, expected: str) -> None:
    # The library does not allocate by the declared range, so only a range no sheet can have
    # is refused: the cells decide how much is read.
    ref = _DIMENSION.search(attributes)
    if ref is None:
        return
    letters, digits = (ref.group(3), ref.group(4)) if ref.group(3) else (ref.group(1), ref.group(2))
    row, column = _number(digits, MAX_ROWS), _column_index(letters)
    if row > MAX_ROWS or column >= MAX_COLUMNS:
        raise limits.refuse(
            "the sheet declares a range beyond the last row or column a sheet can have (a damaged workbook)",
            row,
            column,
            expected,
        )


def shared_string_error(path: str | Path, reason: str, number: int) -> IngestError:
    """A workbook's shared strings past what cadkg reads, at the ``number``-th (XLSX or XLS)."""
    return IngestError(
        path,
        f"{reason} (shared string {number})",
        expected=f"at most {_MAX_STRINGS:,} shared strings of at most {MAX_TEXT:,} characters",
    )


def _scan_strings(archive: zipfile.ZipFile, member: str, path: str | Path, lengths: array[int]) -> None:
    """Check a shared-strings part; the bytes of text of each string go on ``lengths``."""
    count = 0

    def refuse(reason: str) -> IngestError:
        return shared_string_error(path, reason, count)

    for closing, name, attributes, _, text in _tags(archive, member, _MAX_PART, refuse):
        if closing:
            if name == b"t" and lengths:
                lengths[-1] += len(text)
            continue
        if name == b"si":
            lengths.append(0)
            count += 1
            if count > _MAX_STRINGS:
                raise refuse("more shared strings than cadkg reads of a workbook")
        elif name == b"sst":
            declared = _COUNT.search(attributes)
            if declared and _number(declared.group(1), _MAX_STRINGS) > _MAX_STRINGS:
                raise refuse("the workbook declares more shared strings than cadkg reads")


def _small_xml(archive: zipfile.ZipFile, member: str, path: str | Path) -> etree._Element:
    info = archive.getinfo(member)
    if info.file_size > _MAX_SMALL_PART:
        raise IngestError(path, f"the part {member} is over {_MAX_SMALL_PART >> 20} MiB")
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False, huge_tree=False)
    return etree.fromstring(archive.read(member), parser)


def _local(name: object) -> str:
    """The local name of an element's or attribute's tag, whatever its namespace."""
    # A tag in Clark notation, ``{namespace}local``; what etree.QName gives, at a tenth the cost.
    return name.rpartition("}")[2] if isinstance(name, str) else ""


def _attribute(element: etree._Element, local: str, default: str = "") -> str:
    """The value of the attribute with local name ``local``, in whichever namespace; unprefixed first."""
    found = element.get(local)
    if found is not None:
        return str(found)
    return next((v for k, v in attributes_of(element).items() if _local(k) == local), default)


def _parts(archive: zipfile.ZipFile, path: str | Path) -> tuple[list[tuple[str, str]], list[str]]:
    """(sheet name, part) of each worksheet, in tab order and then any other worksheet part of
    the archive, and the shared-strings parts."""
    workbook = _small_xml(archive, "xl/workbook.xml", path)
    rels_name = "xl/_rels/workbook.xml.rels"
    targets: dict[str, str] = {}
    strings: list[str] = []
    worksheets: list[str] = []
    if rels_name in archive.NameToInfo:
        for rel in _small_xml(archive, rels_name, path).iter():
            if _local(rel.tag) != "Relationship":
                continue
            target = _attribute(rel, "Target")
            part = target.lstrip("/") if target.startswith("/") else str(PurePosixPath("xl", target))
            targets[_attribute(rel, "Id")] = part
            kind = _attribute(rel, "Type").rsplit("/", 1)[-1]
            if kind == "sharedStrings":
                strings.append(part)
            elif kind == "worksheet":
                worksheets.append(part)
    sheets = []
    for sheet in workbook.iter():
        if _local(sheet.tag) != "sheet":
            continue
        part = targets.get(_attribute(sheet, "id"), "")
        if part in archive.NameToInfo:
            sheets.append((_attribute(sheet, "name", "Sheet"), part))
    named = {part for _, part in sheets}
    # A worksheet part that no sheet names is scanned too, by its part name: what the library
    # finds must not depend on the workbook naming it as the scan expects.
    others = worksheets + sorted(n for n in archive.NameToInfo if n.startswith("xl/worksheets/"))
    for part in dict.fromkeys(others):
        if part not in named and part.endswith(".xml") and part in archive.NameToInfo:
            sheets.append((PurePosixPath(part).stem, part))
    strings += [n for n in archive.NameToInfo if PurePosixPath(n).name.lower() == "sharedstrings.xml"]
    return sheets, [s for s in dict.fromkeys(strings) if s in archive.NameToInfo]


def scan_xlsx(path: str | Path) -> dict[str, dict[tuple[int, int], str]]:
    """Check an XLSX/XLSM workbook against the limits; per sheet name, its formula error cells.

    Raises
    ------
    IngestError
        At the cell (or shared string) over a limit; KeyError and zipfile errors for a damaged
        archive, which the caller turns into its "corrupt workbook" error.
    """
    with zipfile.ZipFile(path) as archive:
        sheets, parts = _parts(archive, path)
        lengths = array("Q")  # up to MAX_CELLS strings: 8 bytes each, not a Python int's 32
        for member in parts:
            _scan_strings(archive, member, path, lengths)
        budget = TextBudget()
        return {
            name: _scan_sheet(archive, part, _Limits(path, name, budget), lengths) for name, part in sheets
        }


def check_ods_extent(path: str | Path) -> None:
    """Refuse repeat counts that expand a sheet past its size, and text that the repeats
    expand past :data:`MAX_WORKBOOK_TEXT`."""
    budget = TextBudget()
    with zipfile.ZipFile(path) as archive, archive.open("content.xml") as content:
        rows = last = width = 0
        # Only tables and rows come to Python; a row's cells are walked from the row, so the
        # scan costs one proxy per cell rather than one per element of the sheet.
        events = etree.iterparse(
            content,
            events=("end",),
            tag=("{*}table", "{*}table-row"),
            resolve_entities=False,
            no_network=True,
            load_dtd=False,
        )
        for _, element in events:
            if _local(element.tag) == "table":
                rows = last = width = 0
                element.clear()
                continue
            repeated = _count(_by_local_name(element)[0], "number-rows-repeated")
            columns = filled = text = 0
            for cell in element:
                if _local(cell.tag) in _CELLS:
                    named, value = _by_local_name(cell)
                    times = _count(named, "number-columns-repeated")
                    columns += times
                    if named.get("value-type") or len(cell):
                        filled = columns
                    text += (value + _cell_content(cell)) * times
                # lxml takes time with the square of an element's namespaced attributes to
                # move one still referenced from Python (as the loop's cell is) out of a tree
                # being cleared; clearing the cell itself frees them at once.
                cell.clear()
            rows += repeated
            if filled:
                last, width = rows, max(width, filled)
            if rows > MAX_ROWS or columns > MAX_COLUMNS or last * width > MAX_CELLS:
                raise _oversized(path, _table_name(element), rows, columns)
            if not budget.spend(text * repeated):
                reason, expected = TextBudget.refusal()
                at = cell_address(_table_name(element), rows - repeated + 1, max(filled, 1) - 1)
                raise IngestError(path, reason, cell=at, expected=expected)
            element.clear()


def _by_local_name(element: etree._Element) -> tuple[dict[str, str], int]:
    """An element's attributes by local name (the unprefixed one if there is one, else the
    first in document order, as :func:`_attribute` picks), and the characters of those whose
    local name ends in ``value`` (a cell's string or date given there), in one pass."""
    named: dict[str, str] = {}
    size = 0
    for key, value in attributes_of(element).items():
        local = _local(key)
        if local not in named or key == local:
            named[local] = value
        if local.endswith("value"):
            size += len(value)
    return named, size


def _count(named: dict[str, str], local: str) -> int:
    return int(named.get(local, "1"))


def _cell_content(cell: etree._Element) -> int:
    """The characters of a cell's text and of its children's, with the spaces of
    ``<text:s text:c="n">``."""
    size = len(cell.text or "")
    for node in cell.iterdescendants():
        size += len(node.text or "") + len(node.tail or "")
        if _local(node.tag) == "s":
            size += int(_attribute(node, "c", "1"))
    return size


def _table_name(row: etree._Element) -> str:
    table = next((t for t in row.iterancestors() if _local(t.tag) == "table"), None)
    return "Sheet" if table is None else _attribute(table, "name", "Sheet")


def _oversized(path: str | Path, sheet: str, rows: int, columns: int) -> IngestError:
    return IngestError(
        path,
        "repeated rows or cells expand the sheet beyond what a sheet can hold (a damaged workbook)",
        cell=cell_address(sheet, min(rows, MAX_ROWS + 1), min(columns, MAX_COLUMNS + 1) - 1),
        expected=f"at most {MAX_ROWS:,} rows, {MAX_COLUMNS:,} columns"
        f" and {MAX_CELLS:,} cells up to the last value",
    )
