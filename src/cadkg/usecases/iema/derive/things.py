"""A cabinet's placed pins and wires as a revision diff finds them, from its derived model.

The same things the kinds' queries (``usecases/iema/changes/pin.rq``, ``wire.rq``) find in the
graph written from this model and its sources (tests/changes/test_derived_things.py).
"""

from __future__ import annotations

from cadkg.changes.things import Thing, Value
from cadkg.mapping.writer import node_iri
from cadkg.usecases.iema.derive.cabinet import CellModel

__all__ = ["placed_pins", "wire_ends"]


def placed_pins(model: CellModel) -> list[Thing]:
    """Each pin with a hole, by its component's label and its name; its screw relative to its
    component (the three queries of ``pin.rq``)."""
    things = []
    for label, component in model.components.items():
        at = component.original
        back = None if at is None else at.inverse()
        for name, pin in component.pins.items():
            if pin.hole is None:
                continue
            pose = None if back is None or pin.screw is None else back * pin.screw
            iri = pin.iri if pin.iri is not None else node_iri(model.base, "derived", label, "pin", name)
            things.append(Thing("pin", f"{label}:{name}", iri, {}, pose))
    return things


def wire_ends(model: CellModel) -> list[Thing]:
    """Each wire by its number and its two ends, in either order (the first query of ``wire.rq``)."""
    things = []
    for step in model.steps:
        ends = [f"{end.label}:{end.pin}" for end in (step.origin, step.destination)]
        key = " ".join(sorted(ends))
        attributes: dict[str, Value] = {"from": ends[0], "to": ends[1]}
        things.append(Thing("wire", step.wire, step.iri, attributes, None, {"key_ends": key}))
    return things
