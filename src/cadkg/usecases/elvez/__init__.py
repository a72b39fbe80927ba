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

from cadkg.ingest.reader import Reader
from cadkg.usecase import Planner, UseCase
from cadkg.usecases.elvez import mapping as _mapping  # noqa: F401  (registers the record mappings)
from cadkg.usecases.elvez.checks import findings
from cadkg.usecases.elvez.files.components import looks_like_components, read_components
from cadkg.usecases.elvez.files.definitions import looks_like_element_definitions, read_element_definitions
from cadkg.usecases.elvez.files.harnesses import looks_like_harness_configuration, read_harness_configuration
from cadkg.usecases.elvez.files.platforms import read_platform_ids, read_platform_mesh, read_platform_scene
from cadkg.usecases.elvez.files.sequence import looks_like_sequence, read_sequence
from cadkg.usecases.elvez.plan_tasks import DEFAULT_RULES, elvez_problem
from cadkg.usecases.elvez.scene import platform_scene
from cadkg.usecases.elvez.services import SERVICES, element_meshes, platform_frames

__all__ = ["USE_CASE"]

USE_CASE = UseCase(
    name="elvez",
    title="wire harness assembly on jigs and guides (D3.1 section 4.3, Table 2)",
    section="4.3",
    readers=(
        Reader(
            "elvez-scene",
            (".x3d",),
            read_platform_scene,
            "ELVEZ platform scene (Blender X3D, mm; in an elvez cell): element frames, broken shapes skipped",
        ),
        Reader(
            "elvez-ids",
            (".wri",),
            read_platform_ids,
            "ELVEZ platform WRI table (in an elvez cell): CAD ID, label (T/J/B/C/A + name), commercial code",
        ),
        Reader(
            "elvez-mesh",
            (".stl",),
            read_platform_mesh,
            "ELVEZ element mesh (STL in mm, binary or ASCII) of the platform its folder names",
        ),
        Reader(
            "elvez-definitions",
            (".xml",),
            read_element_definitions,
            "ELVEZ element definitions (Jigs_definition_v2.xml): jigs, combs, boxes, ATC stations",
            looks_like_element_definitions,
        ),
        Reader(
            "elvez-harnesses",
            (".xml",),
            read_harness_configuration,
            "ELVEZ wiring harnesses (WH_configuration.xml): first connector, tray, end connectors, cables",
            looks_like_harness_configuration,
        ),
        Reader(
            "elvez-components",
            (".csv",),
            read_components,
            "ELVEZ components (Components_definition.csv): connectors, cables, devices; colour, sizes in mm",
            looks_like_components,
        ),
        Reader(
            "elvez-sequence",
            (".csv",),
            read_sequence,
            "ELVEZ assembly sequence (Assembly_sequence.csv): Order;Type of operation;Label;Spot",
            looks_like_sequence,
        ),
    ),
    services=SERVICES,
    queries=resources.files(__name__).joinpath("queries"),
    changes=resources.files(__name__).joinpath("changes"),
    ros_namespace="/elvez",
    frames=platform_frames,
    markers=element_meshes,
    scene=platform_scene,
    checks=findings,
    planner=Planner(DEFAULT_RULES, elvez_problem),
)
