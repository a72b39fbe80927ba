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
from importlib import resources

from cadkg.ingest.reader import Reader
from cadkg.usecase import Derivation, DerivedKind, Planner, UseCase
from cadkg.usecases.iema import mapping as _mapping  # noqa: F401  (registers the record mappings)
from cadkg.usecases.iema.checks import cabinet_checks
from cadkg.usecases.iema.component_list import looks_like_component_list, read_component_list
from cadkg.usecases.iema.component_model import looks_like_component_models, read_component_models
from cadkg.usecases.iema.derive.cabinet import derive_cell
from cadkg.usecases.iema.derive.collect import InputCollector
from cadkg.usecases.iema.derive.emit import derived_graph, derived_ntriples
from cadkg.usecases.iema.derive.extract import extract
from cadkg.usecases.iema.derive.persist import dump_model, load_model
from cadkg.usecases.iema.derive.settings import DERIVE_SETTINGS
from cadkg.usecases.iema.derive.things import placed_pins, wire_ends
from cadkg.usecases.iema.marker_table import looks_like_marker_table, read_marker_table
from cadkg.usecases.iema.plan_tasks import DEFAULT_RULES, SETTINGS, iema_problem, order_check
from cadkg.usecases.iema.services import SERVICES, cabinet_frames
from cadkg.usecases.iema.terminal_diagram import looks_like_terminal_diagram, read_terminal_diagram
from cadkg.usecases.iema.terminal_schema import looks_like_terminal_schema, read_terminal_schema

__all__ = ["CABINET", "USE_CASE"]

CABINET = Derivation(
    collector=InputCollector,
    extract=extract,
    derive=derive_cell,
    graph=derived_graph,
    ntriples=derived_ntriples,
    dump=dump_model,
    load=load_model,
    settings=DERIVE_SETTINGS,
    adjust=lambda inputs, settings: dataclasses.replace(inputs, **settings),
    things={"pin": DerivedKind(placed_pins, queries=3), "wire": DerivedKind(wire_ends)},
    # Any cell's components sit at their scene items: a cell of a use case without a
    # derivation of its own gets the cabinet geometry without the cabinet's wiring.
    default=True,
)

USE_CASE = UseCase(
    name="iema",
    title="switchgear cabinet wiring (D3.1 section 4.1, Table 1)",
    section="4.1",
    readers=(
        Reader(
            "component-model",
            (".xml",),
            read_component_models,
            "Component models XML (<data><code>): size, screw and hole of each pin, children",
            looks_like_component_models,
        ),
        Reader(
            "component-list",
            (".csv", ".tsv"),
            read_component_list,
            "Component list: Component ID, Description, Part Number, Quantity, XML Data",
            looks_like_component_list,
        ),
        Reader(
            "terminal-schema",
            (".csv", ".xlsx", ".ods"),
            read_terminal_schema,
            "Terminal block schema: terminal items in order along each block, and their levels",
            looks_like_terminal_schema,
        ),
        Reader(
            "terminal-diagram",
            (".xlsx", ".xlsm", ".xls", ".ods"),
            read_terminal_diagram,
            "EPLAN terminal diagram (Schema Morsetti): the rows along each terminal strip, their wire ends",
            looks_like_terminal_diagram,
        ),
        Reader(
            "marker-table",
            (".ods", ".xlsx", ".xlsm", ".xls"),
            read_marker_table,
            "QR-code marker table: product, commercial code, label, CAD item, X/Y/Z (m) of each marker",
            looks_like_marker_table,
        ),
    ),
    services=SERVICES,
    queries=resources.files(__name__).joinpath("queries"),
    changes=resources.files(__name__).joinpath("changes"),
    ros_namespace="/gearbox_handler",
    derivation=CABINET,
    frames=cabinet_frames,
    checks=lambda kg: [*cabinet_checks(kg), *order_check(kg)],
    planner=Planner(DEFAULT_RULES, iema_problem, SETTINGS),
)
