"""The formats no single use case owns: WRI tables, EPLAN connection lists, X3D and VRML
scenes, KBL and VEC harnesses, robot/human assignments. Use cases add their own (see cadkg.usecase)."""

from __future__ import annotations

from cadkg.ingest.assignments import looks_like_assignments, read_assignments
from cadkg.ingest.eplan.bill_of_materials import looks_like_bill_of_materials, read_bill_of_materials
from cadkg.ingest.eplan.connection_files import iter_connections, looks_like_connections, read_connections
from cadkg.ingest.eplan.parts import looks_like_parts_management, read_parts_management
from cadkg.ingest.harness.kbl import looks_like_kbl, read_kbl
from cadkg.ingest.harness.vec import looks_like_vec, read_vec
from cadkg.ingest.reader import Reader
from cadkg.ingest.scene.read import read_vrml, read_x3d
from cadkg.ingest.scene.vrml import looks_like_vrml97
from cadkg.ingest.wri import iter_wri, looks_like_wri, read_wri

__all__ = ["READERS"]

READERS: tuple[Reader, ...] = (
    Reader(
        kind="wri",
        suffixes=(".wri", ".txt"),
        read=read_wri,
        stream=iter_wri,
        description="WRI ID table: CAD item ID, label, commercial code (tab separated)",
        sniff=looks_like_wri,
    ),
    Reader(
        kind="connection-list",
        suffixes=(".csv", ".tsv", ".txt", ".xlsx", ".xlsm", ".xls", ".ods", ".xml"),
        read=read_connections,
        stream=iter_connections,
        description="EPLAN connection list: text (Figure 3, Lista cablaggio, Komax), workbook, labelling XML",
        sniff=looks_like_connections,
    ),
    Reader(
        kind="bill-of-materials",
        suffixes=(".xlsx", ".xlsm", ".xls", ".ods", ".xml"),
        read=read_bill_of_materials,
        description="EPLAN bill of materials (Distinta componenti): workbook or labelling XML",
        sniff=looks_like_bill_of_materials,
    ),
    Reader(
        kind="parts-management",
        suffixes=(".xml",),
        read=read_parts_management,
        description="EPLAN parts-management XML (<partsmanagement>): connection points of each part number",
        sniff=looks_like_parts_management,
    ),
    Reader(
        kind="x3d",
        suffixes=(".x3d",),
        read=read_x3d,
        description="X3D scene (XML encoding): DEF-named Transforms and Groups, poses, boxes, meshes",
    ),
    Reader(
        kind="vrml",
        suffixes=(".wrl",),
        read=read_vrml,
        description="VRML97 scene (#VRML V2.0 utf8): DEF-named Transforms and Groups, poses, boxes, meshes",
        sniff=looks_like_vrml97,
    ),
    Reader(
        kind="assignments",
        suffixes=(".csv",),
        read=read_assignments,
        description="robot/human assignment overlay: kind,id,performer (wire, component or operation)",
        sniff=looks_like_assignments,
    ),
    Reader(
        kind="kbl",
        suffixes=(".kbl",),
        read=read_kbl,
        description="KBL harness (VDA 4964) 2.3 SR-1, 2.4, 2.4 SR-1: connectors, topology, wires, modules",
        sniff=looks_like_kbl,
    ),
    Reader(
        kind="vec",
        suffixes=(".vec", ".xml"),
        read=read_vec,
        description="VEC harness description (VDA 4968) 1.1 to 2.1: connectors, topology, wires, variants",
        sniff=looks_like_vec,
    ),
)
