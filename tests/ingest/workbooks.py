"""Writing small XLSX and ODS workbooks for the spreadsheet reader tests (no binaries in the tree)."""

from __future__ import annotations

import os
import signal
import struct
import subprocess
import sys
import zipfile
import zlib
from collections.abc import Sequence
from pathlib import Path

import openpyxl
import pandas as pd

Sheet = tuple[str, Sequence[Sequence[object]]]


def write_xlsx(path: Path, sheets: Sequence[Sheet]) -> Path:
    """Rows start at A1; ``None`` leaves a cell empty."""
    book = openpyxl.Workbook()
    book.remove(book.active)
    for name, rows in sheets:
        sheet = book.create_sheet(name)
        for r, row in enumerate(rows, start=1):
            for c, value in enumerate(row, start=1):
                if value is not None:
                    cell = sheet.cell(row=r, column=c, value=value)
                    if isinstance(value, str) and value.startswith("="):
                        cell.data_type = "s"  # EPLAN's '=-X1600' is text, not a formula
    book.save(path)
    return path


def write_ods(path: Path, sheets: Sequence[Sheet]) -> Path:
    with pd.ExcelWriter(path, engine="odf") as writer:
        for name, rows in sheets:
            width = max((len(r) for r in rows), default=0)
            padded = [[*r, *[None] * (width - len(r))] for r in rows]
            pd.DataFrame(padded).to_excel(writer, sheet_name=name, header=False, index=False)
    return path


def replace_in_member(path: Path, member: str, old: bytes, new: bytes) -> None:
    """Rewrite one file inside a workbook, e.g. to store ``2.0`` where openpyxl writes ``2``."""
    with zipfile.ZipFile(path) as archive:
        items = [(info, archive.read(info)) for info in archive.infolist()]
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for info, data in items:
            if info.filename == member:
                assert old in data, f"{old!r} not in {member}"
                data = data.replace(old, new)
            archive.writestr(info, data)


def _member(name: str, chunks: Sequence[tuple[bytes, int]]) -> tuple[bytes, bytes, int, int]:
    """(name, raw deflate data, CRC-32, size) of a member made of ``(data, times)`` runs.

    Each run is compressed once and its compressed form repeated, so a member of a gigabyte
    takes a second: the runs end on a full flush, which no later data refers back across.
    """
    out, crc, size = [], 0, 0
    for data, times in chunks:
        packer = zlib.compressobj(9, zlib.DEFLATED, -15)
        block = packer.compress(data) + packer.flush(zlib.Z_FULL_FLUSH)
        out.append(block * times)
        for _ in range(times):
            crc = zlib.crc32(data, crc)
        size += len(data) * times
    out.append(zlib.compressobj(9, zlib.DEFLATED, -15).flush())  # an empty final block
    return name.encode(), b"".join(out), crc, size


def write_zip(path: Path, members: Sequence[tuple[str, Sequence[tuple[bytes, int]]]]) -> Path:
    """A ZIP archive written by hand from runs of repeated bytes (see :func:`_member`)."""
    local, central = bytearray(), bytearray()
    entries = [_member(name, chunks) for name, chunks in members]
    for name, data, crc, size in entries:
        fields = (20, 0, 8, 0, 0x21, crc, len(data), size, len(name), 0)
        central += struct.pack("<IH", 0x02014B50, 20) + struct.pack("<HHHHHIIIHH", *fields)
        central += struct.pack("<HHHII", 0, 0, 0, 0, len(local)) + name
        local += struct.pack("<I", 0x04034B50) + struct.pack("<HHHHHIIIHH", *fields) + name + data
    end = struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, len(entries), len(entries), len(central), len(local), 0)
    path.write_bytes(bytes(local + central + end))
    return path


_CONTENT_TYPES = (
    b'<?xml version="1.0"?><Types xmlns="http://schemas.openxmlformats.org/package/2006/content-types">'
    b'<Override PartName="/xl/workbook.xml" ContentType="application/vnd.openxmlformats-officedocument.'
    b'spreadsheetml.sheet.main+xml"/></Types>'
)
_RELS = (
    b'<?xml version="1.0"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
    b'<Relationship Id="rId1" Type="http://schemas.openxmlformats.org/officeDocument/2006/relationships/'
    b'officeDocument" Target="xl/workbook.xml"/></Relationships>'
)
_WORKBOOK = (
    b'<?xml version="1.0"?><workbook xmlns="http://schemas.openxmlformats.org/spreadsheetml/2006/main" '
    b'xmlns:r="http://schemas.openxmlformats.org/officeDocument/2006/relationships"><sheets>'
    b'<sheet name="S" sheetId="1" r:id="rId1"/></sheets></workbook>'
)
_WORKBOOK_RELS = (
    b'<?xml version="1.0"?><Relationships xmlns="http://schemas.openxmlformats.org/package/2006/relationships">'
    b'<Relationship Id="rId1" Type="http://schemas.openxmlformats.org/officeDocument/2006/relationships/'
    b'worksheet" Target="worksheets/sheet1.xml"/></Relationships>'
)
SHEET_HEAD = (
    b'<?xml version="1.0"?><worksheet xmlns="http://schemas.openxmlformats.org/spreadsheetml/2006/main">'
    b'<sheetData><row r="1"><c r="A1" t="inlineStr"><is><t>Morsettiera</t></is></c></row>'
)
SHEET_TAIL = b"</sheetData></worksheet>"


def write_raw_xlsx(path: Path, sheet: Sequence[tuple[bytes, int]]) -> Path:
    """A one-sheet XLSX (sheet ``S``) whose sheet XML is the given runs of repeated bytes."""
    return write_zip(
        path,
        [
            ("[Content_Types].xml", [(_CONTENT_TYPES, 1)]),
            ("_rels/.rels", [(_RELS, 1)]),
            ("xl/workbook.xml", [(_WORKBOOK, 1)]),
            ("xl/_rels/workbook.xml.rels", [(_WORKBOOK_RELS, 1)]),
            ("xl/worksheets/sheet1.xml", sheet),
        ],
    )


# A child process reads the file and reports its peak memory: the test process's own peak
# would hide what the read costs. VmHWM starts afresh at exec; ru_maxrss would keep the
# size of the test process the child was forked from.
_MEASURE = """
import sys, time
from cadkg.errors import IngestError
from cadkg.ingest.sheet import read_workbook
start = time.monotonic()
try:
    read_workbook(sys.argv[1])
    print("read")
except IngestError as err:
    print(err)
print(time.monotonic() - start)
with open("/proc/self/status") as status:
    print(next(int(line.split()[1]) for line in status if line.startswith("VmHWM:")) // 1024)
"""


def read_in_child(path: Path, timeout: float = 120) -> tuple[str, float, int]:
    """(the error line or ``read``, seconds, peak RSS in MB) of reading ``path`` in a child
    process; a child past ``timeout`` is killed with its process group and the test fails."""
    out = run_child([sys.executable, "-c", _MEASURE, str(path)], timeout, f"reading {path.name}")
    message, seconds, megabytes = out.splitlines()[-3:]
    return message, float(seconds), int(megabytes)


def run_child(command: Sequence[str], timeout: float, what: str, env: dict[str, str] | None = None) -> str:
    """The output of ``command`` run in a process group of its own, which must exit with 0;
    a process past ``timeout`` is killed with its group and the test fails."""
    process = subprocess.Popen(
        command,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        env=env,
    )
    try:
        out, err = process.communicate(timeout=timeout)
    except subprocess.TimeoutExpired:
        os.killpg(process.pid, signal.SIGKILL)
        process.communicate()
        raise AssertionError(f"{what} took over {timeout} s") from None
    assert process.returncode == 0, err[-2000:]
    return out
