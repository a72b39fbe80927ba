"""Writing small XLSX and ODS workbooks for the spreadsheet reader tests (no binaries in the tree)."""

from __future__ import annotations

import zipfile
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
