"""Registration of the ELVEZ services (profile ``elvez``): Table 2 of D3.1 and the route traversal.

Each service answers from the session's ELVEZ model, built from the graph on first use.
"""

from __future__ import annotations

from pathlib import Path

import cadkg.usecases.elvez.answers as elvez
from cadkg.services.display import Frame, MarkerSpec
from cadkg.services.service import Service, model_services
from cadkg.services.session import Session

__all__ = ["SERVICES", "element_meshes", "platform_frames"]

PROFILE = "elvez"


def model_of(session: Session) -> elvez.ElvezModel:
    """The ELVEZ model of a session, built once."""
    return session.profile_model(PROFILE, elvez.build_model)


_service = model_services(PROFILE, model_of)

SERVICES: tuple[Service, ...] = (
    _service(
        "guide_info",
        "a guide's CAD ID, dimensions, origin, key and key corner frames (robot base or 'frame'), key size",
        {"name": str, "frame": str},
        elvez.guide_info,
        optional={"frame"},
    ),
    _service(
        "cable_info",
        "a cable's colour, length, diameter, harness, connector and cavity indices",
        {"name": str},
        elvez.cable_info,
    ),
    _service(
        "con_info",
        "a connector's colour, dimensions, harness and cables",
        {"name": str},
        elvez.con_info,
    ),
    _service(
        "wh_info",
        "a wire harness's main connector and branches (connector and cables of each)",
        {"number": int},
        elvez.wh_info,
    ),
    _service("all_tools", "the names of every tool", {}, elvez.all_tools),
    _service(
        "tool_info",
        "a tool's ATC slot, base-to-wrist and wrist-to-action frames and dimensions",
        {"name": str},
        elvez.tool_info,
    ),
    _service("all_op", "every operation of the action plan: type, spots, components, tool", {}, elvez.all_op),
    _service(
        "index_op",
        "one operation of the action plan by its index (1-based)",
        {"index": int},
        elvez.index_op,
    ),
    _service(
        "wh_routes",
        "each cable of a harness: from and to connector cavity, guides it is routed through, tape spots",
        {"number": int},
        elvez.wh_routes,
    ),
)


def platform_frames(session: Session) -> list[Frame]:
    """Every platform element under its CAD id and each point of interest (``G4_key``,
    ``G4_key_corner`` ...) in its element, as the reference's Figure 25 orders them."""
    return [Frame(*transform) for transform in model_of(session).platforms.tree.transforms()]


def element_meshes(session: Session, files_dir: Path) -> list[MarkerSpec]:
    """One mesh per platform element with its model's STL, in the element's own frame."""
    elements = sorted(model_of(session).platforms.elements.values(), key=lambda e: e.label)
    return [
        MarkerSpec(
            "mesh",
            "elements",
            index,
            element.frame,
            mesh_uri="file://" + str((Path(files_dir) / str(element.mesh)).resolve()),
            text=element.label,
        )
        for index, element in enumerate(e for e in elements if e.mesh)
    ]
