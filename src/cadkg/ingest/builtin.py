"""Registration of the readers cadkg ships."""

from __future__ import annotations

from importlib import import_module

from cadkg.ingest.assignments import read_assignments
from cadkg.usecases.iema.component_list import looks_like_component_list, read_component_list
from cadkg.usecases.iema.component_model import looks_like_component_models, read_component_models
from cadkg.ingest.eplan.connection_list import iter_connection_list, read_connection_list
from cadkg.usecases.elimco.cable_list import workbook_strings
from cadkg.ingest.registry import Reader, register
from cadkg.usecases.iema.terminal_schema import looks_like_terminal_schema, read_terminal_schema
from cadkg.ingest.scene.vrml import read_vrml
from cadkg.ingest.wri import iter_wri, read_wri
from cadkg.ingest.scene.x3d import read_x3d

__all__: list[str] = []


def _looks_like_connection_list(head: bytes) -> bool:
    text = head.decode("utf-8", errors="replace").lower()
    return "componente:pin" in text or "component:pin" in text or "device:pin" in text


register(
    Reader(
        kind="wri",
        suffixes=(".wri",),
        read=read_wri,
        stream=iter_wri,
        description="WRI ID table: CAD item ID, label, commercial code (tab separated)",
    )
)
register(
    Reader(
        kind="connection-list",
        suffixes=(".csv", ".tsv", ".txt"),
        read=read_connection_list,
        stream=iter_connection_list,
        description="EPLAN connection list (Figure 3 form, Lista cablaggio, machine exports)",
        sniff=_looks_like_connection_list,
    )
)


def _looks_like_vrml97(head: bytes) -> bool:
    return head.removeprefix(b"\xef\xbb\xbf").startswith(b"#VRML V2.0")


register(
    Reader(
        kind="x3d",
        suffixes=(".x3d",),
        read=read_x3d,
        description="X3D scene (XML encoding): DEF-named Transforms and Groups, poses, boxes, meshes",
    )
)
register(
    Reader(
        kind="vrml",
        suffixes=(".wrl",),
        read=read_vrml,
        description="VRML97 scene (#VRML V2.0 utf8): DEF-named Transforms and Groups, poses, boxes, meshes",
        sniff=_looks_like_vrml97,
    )
)
register(
    Reader(
        kind="component-model",
        suffixes=(".xml",),
        read=read_component_models,
        description="Component models XML (<data><code>): size, screw and hole of each pin, children",
        sniff=looks_like_component_models,
    )
)
register(
    Reader(
        kind="component-list",
        suffixes=(".csv", ".tsv"),
        read=read_component_list,
        description="Component list: Component ID, Description, Part Number, Quantity, XML Data",
        sniff=looks_like_component_list,
    )
)


def _looks_like_terminal_schema(head: bytes) -> bool:
    # .xlsx is also the ELIMCO cable list's suffix, and a workbook is compressed: its header
    # is looked for among the strings of the sheet parts that start in the head.
    if head.startswith(b"PK\x03\x04"):
        head = "\t".join(workbook_strings(head)).encode("utf-8")
    return looks_like_terminal_schema(head)


register(
    Reader(
        kind="terminal-schema",
        suffixes=(".csv", ".xlsx", ".ods"),
        read=read_terminal_schema,
        description="Terminal block schema: terminal items in order along each block, and their levels",
        sniff=_looks_like_terminal_schema,
    )
)


def _looks_like_assignments(head: bytes) -> bool:
    first = head.decode("utf-8", errors="replace").lstrip("\ufeff").split("\n", 1)[0]
    return first.strip().lower().replace(";", ",").startswith("kind,id,performer")


register(
    Reader(
        kind="assignments",
        suffixes=(".csv",),
        read=read_assignments,
        description="robot/human assignment overlay: kind,id,performer (wire, component or operation)",
        sniff=_looks_like_assignments,
    )
)

# The mappings of the cabinet records register themselves with the mapping on import.
import_module("cadkg.usecases.iema.mapping")


def _register_elvez() -> None:
    # The ELVEZ harness-assembly cell; shared suffixes are told apart by the first element
    # (XML) or the header row (CSV).
    from cadkg.usecases.elvez.action_plan import looks_like_action_plan, read_action_plan
    from cadkg.usecases.elvez.element_models import looks_like_element_models, read_element_models
    from cadkg.usecases.elvez.tools import looks_like_tools, read_tools
    from cadkg.usecases.elvez.harness_components import looks_like_harness_components, read_harness_components
    from cadkg.usecases.elvez.harness_structure import looks_like_harness_structure, read_harness_structure

    for reader in (
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
    ):
        register(reader)
    import_module("cadkg.usecases.elvez.mapping")


_register_elvez()


def _register_vw() -> None:
    # Volkswagen harness descriptions: KBL files and the harness text format.
    from cadkg.usecases.vw.harness_text import looks_like_harness_text, read_harness_text
    from cadkg.ingest.harness.kbl import looks_like_kbl, read_kbl

    register(
        Reader(
            "kbl",
            (".kbl",),
            read_kbl,
            "KBL harness (VDA 4964) 2.3 SR-1, 2.4: connectors, topology, wires",
            looks_like_kbl,
        )
    )
    register(
        Reader(
            "harness-text",
            (".harness",),
            read_harness_text,
            "Harness text description: connectors, nodes, segments, wires with cavities",
            looks_like_harness_text,
        )
    )
    import_module("cadkg.mapping.harness")


_register_vw()


def _register_elimco_enki() -> None:
    # ELIMCO's cable list and route-design files, ENKI's hose products. Shared suffixes are
    # told apart by the root element (XML) or the header row (CSV and workbooks).
    from cadkg.usecases.elimco.cable_list import looks_like_cable_list, read_elimco_cable_list
    from cadkg.usecases.enki.hose import looks_like_hose_table, read_hoses
    from cadkg.usecases.elimco.route_design import (
        looks_like_cable_info,
        looks_like_path_info,
        looks_like_pin_info,
        read_cable_info,
        read_path_info,
        read_pin_info,
    )

    for reader in (
        Reader(
            "elimco-cable-list",
            (".csv", ".tsv", ".xlsx", ".ods"),
            read_elimco_cable_list,
            "ELIMCO cable list (Figure 11): PN, REP, ZONA_A, BORNIA_A, HILO, CABLE, LONGITUD, ZONA_B ...",
            looks_like_cable_list,
        ),
        Reader(
            "pin-info",
            (".xml",),
            read_pin_info,
            "Route design pin_info.xml (<pin_info>): bench pins, drawing position, role, double pins",
            looks_like_pin_info,
        ),
        Reader(
            "cable-info",
            (".xml",),
            read_cable_info,
            "Route design cable_info.xml (<cable_info>): cables, initial and final connector, length",
            looks_like_cable_info,
        ),
        Reader(
            "path-info",
            (".xml",),
            read_path_info,
            "Route design path_info.xml (<path_info>): route of each cable over the bench pins",
            looks_like_path_info,
        ),
        Reader(
            "hose",
            (".csv",),
            read_hoses,
            "Hose products: product, diameter_mm, optional length_m, material, bend_radius_mm",
            looks_like_hose_table,
        ),
    ):
        register(reader)
    import_module("cadkg.usecases.elimco.mapping")


_register_elimco_enki()
