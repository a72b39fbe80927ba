"""What ``cadkg validate`` finds in an ELVEZ cell besides the shapes: names one file gives and
no other defines, each at the line that names it.

Real cells are not always consistent (a sequence naming a harness no file defines, a harness
kept in a box no platform has): the build goes through and the services answer what is
known; these findings say where the rest is missing.
"""

from __future__ import annotations

from typing import Any

from cadkg.errors import CadkgError
from cadkg.query.validate import Finding
from cadkg.usecases.elvez.files.harnesses import split_tray
from cadkg.usecases.elvez.model import ElvezModel, build_model, unresolved
from cadkg.usecases.elvez.plan_tasks import order_findings, source_path

__all__ = ["findings"]

_CHECK = "elvez"


def findings(kg: Any) -> list[Finding]:
    """Dangling names and gaps of an ELVEZ cell, located at the file and line naming them."""
    try:
        model = build_model(kg)
    except CadkgError as err:
        return [Finding("(cell)", "error", _CHECK, f"the ELVEZ model cannot be built: {err}")]
    found = []
    for step, where in zip(model.sequence, model.step_where, strict=True):
        found += [Finding(where, "error", _CHECK, note) for note in unresolved(model, step)]
    found += order_findings(kg, model)
    found += _harness_findings(kg, model)
    found += _element_findings(kg, model)
    components = source_path(kg, "elvez-components")
    for component in model.components.values():
        if component.colour and component.rgb is None:
            found.append(
                Finding(
                    f"{components}:{component.line}",
                    "warning",
                    _CHECK,
                    f"colour {component.colour!r} of {component.label} has no red, green, blue values",
                )
            )
    return found


def _harness_findings(kg: Any, model: ElvezModel) -> list[Finding]:
    path = source_path(kg, "elvez-harnesses")
    found = []
    for harness in model.harnesses:
        where = f"{path}:{harness.line}"
        box, tray = split_tray(harness.tray)
        element = model.element(box) if box else None
        if box and (element is None or element.type != "box"):
            found.append(
                Finding(
                    where,
                    "error",
                    _CHECK,
                    f"tray {harness.tray} of harness {harness.id}: no box {box} on the platforms",
                )
            )
        elif element is not None:
            definition = model.definition(element)
            if definition is not None and tray not in {t.id for t in definition.trays}:
                found.append(
                    Finding(
                        where,
                        "error",
                        _CHECK,
                        f"tray {harness.tray} of harness {harness.id}: {box} has no tray {tray}",
                    )
                )
        labels = [harness.first_connector] + [c.label for e in harness.end_connectors for c in e.cables]
        missing = [label for label in labels if label not in model.components]
        if missing:
            found.append(
                Finding(
                    where,
                    "warning",
                    _CHECK,
                    f"harness {harness.id}: not in the components definition: {', '.join(missing)}",
                )
            )
    return found


def _element_findings(kg: Any, model: ElvezModel) -> list[Finding]:
    found = []
    first: dict[str, str] = {}
    uncentred: dict[str, list[str]] = {}
    for element in model.elements:
        if not element.type or element.type == "table":
            continue
        if element.label in first:
            found.append(
                Finding(
                    element.where,
                    "error",
                    _CHECK,
                    f"label {element.label} already names an element at {first[element.label]}",
                )
            )
            continue
        first[element.label] = element.where
        if element.frame not in model.tree:
            found.append(
                Finding(
                    element.where,
                    "error",
                    _CHECK,
                    f"{element.label}: no Transform {element.cad_id} in the {element.platform} scene",
                )
            )
        definition = model.definition(element)
        if definition is None:
            found.append(
                Finding(
                    element.where,
                    "error",
                    _CHECK,
                    f"{element.label}: no definition of model {element.model or '(none)'}",
                )
            )
        elif element.type == "jig" and definition.centre is None:
            uncentred.setdefault(definition.model, []).append(element.label)
    path = source_path(kg, "elvez-definitions")
    for code, labels in uncentred.items():
        found.append(
            Finding(
                f"{path}:{model.definitions[code].line}",
                "warning",
                _CHECK,
                f"jig model {code} ({', '.join(labels)}) gives no xcenter, ycenter, xcolli, ycolli: "
                "all_guides answers without its centre and footprint",
            )
        )
    return found
