"""``GET /api/plan``: the robot's task list stored in the served graph (``cadkg plan``), as
``cadkg plan --format json`` prints it; 404 when the store holds none."""

from __future__ import annotations

import json
from collections.abc import Callable

from starlette.requests import Request
from starlette.responses import Response

from cadkg.errors import CadkgError
from cadkg.plan.graph import cell_base, read_plan
from cadkg.plan.report import as_json
from cadkg.server.context import Answer, Endpoint, ProtocolError, json_response, status_of
from cadkg.server.holder import Served
from cadkg.server.limits import Deadline

__all__ = ["plan"]


async def plan(request: Request) -> Response:
    """``GET /api/plan``: steps, precedence and summary of the stored plan."""
    endpoint: Endpoint = request.app.state.endpoint
    deadline = Deadline(endpoint.limits.timeout)
    try:
        if request.method != "GET":
            # Taken here, so that no service named like it answers a POST in its stead.
            raise ProtocolError(405, "the plan is read with GET; cadkg plan STORE makes it", {"Allow": "GET"})

        def make_job(served: Served) -> Callable[[Deadline], Answer]:
            def job(_: Deadline) -> Answer:
                stored = read_plan(served.graph, cell_base(served.graph))
                if stored is None:
                    raise ProtocolError(404, "the store holds no plan: make one with cadkg plan STORE")
                return Answer(json.dumps(as_json(stored), ensure_ascii=False).encode(), "application/json")

            return job

        answer, generation = await endpoint.run(make_job, ("plan",), deadline, local=True)
        return endpoint.respond(answer, generation)
    except CadkgError as err:
        status, headers = status_of(err)
        return json_response({"error": str(err)}, status, headers)
