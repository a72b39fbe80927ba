"""Which tf frames belong to a label: a component's CAD items (their frames are named by CAD
id, as the scene's DEF names them) and the frames derived for it (``LABEL/original`` ...)."""

from __future__ import annotations

from collections.abc import Iterable
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from cadkg.store import GraphStore

__all__ = ["label_frames"]

_ITEMS = """SELECT DISTINCT ?label ?cadId WHERE {
  ?component ck:label ?label ; ck:hasItem ?item .
  ?item ck:cadId ?cadId .
}"""


def label_frames(kg: GraphStore, published: Iterable[str], label: str = "") -> list[tuple[str, str]]:
    """``(label, frame id)`` pairs among the ``published`` frame ids, sorted; only ``label``'s
    when one is given (an unknown label gives none)."""
    frames = set(published)
    rows = kg.query(_ITEMS, label=label).rows if label else kg.query(_ITEMS).rows
    pairs = {(str(row["label"]), str(row["cadId"])) for row in rows if str(row["cadId"]) in frames}
    labels = {label} if label else {name for name, _ in pairs}
    for frame in frames:
        owner = frame.rsplit("/", 1)[0]
        if "/" in frame and owner in labels:
            pairs.add((owner, frame))
    return sorted(pairs)
