"""Volkswagen: the harness state a detection system starts from (D3.1 section 4.4).

A harness description (KBL, VEC, or a small text form) is read into the graph's harness
terms and exported as GraphML in two views: the topology (connectors, branch points and
fixings as nodes, with their positions; segments with their wires as edges) and the wires
(cavities as nodes, wires as edges), of the whole harness or of one variant of a modular
harness, by ``cadkg export --view`` and the ``harness_topology`` service.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

from cadkg.ingest.reader import Reader, lazy
from cadkg.usecase import ExportOptions, ExportView, UseCase

__all__ = ["USE_CASE"]


def _view(name: str) -> ExportView:
    # The GraphML writer's views import networkx: when a view is exported, not with the registry.
    write_harness_graphml = lazy("cadkg.usecases.vw.graphml:write_harness_graphml")

    def write(kg: Any, output: str, harness: str | None, options: ExportOptions) -> Sequence[str]:
        written = write_harness_graphml(kg, output, name, harness, options.modules, yed=options.yed)
        warnings: Sequence[str] = written.warnings
        return warnings

    return write


USE_CASE = UseCase(
    name="vw",
    package=__name__,
    title="harness state for a detection system (D3.1 section 4.4)",
    section="4.4",
    readers=(
        Reader(
            "harness-text",
            (".harness",),
            "cadkg.usecases.vw.harness_text:read_harness_text",
            "Harness text description: connectors, nodes, segments, wires with cavities",
            "cadkg.usecases.vw.harness_text:looks_like_harness_text",
        ),
    ),
    services="cadkg.usecases.vw.services:SERVICES",
    ros_namespace="/vw_harness",
    views={"topology": _view("topology"), "wires": _view("wires")},
)
