"""The 3D scene asks the cell's use case for its own points and routes (its ``scene`` hook)."""

from __future__ import annotations

from typing import Any

import pytest

import cadkg.registry as registry
from cadkg.errors import QueryError
from cadkg.server.workbench.scene_extras import profile_extras
from cadkg.services.session import Session
from cadkg.store import GraphStore
from cadkg.usecase import UseCase


def _marks(graph: Any, session: Session, frames: set[str], out: dict[str, list[Any]]) -> None:
    for frame in sorted(frames):
        out["points"].append({"kind": "mark", "frame": frame, "label": frame, "iri": None})
    out["routes"].append({"label": "via", "iri": None, "via": sorted(frames)})


def _broken(graph: Any, session: Session, frames: set[str], out: dict[str, list[Any]]) -> None:
    raise QueryError("the marks cannot be read")


@pytest.fixture
def plugged(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(registry, "_TABLE", None)
    registry.add_use_case(UseCase(name="toy-marks", title="marks at every frame", scene=_marks))
    registry.add_use_case(UseCase(name="toy-broken", title="marks it cannot read", scene=_broken))


@pytest.mark.usefixtures("plugged")
def test_the_scene_hook_of_the_cells_profile_adds_its_points_and_routes() -> None:
    graph, problems = GraphStore.memory(), []
    extras = profile_extras(graph, Session(None, kg=graph), "toy-marks", {"a", "b"}, problems)
    assert [p["frame"] for p in extras["points"]] == ["a", "b"]
    assert extras["routes"] == [{"label": "via", "iri": None, "via": ["a", "b"]}]
    assert problems == [] and extras["harnesses"] == []
    # Another profile's hook is not called, nor is one of a profile that is not installed.
    for profile in ("iema", "no-such-profile", ""):
        assert profile_extras(graph, Session(None, kg=graph), profile, {"a"}, problems)["points"] == []
    assert problems == []


@pytest.mark.usefixtures("plugged")
def test_a_scene_hook_that_fails_leaves_its_part_out_and_says_why() -> None:
    graph, problems = GraphStore.memory(), []
    extras = profile_extras(graph, Session(None, kg=graph), "toy-broken", {"a"}, problems)
    assert extras == {"points": [], "routes": [], "harnesses": []}
    assert problems == ["toy-broken details left out: the marks cannot be read"]
