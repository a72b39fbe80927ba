"""The Volkswagen services (profile ``vw``): the harness state a detection system starts from.

D3.1 section 4.4: the detection system reads a description of the harness and represents
its state in GraphML. ``harness_topology`` gives that description from the graph: the
topology (nodes with what sits on them, segments with length, diameter and wires), the
wires with their cavities and routes, and one GraphML view as text. The model is built from
the graph once per session (:func:`build_model`); an unknown harness or view gives
``success=False`` and a message.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

import networkx as nx

from cadkg.errors import NotFound, QueryError
from cadkg.services.service import Service, on_model
from cadkg.services.session import Session
from cadkg.usecases.vw.graphml import VIEWS, graphml_text
from cadkg.usecases.vw.views import LIST_SEPARATOR, HarnessRef, harnesses, topology_graph, wire_graph

if TYPE_CHECKING:
    from cadkg.graph import KnowledgeGraph

__all__ = [
    "SERVICES",
    "HarnessTopologyResult",
    "TopologyNode",
    "TopologySegment",
    "TopologyWire",
    "VwModel",
    "build_model",
    "harness_topology",
]

PROFILE = "vw"


@dataclass(frozen=True)
class TopologyNode:
    """A node of the topology: ``kind`` is connector, fixing, branch, end or inline."""

    id: str
    label: str
    kind: str
    degree: int
    connectors: tuple[str, ...]
    fixings: tuple[str, ...]


@dataclass(frozen=True)
class TopologySegment:
    """A segment between two nodes (by node id); metres; ``wires`` are wire labels."""

    id: str
    label: str
    from_node: str
    to_node: str
    length_m: float | None
    diameter_m: float | None
    wires: tuple[str, ...]
    fixings: tuple[str, ...]
    protections: tuple[str, ...]


@dataclass(frozen=True)
class TopologyWire:
    """A wire between two connector cavities and the segments it runs through, in route order."""

    id: str
    label: str
    from_connector: str
    from_cavity: str
    to_connector: str
    to_cavity: str
    section_mm2: float | None
    colour: str
    length_m: float | None
    segments: tuple[str, ...]


@dataclass(frozen=True)
class HarnessTopologyResult:
    success: bool
    message: str
    harness: str = ""
    file_format: str = ""
    nodes: tuple[TopologyNode, ...] = ()
    segments: tuple[TopologySegment, ...] = ()
    wires: tuple[TopologyWire, ...] = ()
    graphml: str = ""


@dataclass(frozen=True)
class VwModel:
    """Every harness of the graph with its two views (by harness IRI)."""

    harnesses: tuple[HarnessRef, ...]
    topology: Mapping[str, nx.MultiGraph]
    wires: Mapping[str, nx.MultiGraph]


def build_model(kg: KnowledgeGraph) -> VwModel:
    """The views of every harness in the graph, from SPARQL over it."""
    refs = tuple(harnesses(kg))
    return VwModel(
        refs,
        {r.iri: topology_graph(kg, r.iri) for r in refs},
        {r.iri: wire_graph(kg, r.iri) for r in refs},
    )


def _split(value: str) -> tuple[str, ...]:
    return tuple(value.split(LIST_SEPARATOR)) if value else ()


def _find(model: VwModel, harness: str) -> HarnessRef:
    if not model.harnesses:
        raise NotFound("the graph holds no harness")
    if not harness:
        if len(model.harnesses) > 1:
            names = ", ".join(r.label for r in model.harnesses)
            raise QueryError(f"the graph holds {len(model.harnesses)} harnesses; name one: {names}")
        return model.harnesses[0]
    for ref in model.harnesses:
        if harness in (ref.label, ref.id, ref.iri):
            return ref
    raise NotFound(f"no harness {harness!r}; known: {', '.join(r.label for r in model.harnesses)}")


def harness_topology(model: VwModel, harness: str = "", view: str = "topology") -> HarnessTopologyResult:
    """The topology and wires of a harness, and its ``view`` (topology or wires) as GraphML.

    ``harness`` is the harness label (a KBL part number, a text description's name), its id
    or IRI; it may be empty when the graph holds one harness.
    """
    view = view or "topology"
    if view not in VIEWS:
        return HarnessTopologyResult(False, f"unknown view {view!r}; one of {', '.join(VIEWS)}")
    try:
        ref = _find(model, harness)
    except (NotFound, QueryError) as err:
        return HarnessTopologyResult(False, str(err))
    topology, wires = model.topology[ref.iri], model.wires[ref.iri]
    nodes = tuple(
        TopologyNode(
            node,
            data["label"],
            data["kind"],
            data["degree"],
            _split(data["connectors"]),
            _split(data["fixings"]),
        )
        for node, data in sorted(topology.nodes(data=True))
    )
    segments = tuple(
        TopologySegment(
            key,
            data["label"],
            data["from_node"],
            data["to_node"],
            data.get("length_m"),
            data.get("diameter_m"),
            _split(data["wires"]),
            _split(data["fixings"]),
            _split(data["protections"]),
        )
        for _, _, key, data in sorted(topology.edges(keys=True, data=True), key=lambda e: e[2])
    )
    wire_list = []
    for _, _, key, data in sorted(wires.edges(keys=True, data=True), key=lambda e: e[2]):
        start, end = wires.nodes[data["from_cavity"]], wires.nodes[data["to_cavity"]]
        wire_list.append(
            TopologyWire(
                key,
                data["label"],
                start["connector"],
                start["cavity"],
                end["connector"],
                end["cavity"],
                data.get("section_mm2"),
                data.get("colour", ""),
                data.get("length_m"),
                _split(data["segments"]),
            )
        )
    graph = topology if view == "topology" else wires
    message = (
        f"{ref.label}: {len(nodes)} nodes, {len(segments)} segments, {len(wire_list)} wires"
        if segments or wire_list
        else f"{ref.label}: no topology or wires in the graph"
    )
    return HarnessTopologyResult(
        True, message, ref.label, ref.file_format, nodes, segments, tuple(wire_list), graphml_text(graph)
    )


def _model(session: Session) -> VwModel:
    return session.profile_model(PROFILE, build_model)


SERVICES: tuple[Service, ...] = (
    Service(
        "harness_topology",
        "a harness's nodes, segments (length, diameter, wires) and wires (cavities, route), and GraphML",
        {"harness": str, "view": str},
        on_model(harness_topology, _model),
        profile=PROFILE,
        optional=frozenset({"harness", "view"}),
    ),
)
