"""Registration of the readers cadkg ships."""

from __future__ import annotations

from importlib import import_module

from cadkg.ingest.assignments import read_assignments
from cadkg.ingest.component_list import looks_like_component_list, read_component_list
from cadkg.ingest.component_model import looks_like_component_models, read_component_models
from cadkg.ingest.connection_list import read_connection_list
from cadkg.ingest.registry import Reader, register
from cadkg.ingest.terminal_schema import looks_like_terminal_schema, read_terminal_schema
from cadkg.ingest.vrml import read_vrml
from cadkg.ingest.wri import read_wri
from cadkg.ingest.x3d import read_x3d

__all__: list[str] = []


def _looks_like_connection_list(head: bytes) -> bool:
    text = head.decode("utf-8", errors="replace").lower()
    return "componente:pin" in text or "component:pin" in text or "device:pin" in text


register(
    Reader(
        kind="wri",
        suffixes=(".wri",),
        read=read_wri,
        description="WRI ID table: CAD item ID, label, commercial code (tab separated)",
    )
)
register(
    Reader(
        kind="connection-list",
        suffixes=(".csv", ".tsv", ".txt"),
        read=read_connection_list,
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
register(
    Reader(
        kind="terminal-schema",
        suffixes=(".csv", ".xlsx", ".ods"),
        read=read_terminal_schema,
        description="Terminal block schema: terminal items in order along each block, and their levels",
        sniff=looks_like_terminal_schema,
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
import_module("cadkg.ingest.mapping_cabinet")
