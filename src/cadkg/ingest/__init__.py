"""Readers of the cell's input files, the reader registry, the manifest and the mapping to triples."""

from cadkg.ingest.eplan.connection_list import Connection, ConnectionListInfo, read_connection_list
from cadkg.ingest.eplan.labels import PinRef, normalize_label, parse_pin_ref
from cadkg.ingest.manifest import CellSpec, FrameSpec, Manifest, SourceSpec, load_manifest
from cadkg.ingest.pipeline import SourceReport, read_source
from cadkg.ingest.registry import Reader, kinds, reader_for, register, sniff_kind
from cadkg.ingest.wri import IdEntry, read_wri

__all__ = [
    "CellSpec",
    "Connection",
    "ConnectionListInfo",
    "FrameSpec",
    "IdEntry",
    "Manifest",
    "PinRef",
    "Reader",
    "SourceReport",
    "SourceSpec",
    "kinds",
    "load_manifest",
    "normalize_label",
    "parse_pin_ref",
    "read_connection_list",
    "read_source",
    "read_wri",
    "reader_for",
    "register",
    "sniff_kind",
]
