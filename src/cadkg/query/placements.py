"""Where a cell's source files put things: every frame's parent and pose, every scene item's
mesh. Every cell has them, whatever its use case; ``/tf_static``, the markers and the 3D
workbench start from them, and a derivation reads them with the rest of its inputs.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import product
from typing import TYPE_CHECKING

from cadkg.geometry.poses import Pose
from cadkg.query.tables import SourceTables, source_tables

if TYPE_CHECKING:
    from cadkg.store import GraphStore

__all__ = ["Placements", "frames_of", "meshes_of", "placements"]

_CELL = "SELECT ?cell WHERE { ?cell a ck:Cell } LIMIT 1"


@dataclass
class Placements:
    """Where the source files put things: each frame's parent and pose, each item's mesh."""

    frames: dict[str, tuple[str, Pose]]
    meshes: dict[str, str]


def placements(kg: GraphStore) -> Placements:
    """The frames and meshes of the cell's source graphs, read without the rest.

    What ``/tf_static`` and the markers need besides the derived model, which a store keeps:
    a quarter of the time of a whole extraction of a cabinet's inputs on an on-disk store.
    """
    cell = kg.query(_CELL).rows
    tables = source_tables(kg, cell[0]["cell"].removesuffix("cell/this") if cell else "")
    return Placements(frames_of(tables), meshes_of(tables))


def frames_of(tables: SourceTables) -> dict[str, tuple[str, Pose]]:
    """Every labelled ``ck:Frame`` with a pose: its parent frame's label and its pose there."""
    labels, poses = tables.values("label"), tables.poses()
    frames: dict[str, tuple[str, Pose]] = {}
    for frame in tables.instances("Frame"):
        for pose in tables.values("hasPose").get(frame, ()):
            if pose in poses:
                parents = tables.follow(pose, "parentFrame", "label")
                for name, parent in product(labels.get(frame, ()), parents):
                    frames[name] = (parent, poses[pose])
    return frames


def meshes_of(tables: SourceTables) -> dict[str, str]:
    """Every scene item's mesh file (``ck:meshUri``) by its CAD id."""
    return {
        ident: uri
        for item, ids in tables.values("cadId").items()
        for ident in ids
        for uri in tables.follow(item, "hasMesh", "meshUri")
    }
