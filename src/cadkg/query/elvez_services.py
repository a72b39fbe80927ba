"""Registration of the ELVEZ services (profile ``elvez``): Table 2 of D3.1 and the route traversal.

Each service answers from the session's ELVEZ model, built from the graph on first use.
"""

from __future__ import annotations

from cadkg.query import elvez
from cadkg.query.cursors import Session
from cadkg.query.services import Service, on_model, register

__all__: list[str] = []

PROFILE = "elvez"


def model_of(session: Session) -> elvez.ElvezModel:
    """The ELVEZ model of a session, built once."""
    return session.profile_model(PROFILE, elvez.build_model)


register(
    Service(
        "guide_info",
        "a guide's CAD ID, dimensions, origin, key and key corner frames (robot base or 'frame'), key size",
        {"name": str, "frame": str},
        on_model(elvez.guide_info, model_of),
        profile=PROFILE,
        optional=frozenset({"frame"}),
    ),
    Service(
        "cable_info",
        "a cable's colour, length, diameter, harness, connector and cavity indices",
        {"name": str},
        on_model(elvez.cable_info, model_of),
        profile=PROFILE,
    ),
    Service(
        "con_info",
        "a connector's colour, dimensions, harness and cables",
        {"name": str},
        on_model(elvez.con_info, model_of),
        profile=PROFILE,
    ),
    Service(
        "wh_info",
        "a wire harness's main connector and branches (connector and cables of each)",
        {"number": int},
        on_model(elvez.wh_info, model_of),
        profile=PROFILE,
    ),
    Service(
        "all_tools",
        "the names of every tool",
        {},
        on_model(elvez.all_tools, model_of),
        profile=PROFILE,
    ),
    Service(
        "tool_info",
        "a tool's ATC slot, base-to-wrist and wrist-to-action frames and dimensions",
        {"name": str},
        on_model(elvez.tool_info, model_of),
        profile=PROFILE,
    ),
    Service(
        "all_op",
        "every operation of the action plan: type, spots, components, tool",
        {},
        on_model(elvez.all_op, model_of),
        profile=PROFILE,
    ),
    Service(
        "index_op",
        "one operation of the action plan by its index (1-based)",
        {"index": int},
        on_model(elvez.index_op, model_of),
        profile=PROFILE,
    ),
    Service(
        "wh_routes",
        "each cable of a harness: from and to connector cavity, guides it is routed through, tape spots",
        {"number": int},
        on_model(elvez.wh_routes, model_of),
        profile=PROFILE,
    ),
)
