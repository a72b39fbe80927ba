"""What the ROS node serves, loaded from a store directory, a manifest or a remote endpoint:
the graph, its derived model, the scene's placements and the session the services share."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cadkg.registry as registry
from cadkg.errors import CadkgError
from cadkg.graph import KnowledgeGraph
from cadkg.query.placements import Placements, placements
from cadkg.services.session import Session
from cadkg.store import cell_profile

__all__ = ["Loaded", "load"]


@dataclass
class Loaded:
    """One generation of what the node serves: graph, derived model, cursors, profile."""

    kg: KnowledgeGraph
    placements: Placements
    model: Any
    session: Session
    profile: str


def load(source: str, approach_distance: float | None = None, *, writable: bool = False) -> Loaded:
    """Open a store directory (read-only unless ``writable``: then assignments are kept in it),
    build a manifest in memory, or read a remote SPARQL endpoint (an http(s) URL; credentials
    from CADKG_STORE_AUTH[_DIGEST]), and derive the model.

    Raises
    ------
    CadkgError
        When the source cannot be read, or an ``approach_distance`` is given for a cell whose
        derivation takes no settings.
    """
    path = Path(source)
    if source.lower().startswith(("http://", "https://")):
        from cadkg.remote import RemoteGraph, auth_from_env

        kg: KnowledgeGraph = RemoteGraph(source, auth=auth_from_env())
    elif path.is_dir():
        kg = KnowledgeGraph.open(path, read_only=not writable)
    elif path.is_file():
        kg = KnowledgeGraph.build(path)
    else:
        raise CadkgError(f"{source!r} is neither a store directory nor a manifest file")
    profile = cell_profile(kg)
    derivation = registry.derivation(profile)
    if approach_distance is not None and approach_distance >= 0 and derivation is not None:
        if derivation.adjust is None:
            raise CadkgError(f"the cell model of a {profile or 'default'} cell takes no approach_distance")
        model = derivation.derive(
            derivation.adjust(derivation.extract(kg), {"approach_distance": approach_distance})
        )
    else:
        # The store keeps the model; only the frames and meshes are read from the graph.
        model = kg.cell_model()
    return Loaded(kg, placements(kg), model, Session(model, kg=kg), profile)
