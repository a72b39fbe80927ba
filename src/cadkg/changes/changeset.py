"""What changed between two revisions: added, removed and changed things."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

__all__ = ["Change", "ChangeSet"]


@dataclass(frozen=True)
class Change:
    """One thing added, removed or changed; ``attributes`` maps a changed attribute to its old and
    new value, ``offset`` is a move (``translation`` and ``distance`` in metres, ``rotation_deg``)."""

    change: str  # added, removed or changed
    kind: str
    id: str
    old_iri: str | None = None
    new_iri: str | None = None
    attributes: dict[str, tuple[Any, Any]] = field(default_factory=dict)
    offset: dict[str, Any] | None = None

    @property
    def iri(self) -> str | None:
        """The thing's IRI in the newest revision that has it."""
        return self.new_iri or self.old_iri

    def to_json(self) -> dict[str, Any]:
        item: dict[str, Any] = {"kind": self.kind, "id": self.id}
        if self.iri is not None:
            item["iri"] = self.iri
        if self.change == "changed":
            item["attributes"] = {name: list(pair) for name, pair in self.attributes.items()}
            if self.offset is not None:
                item["offset"] = self.offset
        return item


@dataclass
class ChangeSet:
    """The changes from revision ``old`` to revision ``new`` (their names: paths, generations)."""

    old: str = ""
    new: str = ""
    added: list[Change] = field(default_factory=list)
    removed: list[Change] = field(default_factory=list)
    changed: list[Change] = field(default_factory=list)
    # What the changes mean for a plan and the cursors (:class:`cadkg.changes.impact.Impact`).
    impact: Any = None

    def __bool__(self) -> bool:
        return bool(self.added or self.removed or self.changed)

    def __iter__(self) -> Any:
        return iter([*self.added, *self.removed, *self.changed])

    def counts(self) -> dict[str, int]:
        return {"added": len(self.added), "removed": len(self.removed), "changed": len(self.changed)}

    def of(self, change: Change) -> None:
        {"added": self.added, "removed": self.removed, "changed": self.changed}[change.change].append(change)

    def to_json(self) -> dict[str, Any]:
        """``{"old", "new", "added", "removed", "changed"}``, items ``{"kind", "id", ...}``, and
        ``impact`` when a plan or a cursor was looked at."""
        data: dict[str, Any] = {
            "old": self.old,
            "new": self.new,
            "added": [c.to_json() for c in self.added],
            "removed": [c.to_json() for c in self.removed],
            "changed": [c.to_json() for c in self.changed],
        }
        if self.impact is not None:
            data["impact"] = self.impact.to_json()
        return data
