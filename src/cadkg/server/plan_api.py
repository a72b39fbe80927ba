"""``GET /api/plan``: the ``plan`` service (the robot's task list stored in the served graph,
``cadkg plan`` makes it), answered as ``cadkg plan --format json`` prints it; 404 when the
store holds none."""

from __future__ import annotations

from typing import Any

from starlette.requests import Request
from starlette.responses import Response

from cadkg.server.api import _error, call_service
from cadkg.server.context import ProtocolError

__all__ = ["plan"]


def _document(data: dict[str, Any]) -> dict[str, Any]:
    return {key: data[key] for key in ("summary", "steps", "precedence")}


async def plan(request: Request) -> Response:
    """``GET /api/plan``: steps, precedence and summary of the stored plan."""
    if request.method != "GET":
        # Taken here, so that no service named like it answers a POST in its stead.
        refusal = ProtocolError(405, "the plan is read with GET; cadkg plan STORE makes it", {"Allow": "GET"})
        return _error(refusal)
    return await call_service(request, "plan", _document)
