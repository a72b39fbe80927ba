"""IEMA: wiring a switchgear cabinet (D3.1 section 4.1, services of Table 1).

A robot mounts components on DIN rails and wires them from an EPLAN connection list. The
cabinet is described by the WRI ID table, the connection list, the component models (where
each pin's screw and hole sit), the component list, the terminal block schema and the CAD
scene; cadkg derives each component's pose, corner and target, each pin's screw and hole,
the rails, the clusters of connector points and the wires' routing keypoints, and serves the
component data and the cursors that hand the robot its next wire and rail.
"""

from __future__ import annotations

import dataclasses

from cadkg.ingest.reader import Reader, lazy
from cadkg.usecase import Derivation, DerivedKind, Planner, UseCase
from cadkg.usecases.iema.derive.settings import DERIVE_SETTINGS
from cadkg.usecases.iema.plan_scope import DEFAULT_RULES, SETTINGS

# The derivation, the planner, the checks and the readers are named, not imported: their
# modules (numpy, the scene's meshes, the planner) load when a cell first needs them,
# not whenever the registry lists the use cases.
_cabinet_checks = lazy("cadkg.usecases.iema.checks:cabinet_checks")
_order_check = lazy("cadkg.usecases.iema.plan_tasks:order_check")

__all__ = ["CABINET", "USE_CASE"]

CABINET = Derivation(
    collector=lazy("cadkg.usecases.iema.derive.collect:InputCollector"),
    extract=lazy("cadkg.usecases.iema.derive.extract:extract"),
    derive=lazy("cadkg.usecases.iema.derive.cabinet:derive_cell"),
    graph=lazy("cadkg.usecases.iema.derive.emit:derived_graph"),
    ntriples=lazy("cadkg.usecases.iema.derive.emit:derived_ntriples"),
    dump=lazy("cadkg.usecases.iema.derive.persist:dump_model"),
    load=lazy("cadkg.usecases.iema.derive.persist:load_model"),
    things={
        "pin": DerivedKind(lazy("cadkg.usecases.iema.derive.things:placed_pins"), queries=3),
        "wire": DerivedKind(lazy("cadkg.usecases.iema.derive.things:wire_ends")),
    },
    settings=DERIVE_SETTINGS,
    adjust=lambda inputs, settings: dataclasses.replace(inputs, **settings),
    # Any cell's components sit at their scene items: a cell of a use case without a
    # derivation of its own gets the cabinet geometry without the cabinet's wiring.
    default=True,
)

USE_CASE = UseCase(
    name="iema",
    package=__name__,
    title="switchgear cabinet wiring (D3.1 section 4.1, Table 1)",
    section="4.1",
    readers=(
        Reader(
            "component-model",
            (".xml",),
            "cadkg.usecases.iema.component_model:read_component_models",
            "Component models XML (<data><code>): size, screw and hole of each pin, children",
            "cadkg.usecases.iema.component_model:looks_like_component_models",
        ),
        Reader(
            "component-list",
            (".csv", ".tsv"),
            "cadkg.usecases.iema.component_list:read_component_list",
            "Component list: Component ID, Description, Part Number, Quantity, XML Data",
            "cadkg.usecases.iema.component_list:looks_like_component_list",
        ),
        Reader(
            "terminal-schema",
            (".csv", ".xlsx", ".ods"),
            "cadkg.usecases.iema.terminal_schema:read_terminal_schema",
            "Terminal block schema: terminal items in order along each block, and their levels",
            "cadkg.usecases.iema.terminal_schema:looks_like_terminal_schema",
        ),
        Reader(
            "terminal-diagram",
            (".xlsx", ".xlsm", ".xls", ".ods"),
            "cadkg.usecases.iema.terminal_diagram:read_terminal_diagram",
            "EPLAN terminal diagram (Schema Morsetti): the rows along each terminal strip, their wire ends",
            "cadkg.usecases.iema.terminal_diagram:looks_like_terminal_diagram",
        ),
        Reader(
            "marker-table",
            (".ods", ".xlsx", ".xlsm", ".xls"),
            "cadkg.usecases.iema.marker_table:read_marker_table",
            "QR-code marker table: product, commercial code, label, CAD item, X/Y/Z (m) of each marker",
            "cadkg.usecases.iema.marker_table:looks_like_marker_table",
        ),
    ),
    services="cadkg.usecases.iema.services:SERVICES",
    ros_namespace="/gearbox_handler",
    derivation=CABINET,
    frames=lazy("cadkg.usecases.iema.services:cabinet_frames"),
    checks=lambda kg: [*_cabinet_checks(kg), *_order_check(kg)],
    planner=Planner(DEFAULT_RULES, lazy("cadkg.usecases.iema.plan_tasks:iema_problem"), SETTINGS),
    mapping="cadkg.usecases.iema.mapping",
)
