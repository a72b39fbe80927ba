"""ELVEZ: assembling wire harnesses on guides (D3.1 section 4.3, services of Table 2).

Three platforms (the assembly platform with its jigs and guides, the combs, the automatic
tool changer) are merged into one frame tree, so every point of interest (a guide's key, a
taping spot) has a pose in the robot base frame; the harnesses, their components, the tools
and the assembly sequence are read beside them, and the services give the guides, cables,
connectors, harnesses, tools and operations the planner asks for.
"""

from __future__ import annotations

from importlib import resources

from cadkg.ingest.reader import Reader
from cadkg.usecase import UseCase
from cadkg.usecases.elvez import mapping as _mapping  # noqa: F401  (registers the record mappings)
from cadkg.usecases.elvez.action_plan import looks_like_action_plan, read_action_plan
from cadkg.usecases.elvez.element_models import looks_like_element_models, read_element_models
from cadkg.usecases.elvez.harness_components import looks_like_harness_components, read_harness_components
from cadkg.usecases.elvez.harness_structure import looks_like_harness_structure, read_harness_structure
from cadkg.usecases.elvez.services import SERVICES, element_meshes, platform_frames
from cadkg.usecases.elvez.tools import looks_like_tools, read_tools

__all__ = ["USE_CASE"]

USE_CASE = UseCase(
    name="elvez",
    title="wire harness assembly on guides (D3.1 section 4.3, Table 2)",
    section="4.3",
    readers=(
        Reader(
            "element-models",
            (".xml",),
            read_element_models,
            "Platform element models XML (<element_models>): size, key frames, key size, STL mesh",
            looks_like_element_models,
        ),
        Reader(
            "tools",
            (".xml",),
            read_tools,
            "Robot tools XML (<tools>): ATC slot, base-to-wrist and wrist-to-action frames, size",
            looks_like_tools,
        ),
        Reader(
            "harness-structure",
            (".xml",),
            read_harness_structure,
            "Harness structure XML (<harness_structure>): main connector, branches, cables, pins",
            looks_like_harness_structure,
        ),
        Reader(
            "harness-components",
            (".csv", ".tsv"),
            read_harness_components,
            "Harness components: name, type, red, green, blue, diameter_mm, length_mm, x/y/z_mm",
            looks_like_harness_components,
        ),
        Reader(
            "action-plan",
            (".csv", ".tsv"),
            read_action_plan,
            "ELVEZ action plan: index, operation (insert/route/tape), components, spots, tool",
            looks_like_action_plan,
        ),
    ),
    services=SERVICES,
    queries=resources.files(__name__).joinpath("queries"),
    ros_namespace="/elvez",
    frames=platform_frames,
    markers=element_meshes,
)
