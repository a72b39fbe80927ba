"""The Volkswagen services (profile ``vw``): the harness state a detection system starts from.

D3.1 section 4.4: the detection system reads a description of the harness and represents
its state in GraphML. ``harness_topology`` gives that description from the graph: the
topology (nodes with what sits on them and their positions, segments with length, diameter
and wires), the wires with their cavities and routes, and one GraphML view as text, of the
whole harness or of the variant of some of its modules. The harnesses' data are read from
the graph once per session (:func:`build_model`); an unknown harness, view or module gives
``success=False`` and a message.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING

from cadkg.errors import NotFound, QueryError
from cadkg.services.service import Effect, Service, on_model
from cadkg.services.session import Session
from cadkg.usecase import Answer
from cadkg.usecases.vw.graphml import VIEWS, graphml_text
from cadkg.usecases.vw.harness_data import HarnessRef, WireData, choose_harness, harnesses, wire_data
from cadkg.usecases.vw.views import LIST_SEPARATOR, choose_modules, topology_view, wire_view

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
    # metres, REP 103 axes; None where the description gives no position
    x: float | None = None
    y: float | None = None
    z: float | None = None


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
class HarnessTopologyResult(Answer):
    harness: str = ""
    file_format: str = ""
    nodes: tuple[TopologyNode, ...] = ()
    segments: tuple[TopologySegment, ...] = ()
    wires: tuple[TopologyWire, ...] = ()
    graphml: str = ""


@dataclass(frozen=True)
class VwModel:
    """Every harness of the graph with the data of its views (by harness IRI)."""

    harnesses: tuple[HarnessRef, ...]
    data: Mapping[str, WireData]


def build_model(kg: KnowledgeGraph) -> VwModel:
    """The data of the views of every harness in the graph."""
    refs = tuple(harnesses(kg))
    return VwModel(refs, {r.iri: wire_data(kg, r, whole=True) for r in refs})


def _split(value: str) -> tuple[str, ...]:
    return tuple(value.split(LIST_SEPARATOR)) if value else ()


def harness_topology(
    model: VwModel, harness: str = "", view: str = "topology", modules: str = ""
) -> HarnessTopologyResult:
    """The topology and wires of a harness, and its ``view`` (topology or wires) as GraphML.

    ``harness`` is the harness label (a KBL part number, a text description's name), its id
    or IRI; it may be empty when the graph holds one harness. ``modules`` (comma separated
    module names, or a configuration's name) gives the variant of a modular harness holding them.
    """
    view = view or "topology"
    if view not in VIEWS:
        return HarnessTopologyResult(False, f"unknown view {view!r}; one of {', '.join(VIEWS)}")
    try:
        ref = choose_harness(list(model.harnesses), harness)
        data = model.data[ref.iri]
        variant = choose_modules(data.topology, [m.strip() for m in modules.split(",") if m.strip()])
    except (NotFound, QueryError) as err:
        return HarnessTopologyResult(False, str(err))
    topology, wires = topology_view(data.topology, variant), wire_view(data, variant)
    nodes = tuple(
        TopologyNode(
            node,
            attributes["label"],
            attributes["kind"],
            attributes["degree"],
            _split(attributes["connectors"]),
            _split(attributes["fixings"]),
            attributes.get("x"),
            attributes.get("y"),
            attributes.get("z"),
        )
        for node, attributes in topology.nodes
    )
    segments = tuple(
        TopologySegment(
            key,
            attributes["label"],
            attributes["from_node"],
            attributes["to_node"],
            attributes.get("length_m"),
            attributes.get("diameter_m"),
            _split(attributes["wires"]),
            _split(attributes["fixings"]),
            _split(attributes["protections"]),
        )
        for _, _, key, attributes in topology.edges
    )
    cavities = dict(wires.nodes)
    wire_list = []
    for _, _, key, attributes in wires.edges:
        start, end = cavities[attributes["from_cavity"]], cavities[attributes["to_cavity"]]
        wire_list.append(
            TopologyWire(
                key,
                attributes["label"],
                start["connector"],
                start["cavity"],
                end["connector"],
                end["cavity"],
                attributes.get("section_mm2"),
                attributes.get("colour", ""),
                attributes.get("length_m"),
                _split(attributes["segments"]),
            )
        )
    graph = topology if view == "topology" else wires
    name = ref.label + (f" ({', '.join(variant.labels)})" if variant.modules is not None else "")
    message = (
        f"{name}: {len(nodes)} nodes, {len(segments)} segments, {len(wire_list)} wires"
        if segments or wire_list
        else f"{name}: no topology or wires in the graph"
    )
    for warning in dict.fromkeys(graph.warnings):
        message += f"; warning: {warning}"
    return HarnessTopologyResult(
        True, message, ref.label, ref.file_format, nodes, segments, tuple(wire_list), graphml_text(graph)
    )


def _model(session: Session) -> VwModel:
    return session.profile_model(PROFILE, build_model)


SERVICES: tuple[Service, ...] = (
    Service(
        "harness_topology",
        "a harness's nodes (position), segments (length, diameter, wires) and wires (cavities, route), "
        "and GraphML; of the variant of some modules",
        {"harness": str, "view": str, "modules": str},
        on_model(harness_topology, _model),
        effect=Effect.READS,
        profile=PROFILE,
        optional=frozenset({"harness", "view", "modules"}),
    ),
)
