"""Registration of the readers cadkg ships."""

from __future__ import annotations

from cadkg.ingest.connection_list import read_connection_list
from cadkg.ingest.registry import Reader, register
from cadkg.ingest.wri import read_wri

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
