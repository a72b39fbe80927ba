"""ENKI: handling hoses (D3.1 section 4.5).

The cell needs the diameter of the hose in hand, and later more product parameters:
``hose_info(product)`` answers diameter, length, material and bend radius from a hose
product table.
"""

from __future__ import annotations

from cadkg.ingest.reader import Reader
from cadkg.usecase import UseCase

__all__ = ["USE_CASE"]

USE_CASE = UseCase(
    name="enki",
    package=__name__,
    title="hose handling (D3.1 section 4.5)",
    section="4.5",
    readers=(
        Reader(
            "hose",
            (".csv",),
            "cadkg.usecases.enki.hose:read_hoses",
            "Hose products: product, diameter_mm, optional length_m, material, bend_radius_mm",
            "cadkg.usecases.enki.hose:looks_like_hose_table",
        ),
    ),
    services="cadkg.usecases.enki.services:SERVICES",
    ros_namespace="/enki",
    mapping="cadkg.usecases.enki.mapping",
)
