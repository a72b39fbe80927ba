"""Decoding of text exports: encodings, byte-order marks, binary garbage, rows with lines.

EPLAN and spreadsheet exports arrive as UTF-8 (with or without a BOM), as UTF-16 with
its BOM (EPLAN's "Unicode" export, Excel's "Unicode Text") or as the Windows code page
of the machine that wrote them. We read UTF-8 first and fall back to Windows-1252 with
a warning, because a silent mojibake label would never match its counterpart in
another file.
"""

from __future__ import annotations

import csv
import os
import re
import warnings
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from decimal import Decimal, InvalidOperation
from itertools import islice
from pathlib import Path

from cadkg.errors import IngestError, IngestWarning

__all__ = [
    "MAX_TEXT_FILE",
    "Row",
    "check_columns",
    "decode_text",
    "find_header",
    "first_line",
    "iter_rows",
    "named_columns",
    "parse_decimal",
    "read_head",
    "read_text",
    "small_integer",
    "sniffable_head",
    "split_cells",
    "xml_document",
]

_BOM = b"\xef\xbb\xbf"
_UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")
# Printable ASCII with a NUL beside every character: UTF-16 written without its BOM.
_UTF16_WITHOUT_BOM = re.compile(rb"((?:[\t\n\r\x20-\x7e]\x00){8})|(?:\x00[\t\n\r\x20-\x7e]){8}")
_CONTROL_OK = {"\t", "\n", "\r", "\f"}
# The largest text export read: a file is held whole while its rows are read one by one (its
# bytes, then its text, up to four bytes a character), and that must fit the read limit of
# cadkg.limited. A connection list of a million wires is about 130 MiB.
MAX_TEXT_FILE = 256 << 20


@dataclass(frozen=True, slots=True)
class Row:
    """One record of a delimited text file and the 1-based line it starts on."""

    line: int
    cells: tuple[str, ...]

    def cell(self, index: int) -> str:
        """The stripped cell at ``index``; empty when the row is shorter."""
        return self.cells[index].strip() if index < len(self.cells) else ""

    @property
    def is_blank(self) -> bool:
        return not "".join(self.cells).strip()


def _line_of(data: bytes, offset: int) -> int:
    return data.count(b"\n", 0, offset) + 1


def decode_text(path: str | Path, data: bytes, *, expected: str) -> str:
    """Decode a text export, rejecting empty and binary files with a located error."""
    order = _utf16_order(data)
    if order is not None:
        if order != "utf-16":
            warnings.warn(
                IngestWarning(path, f"UTF-16 without a byte-order mark; read as {order.upper()}", line=1),
                stacklevel=2,
            )
        text = _decode_utf16(path, data, expected, order)
        # UTF-16 bytes hold NULs in every ASCII character: checked once decoded.
        _refuse_empty_or_binary(path, text, expected)
        return _checked(path, text, expected)
    data = data.removeprefix(_BOM)
    _refuse_empty_or_binary(path, data, expected)
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = _line_of(data, err.start)
        try:
            text = data.decode("cp1252")
            encoding = "Windows-1252"
        except UnicodeDecodeError:
            text = data.decode("latin-1")
            encoding = "Latin-1"
        warnings.warn(
            IngestWarning(
                path,
                f"not UTF-8 (first invalid byte 0x{data[err.start]:02x}); read as {encoding}",
                line=line,
            ),
            stacklevel=2,
        )
    return _checked(path, text, expected)


def xml_document(path: str | Path, data: bytes, *, expected: str) -> bytes | str:
    """What to hand the XML parser: UTF-16 decoded to text, anything else as it came.

    UTF-16 is recognised by its BOM or, without one, by the NULs beside its ASCII (as
    :func:`decode_text` does, with the same warning); the XML parser would refuse it, since
    only the BOM tells it the encoding. Empty and binary files are refused here as
    :func:`decode_text` refuses them; the parser itself reads the encoding other XML declares.
    """
    if _utf16_order(data) is not None:
        return decode_text(path, data, expected=expected)
    _refuse_empty_or_binary(path, data.removeprefix(_BOM), expected)
    return data


def sniffable_head(head: bytes) -> bytes:
    """The first bytes of a file as UTF-8 when they are UTF-16, for content sniffing."""
    order = _utf16_order(head)
    if order is None:
        return head
    # The head may end inside a character: cut to whole units and replace what is left.
    return head[: len(head) - len(head) % 2].decode(order, errors="replace").encode("utf-8")


def _utf16_order(data: bytes) -> str | None:
    """The codec of UTF-16 ``data`` ("utf-16" when a BOM names the order), else ``None``."""
    if data.startswith(_UTF16_BOMS):
        return "utf-16"
    unmarked = _UTF16_WITHOUT_BOM.match(data)
    if unmarked is None:
        return None
    return "utf-16-le" if unmarked.group(1) else "utf-16-be"


def _refuse_empty_or_binary(path: str | Path, body: bytes | str, expected: str) -> None:
    """Refuse a file that is blank, or holds a NUL: undecoded bytes, or decoded UTF-16 text."""
    if not body.strip():
        raise IngestError(path, "the file is empty", expected=expected)
    if isinstance(body, bytes):
        nul = body.find(b"\x00")
        if nul >= 0:
            reason = f"binary content (NUL byte at offset {nul})"
            raise IngestError(path, reason, line=_line_of(body, nul), expected=expected)
    elif (nul := body.find("\x00")) >= 0:
        line = body.count("\n", 0, nul) + 1
        raise IngestError(path, "binary content (a NUL character)", line=line, expected=expected)


def _decode_utf16(path: str | Path, data: bytes, expected: str, order: str) -> str:
    try:
        return data.decode(order)  # plain "utf-16" takes the order from the BOM and drops it
    except UnicodeDecodeError as err:
        # The lines before the bad unit decode cleanly; an odd byte count is cut off at the end.
        before = data[: err.start - err.start % 2].decode(order, errors="replace")
        raise IngestError(
            path,
            f"not valid UTF-16 ({err.reason})",
            line=before.count("\n") + 1,
            expected=expected,
        ) from None


def _checked(path: str | Path, text: str, expected: str) -> str:
    """``text`` once it is known not to be binary nor to hold stray byte-order marks."""
    bad = sum(1 for ch in text[:65536] if ord(ch) < 32 and ch not in _CONTROL_OK)
    if bad > max(8, len(text[:65536]) // 100):
        raise IngestError(path, f"binary content ({bad} control characters)", expected=expected)
    stray = text.find("\ufeff")
    if stray >= 0:
        # Exports joined end to end keep the second one's BOM, invisible at the start of a
        # line; left in, it would become part of a label or an ID that then matches nothing.
        warnings.warn(
            IngestWarning(
                path,
                "byte-order mark inside the file (files joined together?); removed",
                line=text.count("\n", 0, stray) + 1,
            ),
            stacklevel=3,
        )
        text = text.replace("\ufeff", "")
    return text


def small_integer(text: str) -> int | None:
    """``text`` as a whole number of one to nine ASCII digits; ``None`` otherwise.

    The counts, positions and indices of an input never run past nine digits, and this
    keeps ``int()`` from what it refuses: ``'²'``, which ``isdigit()`` accepts, and runs of
    over 4,300 digits.
    """
    return int(text) if text.isascii() and text.isdigit() and len(text) <= 9 else None


def read_head(path: str | Path, size: int = 4096, *, expected: str) -> bytes:
    """The first ``size`` bytes of a file, for a reader that tells its form by content.

    Raises
    ------
    IngestError
        When the file cannot be read or is empty.
    """
    try:
        with Path(path).open("rb") as handle:
            head = handle.read(size)
    except OSError as err:
        raise IngestError(path, f"cannot read the file: {err.strerror}") from err
    if not head:
        raise IngestError(path, "the file is empty", expected=expected)
    return head


def read_text(path: str | Path, *, expected: str) -> str:
    """Read and decode a whole text file (see :func:`decode_text`).

    Raises
    ------
    IngestError
        When the file cannot be read, is over :data:`MAX_TEXT_FILE`, is empty or binary.
    """
    try:
        with Path(path).open("rb") as handle:
            size = os.fstat(handle.fileno()).st_size
            if size > MAX_TEXT_FILE:
                raise IngestError(
                    path,
                    f"the file is {size / (1 << 20):,.0f} MiB, more than cadkg reads of a text export",
                    expected=f"at most {MAX_TEXT_FILE >> 20} MiB",
                )
            data = handle.read()
    except OSError as err:
        raise IngestError(path, f"cannot read the file: {err.strerror}") from err
    return decode_text(path, data, expected=expected)


# A line and its end, as io.StringIO(text, newline="") splits them: CR, LF or CRLF.
_LINE = re.compile(r"[^\r\n]*(?:\r\n|\r|\n)|[^\r\n]+\Z")


def _lines(text: str) -> Iterator[str]:
    """The lines of ``text`` with their ends; io.StringIO would first copy the whole text, at
    four bytes a character."""
    return (match.group() for match in _LINE.finditer(text))


def iter_rows(text: str, delimiter: str, path: str | Path | None = None) -> Iterator[Row]:
    """Rows of delimited text with the line each starts on (quoted cells may span lines).

    Only CR and LF end lines: ``str.splitlines`` would also split at U+2028 and other
    separators that may sit inside a cell.
    """
    reader = csv.reader(_lines(text), delimiter=delimiter, strict=False)
    start = 1
    while True:
        try:
            cells = next(reader)
        except StopIteration:
            return
        except csv.Error as err:
            raise IngestError(
                path, f"malformed row: {err}", line=start, expected="closed quotes and cells under 128 KiB"
            ) from None
        yield Row(start, tuple(cells))
        start = reader.line_num + 1


_UNITS = ("mm²", "mm2", "mmq", "mm^2", "mm", "m")


def parse_decimal(text: str) -> tuple[Decimal, str]:
    """Parse ``'1,5 mm²'`` → ``(Decimal('1.5'), 'mm²')``; raises ValueError when not a number.

    Decimal commas are what Italian and German exports write; when both ``.`` and
    ``,`` occur the last one is the decimal separator.
    """
    value = text.strip().replace("\u00a0", " ")
    unit = ""
    lowered = value.lower()
    for candidate in _UNITS:
        if lowered.endswith(candidate):
            number_part = value[: len(value) - len(candidate)]
            if number_part.strip() and (number_part[-1].isdigit() or number_part[-1] == " "):
                unit = candidate
                value = number_part.strip()
                break
    if "," in value and "." in value:
        if value.rfind(",") > value.rfind("."):
            value = value.replace(".", "").replace(",", ".")
        else:
            value = value.replace(",", "")
    else:
        value = value.replace(",", ".")
    try:
        number = Decimal(value)
    except InvalidOperation:
        raise ValueError(text) from None
    exponent = number.as_tuple().exponent
    if not number.is_finite() or not isinstance(exponent, int) or not -30 <= exponent <= 30:
        # A cell like 1e999999999 would expand to a gigabyte of digits when written out.
        raise ValueError(text)
    return number, unit


def find_header(
    text: str,
    path: str | Path,
    columns_of: Callable[[Row], dict[str, int]],
    accept: Callable[[dict[str, int]], bool],
    expected: str,
    scan_rows: int = 40,
) -> tuple[list[Row], Iterator[Row], int, dict[str, int]]:
    """Where the header of a delimited export is: (rows up to the header, the rows after it,
    header index, columns).

    Tab, semicolon and comma are tried on the first ``scan_rows`` lines only; in each, the
    first row whose column meanings ``accept`` is a candidate and the delimiter whose header
    names the most columns wins. Then the file is split once, the rows after the header as
    they are iterated: a file of a million rows is never a million rows in memory.

    Raises
    ------
    IngestError
        When no delimiter gives an acceptable header row.
    """
    head = "".join(islice(_lines(text), scan_rows))
    best: tuple[int, str, int, dict[str, int]] | None = None
    for delimiter in ("\t", ";", ","):
        for position, row in enumerate(iter_rows(head, delimiter, path)):
            columns = columns_of(row)
            if accept(columns):
                if best is None or len(columns) > best[0]:
                    best = (len(columns), delimiter, position, columns)
                break
    if best is None:
        raise IngestError(path, "no header row found in the first lines", line=1, expected=expected)
    _, delimiter, position, columns = best
    rows = iter_rows(text, delimiter, path)
    return list(islice(rows, position + 1)), rows, position, columns


_SNIFF_DELIMITERS = re.compile(r"[\t;,]")


def first_line(head: bytes) -> str:
    """The first non-empty line of a file's first bytes (BOM dropped): what sniffers read."""
    text = head.decode("utf-8", errors="replace").removeprefix("\ufeff")
    return next((line for line in text.splitlines() if line.strip()), "")


def split_cells(line: str) -> list[str]:
    """A header line's cells, split on tab, semicolon or comma, stripped and unquoted."""
    return [c.strip().strip('"') for c in _SNIFF_DELIMITERS.split(line)]


def named_columns(row: Row, known: Sequence[str]) -> dict[str, int]:
    """Column name (lower case, one of ``known``) → its first index in a header row."""
    columns: dict[str, int] = {}
    for index, cell in enumerate(row.cells):
        name = cell.strip().lower()
        if name in known:
            columns.setdefault(name, index)
    return columns


def check_columns(
    path: str | Path,
    head: Row,
    columns: Mapping[str, int],
    known: Sequence[str],
    required: Sequence[str],
    expected: str,
) -> None:
    """Refuse a header with a column not in ``known`` or without one of ``required``.

    Raises
    ------
    IngestError
        At the header's line, naming the first unknown or missing column.
    """
    unknown = [c.strip() for c in head.cells if c.strip() and c.strip().lower() not in known]
    if unknown:
        raise IngestError(path, "unknown column", line=head.line, found=unknown[0], expected=", ".join(known))
    missing = [c for c in required if c not in columns]
    if missing:
        raise IngestError(path, f"missing column {missing[0]!r}", line=head.line, expected=expected)
