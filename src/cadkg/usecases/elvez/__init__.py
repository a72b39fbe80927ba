"""ELVEZ: assembling wire harnesses on jigs and guides (D3.1 section 4.3, Table 2).

The cell's own files are read as they are: three platforms (the assembly platform with its
jigs, the combs holding the harnesses' connectors, the automatic tool changer), each a Blender
X3D scene with its WRI ID table and an STL folder; the element definitions of the jigs,
combs, boxes and ATC stations; the wiring harnesses, their components and the assembly
sequence. The services give what the robot's planner asks for: D3.1 Table 2's and those of the
reference's CAD platform node, with every point of interest in the robot's base frame.
"""

from __future__ import annotations

from importlib import resources

from cadkg.ingest.reader import Reader, lazy
from cadkg.usecase import Planner, UseCase

# The readers, the mappings, the checks and the planner are named, not imported: their modules
# (numpy, the scene reader, the planner) load when a cell first needs them.
DEFAULT_RULES = resources.files(__name__).joinpath("plan-rules.toml")

__all__ = ["USE_CASE"]

USE_CASE = UseCase(
    name="elvez",
    package=__name__,
    title="wire harness assembly on jigs and guides (D3.1 section 4.3, Table 2)",
    section="4.3",
    readers=(
        Reader(
            "elvez-scene",
            (".x3d",),
            "cadkg.usecases.elvez.files.platforms:read_platform_scene",
            "ELVEZ platform scene (Blender X3D, mm; in an elvez cell): element frames, broken shapes skipped",
        ),
        Reader(
            "elvez-ids",
            (".wri",),
            "cadkg.usecases.elvez.files.platforms:read_platform_ids",
            "ELVEZ platform WRI table (in an elvez cell): CAD ID, label (T/J/B/C/A + name), commercial code",
        ),
        Reader(
            "elvez-mesh",
            (".stl",),
            "cadkg.usecases.elvez.files.platforms:read_platform_mesh",
            "ELVEZ element mesh (STL in mm, binary or ASCII) of the platform its folder names",
        ),
        Reader(
            "elvez-definitions",
            (".xml",),
            "cadkg.usecases.elvez.files.definitions:read_element_definitions",
            "ELVEZ element definitions (Jigs_definition_v2.xml): jigs, combs, boxes, ATC stations",
            "cadkg.usecases.elvez.files.definitions:looks_like_element_definitions",
        ),
        Reader(
            "elvez-harnesses",
            (".xml",),
            "cadkg.usecases.elvez.files.harnesses:read_harness_configuration",
            "ELVEZ wiring harnesses (WH_configuration.xml): first connector, tray, end connectors, cables",
            "cadkg.usecases.elvez.files.harnesses:looks_like_harness_configuration",
        ),
        Reader(
            "elvez-components",
            (".csv",),
            "cadkg.usecases.elvez.files.components:read_components",
            "ELVEZ components (Components_definition.csv): connectors, cables, devices; colour, sizes in mm",
            "cadkg.usecases.elvez.files.components:looks_like_components",
        ),
        Reader(
            "elvez-sequence",
            (".csv",),
            "cadkg.usecases.elvez.files.sequence:read_sequence",
            "ELVEZ assembly sequence (Assembly_sequence.csv): Order;Type of operation;Label;Spot",
            "cadkg.usecases.elvez.files.sequence:looks_like_sequence",
        ),
    ),
    services="cadkg.usecases.elvez.services:SERVICES",
    ros_namespace="/elvez",
    frames=lazy("cadkg.usecases.elvez.services:platform_frames"),
    markers=lazy("cadkg.usecases.elvez.services:element_meshes"),
    scene=lazy("cadkg.usecases.elvez.scene:platform_scene"),
    checks=lazy("cadkg.usecases.elvez.checks:findings"),
    planner=Planner(DEFAULT_RULES, lazy("cadkg.usecases.elvez.plan_tasks:elvez_problem")),
    mapping="cadkg.usecases.elvez.mapping",
)
