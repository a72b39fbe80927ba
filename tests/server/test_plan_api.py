"""``GET /api/plan``: the stored plan as JSON, read-only; 404 before a plan is made."""

from __future__ import annotations

import httpx

from cadkg.graph import KnowledgeGraph
from cadkg.plan.cell import store_plan
from tests.server.serving import serving
from tests.usecases.iema.test_plan import CABINET


def test_the_plan_is_served_as_json_once_made() -> None:
    kg = KnowledgeGraph.build(CABINET)
    with serving(kg) as base:
        missing = httpx.get(f"{base}/api/plan")
        assert missing.status_code == 404 and "cadkg plan" in missing.json()["error"]
    store_plan(kg)
    with serving(kg) as base:
        answer = httpx.get(f"{base}/api/plan")
        assert answer.status_code == 200, answer.text
        data = answer.json()
        assert [s["task"] for s in data["steps"][:2]] == ["W2", "W1"]
        assert data["precedence"][0]["before"] == "W2" and data["summary"]["tasks"] == 12
        # The times the plan's graph keeps: the makespan is when the last step ends.
        summary = data["summary"]
        assert summary["makespan_s"] == max(s["end_s"] for s in data["steps"]) > 0
        assert summary["robot_time_s"] > 0 and summary["person_time_s"] == 6 * 240  # six people's wires
        assert httpx.post(f"{base}/api/plan").status_code == 405
        assert "/api/plan" in httpx.get(f"{base}/api").json()["endpoints"].values()
