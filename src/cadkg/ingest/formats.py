"""The formats no single use case owns: WRI tables, EPLAN connection lists, X3D and VRML
scenes, KBL and VEC harnesses, robot/human assignments. Use cases add their own (see cadkg.usecase).

Functions are named ``"module:attribute"`` and imported on first use (see cadkg.ingest.reader):
listing the kinds imports none of the parsers, and reading a WRI table does not import trimesh."""

from __future__ import annotations

from cadkg.ingest.reader import Reader

__all__ = ["READERS"]

READERS: tuple[Reader, ...] = (
    Reader(
        kind="wri",
        suffixes=(".wri", ".txt"),
        read="cadkg.ingest.wri:read_wri",
        stream="cadkg.ingest.wri:iter_wri",
        description="WRI ID table: CAD item ID, label, commercial code (tab separated)",
        sniff="cadkg.ingest.wri:looks_like_wri",
    ),
    Reader(
        kind="connection-list",
        suffixes=(".csv", ".tsv", ".txt", ".xlsx", ".xlsm", ".xls", ".ods", ".xml"),
        read="cadkg.ingest.eplan.connection_files:read_connections",
        stream="cadkg.ingest.eplan.connection_files:iter_connections",
        description="EPLAN connection list: text (Figure 3, Lista cablaggio, Komax), workbook, labelling XML",
        sniff="cadkg.ingest.eplan.connection_files:looks_like_connections",
    ),
    Reader(
        kind="bill-of-materials",
        suffixes=(".xlsx", ".xlsm", ".xls", ".ods", ".xml"),
        read="cadkg.ingest.eplan.bill_of_materials:read_bill_of_materials",
        description="EPLAN bill of materials (Distinta componenti): workbook or labelling XML",
        sniff="cadkg.ingest.eplan.bill_of_materials:looks_like_bill_of_materials",
    ),
    Reader(
        kind="parts-management",
        suffixes=(".xml",),
        read="cadkg.ingest.eplan.parts:read_parts_management",
        description="EPLAN parts-management XML (<partsmanagement>): connection points of each part number",
        sniff="cadkg.ingest.eplan.parts:looks_like_parts_management",
    ),
    Reader(
        kind="x3d",
        suffixes=(".x3d",),
        read="cadkg.ingest.scene.read:read_x3d",
        description="X3D scene (XML encoding): DEF-named Transforms and Groups, poses, boxes, meshes",
    ),
    Reader(
        kind="vrml",
        suffixes=(".wrl",),
        read="cadkg.ingest.scene.read:read_vrml",
        description="VRML97 scene (#VRML V2.0 utf8): DEF-named Transforms and Groups, poses, boxes, meshes",
        sniff="cadkg.ingest.scene.vrml:looks_like_vrml97",
    ),
    Reader(
        kind="assignments",
        suffixes=(".csv",),
        read="cadkg.ingest.assignments:read_assignments",
        description="robot/human assignment overlay: kind,id,performer (wire, component or operation)",
        sniff="cadkg.ingest.assignments:looks_like_assignments",
    ),
    Reader(
        kind="kbl",
        suffixes=(".kbl",),
        read="cadkg.ingest.harness.kbl:read_kbl",
        description="KBL harness (VDA 4964) 2.3 SR-1, 2.4, 2.4 SR-1: connectors, topology, wires, modules",
        sniff="cadkg.ingest.harness.kbl:looks_like_kbl",
    ),
    Reader(
        kind="vec",
        suffixes=(".vec", ".xml"),
        read="cadkg.ingest.harness.vec:read_vec",
        description="VEC harness description (VDA 4968) 1.1 to 2.1: connectors, topology, wires, variants",
        sniff="cadkg.ingest.harness.vec:looks_like_vec",
    ),
)
