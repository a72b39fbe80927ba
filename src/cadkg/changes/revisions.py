"""A store's previous generation, which ``cadkg diff STORE`` compares its live one with."""

from __future__ import annotations

from pathlib import Path

from cadkg.errors import StoreError
from cadkg.generations import PREVIOUS, current_generation, read_pointer
from cadkg.graph import KnowledgeGraph

__all__ = ["open_generation", "open_previous"]


def open_previous(directory: str | Path) -> tuple[KnowledgeGraph, str, str]:
    """The generation a store directory served before its live one, read-only, with the names
    of both.

    Raises
    ------
    StoreError
        When the directory is no store or keeps no previous generation (built once).
    """
    directory = Path(directory)
    live = current_generation(directory).name
    name = read_pointer(directory, PREVIOUS)
    if name is None or not (directory / name).is_dir():
        raise StoreError(
            f"{directory}: keeps no previous generation (built once); compare two revisions with "
            "'cadkg diff OLD NEW'"
        )
    return open_generation(directory, name), name, live


def open_generation(directory: str | Path, name: str) -> KnowledgeGraph:
    """The generation ``name`` of a store directory, read-only, with what it keeps beside its
    database (its cell model, so a diff reads the model's things from it as from the live one).

    Raises
    ------
    StoreError
        When it cannot be opened (removed by a later build).
    """
    return KnowledgeGraph.open(directory, generation=name)
