"""The copy of the cell model a store generation keeps beside its database, so that opening the
store again reads the model instead of deriving it."""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Any

from cadkg.usecase import Derivation

__all__ = ["MODEL_FILE", "read_model", "write_model"]

MODEL_FILE = "cell-model.json"


def read_model(path: Path, derivation: Derivation) -> Any:
    """The model kept at ``path``, or None when there is none."""
    try:
        data = path.read_bytes()
    except OSError:
        return None
    return derivation.load(data)


def write_model(path: Path, derivation: Derivation, model: Any) -> None:
    """Keep ``model`` at ``path``: written whole and renamed into place, so a reader finds the
    old copy, none, or this one. A copy that cannot be written is left out (it only saves time)."""
    partial = path.with_name(path.name + ".partial")
    with contextlib.suppress(OSError):
        partial.write_bytes(derivation.dump(model))
        partial.replace(path)
