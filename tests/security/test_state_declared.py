"""No change without the token, from one declaration: every registered service (the shipped use
cases' and a plug-in's added here) says what a call changes (``Service.effect``), and the
endpoint derives its checks from that alone.

Over HTTP each changing service refuses GET, HEAD, a POST without the token and one with a wrong
token, and the served session's cursors are the same afterwards; each reading one answers GET.
A reading service, run with real parameters on every example, leaves the session's cursors
and the graph as they were; one that is declared as reading and asks for a cursor anyway is
stopped. The ROS node's side of the same declaration is in ``tests/ros/live/test_guard_live.py``.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Any

import httpx
import pytest

import cadkg
import cadkg.registry as registry
from cadkg.errors import QueryError
from cadkg.plan.cell import store_plan
from cadkg.server import Settings, create_app
from cadkg.services.service import Effect, Service
from cadkg.services.session import Session
from cadkg.services.table import SERVICES, call
from cadkg.usecase import UseCase
from tests.conftest import EXAMPLES
from tests.ros.test_ros_typed import CALLS
from tests.server.serving import serving_app

TOKEN = "t0ken"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
WRONG = {"Authorization": "Bearer t0ken2"}
# One call of each IEMA service that answers on the example cabinet (the other profiles' are CALLS).
IEMA_CALLS: dict[str, dict[str, str]] = {
    "cad_service": {"label": "F1500.1"},
    "full_cad_service": {"label": "F1500.1"},
    "get_item_screw_service": {"label": "F1500.1", "detected_pose": "0.1,0.6,0.0075,0,0,0"},
    "get_terminal_data": {"label": "X1600"},
    "cluster_service": {"label": "F1500.1"},
    "cad_reference": {"label": "F1500.1"},
    "full_connection_provider": {"occupancy": "false"},
    "group_connection_provider": {},
    "reset_connection_list": {},
    "reset_to_connection_list": {"data": "2"},
    "rail_scanner": {},
    "reset_rail_scanner": {},
    # The operations every cell offers (the test makes the example's plan first).
    "assign": {"kind": "wire", "id": "1500.51", "performer": "human"},
    "progress": {"task": "1500.51", "state": "done"},
    "replan": {"task": "1500.53", "performer": "human"},
    "plan": {},
    "label_frames": {"label": "F1500.1"},
    "reload": {},
}


@dataclass
class ToyCursor:
    position: int = 0


def _toy_next(session: Session, client: str = "default") -> dict[str, Any]:
    cursor = session.cursor("toy", client, ToyCursor)
    cursor.position += 1
    return {"success": True, "message": "moved", "position": cursor.position}


def _toy_peek(session: Session, client: str = "default") -> dict[str, Any]:
    # Declared as reading below, yet it moves the cursor: the session must stop it.
    return _toy_next(session, client)


TOY = UseCase(
    name="toy-state",
    title="a plug-in whose services move a cursor and read",
    services=(
        Service(
            "toy_next", "the next widget; the client's cursor moves on", {}, _toy_next, effect=Effect.CURSOR
        ),
        Service("toy_peek", "declared as reading, but asks for a cursor", {}, _toy_peek, effect=Effect.READS),
    ),
)


@pytest.fixture
def plugged(monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """The registry with the shipped use cases and TOY; the shared one again afterwards."""
    monkeypatch.setattr(registry, "_TABLE", None)
    registry.add_use_case(TOY)
    yield


def test_every_service_declares_an_effect_and_the_declaration_is_required() -> None:
    assert {s.effect for s in SERVICES.values()} <= set(Effect)
    declared = {name: s.effect for name, s in SERVICES.items() if s.effect.changes}
    # The reference node's index_operation and all_operations move the caller's cursor too.
    assert declared["CAD_platform.index_operation"] is Effect.CURSOR
    assert declared["CAD_platform.all_operations"] is Effect.CURSOR
    assert declared["load_files"] is Effect.LOADS
    with pytest.raises(TypeError, match="effect"):
        Service("forgot", "a service without a declared effect", {}, _toy_next)  # type: ignore[call-arg]


def _cursors(app: Any) -> str:
    return json.dumps(app.app.state.endpoint.holder.current.session().dump(), sort_keys=True)


def test_every_changing_service_refuses_a_call_without_post_and_the_token(
    plugged: None, iema: cadkg.KnowledgeGraph
) -> None:
    settings = Settings(allow_update=True, token=TOKEN, watch_seconds=0)
    app = create_app(iema, settings)
    changing = sorted(name for name, s in SERVICES.items() if s.effect.changes)
    reading = sorted(name for name, s in SERVICES.items() if not s.effect.changes)
    assert "toy_next" in changing and "toy_peek" in reading
    with serving_app(app) as base:
        moved = httpx.post(f"{base}/api/toy_next", data={"client": "robot"}, headers=AUTH)
        assert moved.json()["position"] == 1
        before = _cursors(app)
        for name in changing:
            url = f"{base}/api/{name}"
            params = {"client": "robot", **IEMA_CALLS.get(name, {})}
            for method in ("GET", "HEAD", "PUT", "DELETE"):
                refused = httpx.request(method, url, params=params, headers=AUTH)
                assert refused.status_code == 405, (name, method, refused.text)
            for headers in ({}, WRONG, {"Authorization": TOKEN}, {"Authorization": "Basic dDBrZW4="}):
                refused = httpx.post(url, data=params, headers=headers)
                assert refused.status_code == 401, (name, headers, refused.text)
            assert _cursors(app) == before, name
        for name in reading:
            answered = httpx.get(f"{base}/api/{name}", params={"client": "robot", **IEMA_CALLS.get(name, {})})
            assert answered.status_code not in (401, 403, 405), (name, answered.text)
        # The one declared as reading that asks for a cursor is refused inside, by the session.
        peek = httpx.get(f"{base}/api/toy_peek", params={"client": "robot"})
        assert peek.status_code == 400 and "declared as only reading" in peek.json()["error"]
        assert _cursors(app) == before
        assert (
            httpx.post(f"{base}/api/toy_next", data={"client": "robot"}, headers=AUTH).json()["position"] == 2
        )


def test_the_reference_nodes_cursor_moves_only_by_post_with_the_token() -> None:
    """The failure this guards against: a GET of index_operation (no token) moved the robot's
    ELVEZ cursor from operation 1 to 8, and all_operations rewound it."""
    app = create_app(
        cadkg.build(EXAMPLES / "elvez-cell" / "manifest.toml"), Settings(token=TOKEN, watch_seconds=0)
    )
    with serving_app(app) as base:
        api = f"{base}/api/CAD_platform."
        first = httpx.post(f"{api}next_operation", data={"client": "robot"}, headers=AUTH).json()
        assert first["success"] is True
        before = _cursors(app)
        for name, params in (("index_operation", {"index": "7"}), ("all_operations", {})):
            assert httpx.get(f"{api}{name}", params={**params, "client": "robot"}).status_code == 405
            assert httpx.post(f"{api}{name}", data={**params, "client": "robot"}).status_code == 401
        assert _cursors(app) == before
        second = httpx.post(f"{api}next_operation", data={"client": "robot"}, headers=AUTH).json()
        other = httpx.post(f"{api}next_operation", data={"client": "other"}, headers=AUTH).json()
        fresh = httpx.post(f"{api}next_operation", data={"client": "other"}, headers=AUTH).json()
        assert other == first and second == fresh  # the robot's cursor went on from where it was


def _state(session: Session, kg: cadkg.KnowledgeGraph) -> tuple[str, int, list[str]]:
    return json.dumps(session.dump(), sort_keys=True), len(kg), sorted(kg.named_graphs())


@pytest.mark.parametrize("example", sorted({e for e, _ in CALLS.values()} | {"iema-switchgear"}))
def test_no_reading_service_changes_the_session_or_the_graph(example: str) -> None:
    kg = cadkg.build(EXAMPLES / example / "manifest.toml")
    session = Session(kg.cell_model(), kg=kg)
    if example == "iema-switchgear":
        store_plan(kg)  # what the plan service reads
    calls = {
        name: ([IEMA_CALLS[name]] if example == "iema-switchgear" else CALLS[name][1])
        for name in SERVICES
        if (CALLS.get(name, ("",))[0] == example) or (example == "iema-switchgear" and name in IEMA_CALLS)
    }
    changing = [name for name in calls if SERVICES[name].effect.changes]
    reading = [name for name in calls if not SERVICES[name].effect.changes]
    assert reading, example
    # Every cursor of the profile is somewhere other than its start, for two clients.
    for client in ("default", "robot"):
        for name in changing:
            if SERVICES[name].effect is Effect.CURSOR:
                call(session, name, calls[name][0], client=client)
    before = _state(session, kg)
    assert json.loads(before[0]) or not any(SERVICES[n].effect is Effect.CURSOR for n in changing)
    for name in reading:
        for params in calls[name]:
            for client in ("default", "robot", "someone-new"):
                call(session, name, params, client=client)
                assert _state(session, kg) == before, (name, params, client)


def test_a_service_declared_as_reading_cannot_take_a_cursor() -> None:
    session = Session(None)
    with session.reading("peek"), pytest.raises(QueryError, match="peek is declared as only reading"):
        session.cursor("toy", "robot", ToyCursor)
    assert session.dump() == {}
    assert session.cursor("toy", "robot", ToyCursor).position == 0  # outside, as before
