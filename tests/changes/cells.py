"""Small pairs of revisions: a copy of a test cell, edited as a design change would edit it."""

from __future__ import annotations

import shutil
from pathlib import Path

from tests.conftest import ROOT

MINI = ROOT / "tests" / "data" / "cells" / "mini"


def copy_cell(source: Path, target: Path) -> Path:
    """A copy of the cell folder ``source`` at ``target``; its manifest."""
    shutil.copytree(source, target)
    return target / "manifest.toml"


def edit(path: Path, old: str, new: str) -> None:
    """Replace ``old`` (which must be there, once) by ``new`` in a text file."""
    text = path.read_text(encoding="utf-8")
    assert text.count(old) == 1, f"{old!r} is not in {path} exactly once"
    path.write_text(text.replace(old, new), encoding="utf-8")
