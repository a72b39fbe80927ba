"""ELIMCO: routing aeronautic harnesses on a pin workbench (D3.1 section 4.2).

An Excel cable list and the three XML files of a route-design application (pins on the 2D
drawing, cables, routes over the pins) are read into one graph; the services swap the files
online (``load_files``), give pin positions in the drawing frame or around the pins'
centroid, the pins as tf frames, the cables and each cable's path.
"""

from __future__ import annotations

from cadkg.ingest.reader import Reader, lazy
from cadkg.usecase import UseCase

__all__ = ["USE_CASE"]

USE_CASE = UseCase(
    name="elimco",
    package=__name__,
    title="aeronautic harness routing on a pin workbench (D3.1 section 4.2)",
    section="4.2",
    readers=(
        Reader(
            "elimco-cable-list",
            (".csv", ".tsv", ".xlsx", ".ods"),
            "cadkg.usecases.elimco.cable_list:read_elimco_cable_list",
            "ELIMCO cable list (Figure 11): PN, REP, ZONA_A, BORNIA_A, HILO, CABLE, LONGITUD, ZONA_B ...",
            "cadkg.usecases.elimco.cable_list:looks_like_cable_list",
        ),
        Reader(
            "pin-info",
            (".xml",),
            "cadkg.usecases.elimco.route_design:read_pin_info",
            "Route design pin_info.xml (<pin_info>): bench pins, drawing position, role, double pins",
            "cadkg.usecases.elimco.route_design:looks_like_pin_info",
        ),
        Reader(
            "cable-info",
            (".xml",),
            "cadkg.usecases.elimco.route_design:read_cable_info",
            "Route design cable_info.xml (<cable_info>): cables, initial and final connector, length",
            "cadkg.usecases.elimco.route_design:looks_like_cable_info",
        ),
        Reader(
            "path-info",
            (".xml",),
            "cadkg.usecases.elimco.route_design:read_path_info",
            "Route design path_info.xml (<path_info>): route of each cable over the bench pins",
            "cadkg.usecases.elimco.route_design:looks_like_path_info",
        ),
    ),
    services="cadkg.usecases.elimco.services:SERVICES",
    ros_namespace="/elimco",
    frames=lazy("cadkg.usecases.elimco.services:bench_frames"),
    scene=lazy("cadkg.usecases.elimco.scene:bench_scene"),
    mapping="cadkg.usecases.elimco.mapping",
)
