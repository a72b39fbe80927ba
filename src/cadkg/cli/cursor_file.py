"""The cursors ``cadkg call`` keeps beside a store between calls (``STORE/cursors.json``), and
their way across a rebuild of the store.

The file names the generation its cursors were made on. After ``cadkg build`` the store is a
new generation: the cursors are moved onto the same wire or operation of it, by identity
(:meth:`cadkg.services.session.Session.carry_over`), from the generation they were made on,
which the store keeps as long as it is the one before the live one.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from cadkg.changes.revisions import open_generation
from cadkg.errors import CadkgError
from cadkg.services.session import Session

__all__ = ["read_cursors", "resume_cursors", "write_cursors"]

_NAME = "cursors.json"


def read_cursors(directory: str | Path) -> tuple[str | None, dict[str, Any]]:
    """The generation the cursors of a store directory were made on, and the cursors as
    :meth:`Session.dump` wrote them; ``(None, {})`` when there are none (or the file is unreadable)."""
    path = Path(directory) / _NAME
    try:
        saved = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None, {}
    if not isinstance(saved, dict) or not isinstance(saved.get("cursors"), dict):
        return None, {}
    generation = saved.get("generation")
    return (generation if isinstance(generation, str) else None), saved["cursors"]


def write_cursors(directory: str | Path, generation: str | None, session: Session) -> None:
    """Keep the cursors of ``session``, made on ``generation``, beside the store (atomically)."""
    path = Path(directory) / _NAME
    temporary = path.with_suffix(".tmp")
    temporary.write_text(json.dumps({"generation": generation, "cursors": session.dump()}, indent=1), "utf-8")
    temporary.replace(path)


def resume_cursors(session: Session, directory: str | Path, generation: str | None) -> list[str]:
    """Give ``session`` (of the live ``generation``) the cursors kept beside the store: as they
    are when made on it, else carried over from the generation they were made on. Says, for
    cursors carried over or dropped, where each is now or why it starts afresh."""
    made_on, cursors = read_cursors(directory)
    if not cursors or made_on is None:
        return []
    if made_on == generation:
        session.load(cursors)
        return []
    try:
        old_kg = open_generation(directory, made_on)
    except CadkgError:
        return [f"cursors start afresh: the generation they were made on ({made_on}) is gone"]
    try:
        old = Session(old_kg.cell_model(), kg=old_kg)
        old.load(cursors)
        return session.carry_over(old)
    finally:
        old_kg.close()
