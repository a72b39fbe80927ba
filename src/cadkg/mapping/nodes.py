"""The nodes several mappings share: components, pins, wires, frames, models, meshes.

Each is described once per graph (:meth:`TripleWriter.once`), whichever record meets it first,
and gets the same IRI in every graph, so that files join on it.
"""

from __future__ import annotations

from collections.abc import Sequence
from decimal import Decimal

from cadkg.confined import file_name
from cadkg.ingest.eplan.labels import PinRef
from cadkg.ingest.placement import Placement
from cadkg.mapping.writer import TYPE, XSD, TripleWriter, literal, node_iri, term, write_pose

__all__ = [
    "cable_node",
    "component_node",
    "connector_node",
    "dimensions",
    "frame_node",
    "item_mesh_file",
    "mesh_node",
    "model_frame",
    "model_node",
    "model_pin",
    "named_node",
    "pin_iri",
    "pin_node",
    "placement_pose",
    "texts",
    "wire_iri",
]


def component_node(w: TripleWriter, label: str, kind: str = "Component") -> str:
    """The component ``label``, labelled once per graph and typed ``kind`` when this graph
    describes it first."""
    node = w.components.get(label)
    if node is not None:
        return node  # described, or found described, by its first call
    node = w.components[label] = w.iri("component", label)
    if w.once(node):
        w.add(node, TYPE, term(kind))
        w.add(node, term("label"), w.text(label))
    return node


def named_node(
    w: TripleWriter, kind: str, name: str, cls: str, *, by: str = "label", once: bool = False
) -> str:
    """The ``cls`` minted from its name (``{base}{kind}/{name}``), given the name as its ``by``;
    with ``once``, described only by the first record that meets it in the graph."""
    node = w.iri(kind, name)
    if not once or w.once(node):
        w.add(node, TYPE, term(cls))
        w.add(node, term(by), w.text(name))
    return node


def texts(w: TripleWriter, node: str, **values: str | None) -> None:
    """The given text properties (ontology term → value) that are neither None nor empty."""
    for name, value in values.items():
        if value:
            w.add(node, term(name), w.text(value))


def pin_iri(base_iri: str, ref: PinRef) -> str:
    """The IRI of the pin ``ref`` names: component, pin and, on a terminal, its level."""
    if ref.level is None:
        return node_iri(base_iri, "pin", ref.component, ref.pin)
    return node_iri(base_iri, "pin", ref.component, ref.pin, ref.level)


def wire_iri(base_iri: str, number: str, taken: set[str]) -> str:
    """The IRI of the wire ``number`` not in ``taken`` (the wires of its file so far), added to it.

    A number a list repeats gets ``~2``, ``~3`` ... so that no row is lost.
    """
    iri = node_iri(base_iri, "wire", number)
    occurrence = 1
    while iri in taken:
        occurrence += 1
        iri = node_iri(base_iri, "wire", f"{number}~{occurrence}")
    taken.add(iri)
    return iri


def item_mesh_file(item_id: str) -> str:
    """Where the STL mesh of scene item ``item_id`` is kept, relative to the store's files."""
    # The ID comes from the file (an X3D DEF): one component, whatever it holds.
    return f"meshes/{file_name(item_id)}.stl"


_PIN, _PIN_NAME, _LEVEL, _PIN_OF, _HAS_PIN = (term(n) for n in ("Pin", "pinName", "level", "pinOf", "hasPin"))


def pin_node(w: TripleWriter, ref: PinRef) -> str:
    """The pin ``ref`` names, with its component, described once per graph."""
    key = (ref.component, ref.pin, ref.level)
    node = w.pins.get(key)
    if node is not None:
        return node
    node = w.pins[key] = f"<{pin_iri(w.base, ref)}>"
    if w.once(node):
        component = component_node(w, ref.component)
        level = "" if ref.level is None else f"{node} {_LEVEL} {literal(ref.level)} .\n"
        w.add_block(
            f"{node} {TYPE} {_PIN} .\n{node} {_PIN_NAME} {literal(ref.pin)} .\n{level}"
            f"{node} {_PIN_OF} {component} .\n{component} {_HAS_PIN} {node} .\n",
            4 if ref.level is None else 5,
        )
    return node


def frame_node(w: TripleWriter, name: str) -> str:
    """The frame called ``name`` (a ROS frame id), described once per graph."""
    return named_node(w, "frame", name, "Frame", once=True)


def placement_pose(w: TripleWriter, node: str, placement: Placement, parent: str) -> str:
    """A pose read from a file (roll, pitch, yaw) in frame ``parent``, with its line."""
    pose = write_pose(w, node, placement.xyz, placement.quaternion(), parent)
    w.add(pose, term("sourceLine"), w.typed(placement.line))
    return pose


def model_node(w: TripleWriter, key: str) -> str:
    """The commercial model ``key`` (a component model, a WRI commercial code, a model number)."""
    return named_node(w, "model", key, "CommercialModel", by="commercialCode", once=True)


def model_frame(w: TripleWriter, model: str, key: str) -> str:
    """The frame of the commercial model ``key`` (node ``model``), in which its poses are given."""
    frame = w.iri("model", key, "frame")
    w.add(frame, TYPE, term("Frame"))
    w.add(frame, term("label"), w.text(f"model {key}"))
    w.add(model, term("hasFrame"), frame)
    return frame


# A component model's couples and a part's connection points stay apart (see
# cadkg.mapping.eplan), each linked from its model by its own term.
def model_pin(w: TripleWriter, model: str, key: str, segment: str, defines: str, name: str, line: int) -> str:
    """The pin ``name`` that the commercial model ``key`` (node ``model``) defines through the
    predicate ``defines``, at ``model/KEY/SEGMENT/NAME``, with its line: a couple of its
    component model or a connection point of its part."""
    pin = w.iri("model", key, segment, name)
    w.add(model, defines, pin)
    w.add(pin, TYPE, term("ModelPin"))
    w.add(pin, term("pinName"), w.text(name))
    w.add(pin, term("sourceLine"), w.typed(line))
    return pin


def dimensions(w: TripleWriter, node: str, sizes: Sequence[float | Decimal]) -> None:
    """Size along x, y, z in metres."""
    for name, value in zip(("xDim", "yDim", "zDim"), sizes, strict=True):
        w.add(node, term(name), w.typed(float(value)))


def mesh_node(w: TripleWriter, owner: str, mesh: str, rel: str) -> None:
    """``owner`` has the mesh node ``mesh`` whose STL file is ``rel`` in the store's files."""
    w.add(owner, term("hasMesh"), mesh)
    w.add(mesh, TYPE, term("Mesh"))
    w.add(mesh, term("meshUri"), f'"{rel}"^^<{XSD}anyURI>')


def connector_node(w: TripleWriter, label: str) -> str:
    """The component ``label``, typed a connector."""
    node = component_node(w, label)
    if w.once(node + "#connector"):
        w.add(node, TYPE, term("Connector"))
    return node


def cable_node(w: TripleWriter, name: str) -> str:
    """The cable ``name``, one node whichever file mentions it."""
    return named_node(w, "cable", name, "Cable", once=True)
