"""The plan's review panel in headless Chromium, on the IEMA example built into a store and
planned, with progress reported over HTTP before the page opens: the table and the two lanes
colour each task by its report and outline the current one; with the token (given once, kept
for the tab), a task is switched to a person from its row and back to the robot from the 3D
view's pick panel, each re-plan saying the times before and after and what moved. Served
without the token, the panel is read-only and says why. An ELVEZ operation is switched from
its row as a wire is.

Expected values come from the same server (``/api/plan`` before and after) and from the
store's ``replan`` answers; the page's own text is checked against them.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import httpx
import pytest
from selenium.webdriver.common.by import By

from tests.cli import run
from tests.conftest import ELVEZ, IEMA
from tests.server.browser import health, text_of, wait
from tests.server.cell_view import open_cell, picked
from tests.server.serving import cadkg_serve

WIRE = "https://example.org/cell/iema-qe01/wire/"
TOKEN = "review-token"
AUTH = {"Authorization": f"Bearer {TOKEN}"}
VIEW = "document.getElementById('cell-view')"


def _serve(tmp_path_factory: pytest.TempPathFactory, manifest: Any, *options: str) -> Iterator[str]:
    store = tmp_path_factory.mktemp("review") / "store"
    built = run("build", manifest, "--store", store)
    assert built.returncode == 0, built.stderr
    assert run("plan", store).returncode == 0
    with cadkg_serve(str(store), "--watch", "0", *options) as base:
        yield base


@pytest.fixture(scope="module")
def writable(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    yield from _serve(tmp_path_factory, IEMA, "--allow-update", "--token", TOKEN)


@pytest.fixture(scope="module")
def read_only(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    yield from _serve(tmp_path_factory, IEMA)


@pytest.fixture(scope="module")
def elvez(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    yield from _serve(tmp_path_factory, ELVEZ, "--allow-update", "--token", TOKEN)


def _plan(base: str) -> list[dict[str, Any]]:
    steps: list[dict[str, Any]] = httpx.get(f"{base}/api/plan", timeout=60).json()["steps"]
    return steps


def _open_review(driver: Any, base: str) -> None:
    open_cell(driver, base)
    driver.find_element(By.ID, "cell-plan-toggle").click()
    wait(driver, lambda d: d.find_elements(By.CSS_SELECTOR, "#plan-table tbody tr"), 60, "the review table")


def _row(driver: Any, key: str) -> Any:
    return driver.find_element(By.CSS_SELECTOR, f'#plan-table tr[data-key="{key}"]')


def _cells(driver: Any, key: str) -> list[str]:
    return [c.text for c in _row(driver, key).find_elements(By.TAG_NAME, "td")]


def _lane_of(driver: Any, key: str) -> str:
    for lane in ("robot", "human"):
        if driver.find_elements(By.CSS_SELECTOR, f'#plan-lane-{lane} [data-key="{key}"]'):
            return lane
    return ""


def _give_token(driver: Any) -> None:
    assert "until you give the server's token" in text_of(driver, "plan-access")
    driver.find_element(By.ID, "plan-token").send_keys(TOKEN)
    driver.find_element(By.ID, "plan-unlock").click()
    wait(driver, lambda d: d.find_element(By.ID, "plan-review").get_attribute("data-writable") == "true", 10)


def _replanned(driver: Any, key: str) -> str:
    wait(
        driver,
        lambda d: key in (d.find_element(By.ID, "plan-replan").get_attribute("data-moved") or "").split(),
        120,
        f"the re-plan of {key}",
    )
    return text_of(driver, "plan-replan")


def test_progress_is_coloured_and_a_task_is_switched_from_its_row_and_from_the_3d_view(
    browser: Any, writable: str
) -> None:
    driver = browser
    before = _plan(writable)
    robot = [s for s in before if s["performer"] == "robot"]
    done, failed, switched = robot[0], robot[1], robot[3]
    for step, state in ((done, "done"), (failed, "failed")):
        reported = httpx.post(
            f"{writable}/api/progress", data={"task": step["key"], "state": state}, headers=AUTH, timeout=120
        )
        assert reported.status_code == 200, reported.text
    order = [s["key"] for s in _plan(writable)]
    steps = {s["key"]: s for s in _plan(writable)}
    summary = httpx.get(f"{writable}/api/plan", timeout=60).json()["summary"]
    _open_review(driver, writable)
    # The table and the lanes: one row per task, each task in its performer's lane.
    rows = driver.find_elements(By.CSS_SELECTOR, "#plan-table tbody tr")
    assert len(rows) == len(steps)
    assert _cells(driver, done["key"])[4] == "done" and "status-done" in _row(
        driver, done["key"]
    ).get_attribute("class")
    assert _cells(driver, failed["key"])[2:5:2] == ["human", "failed"]  # a failed robot task is a person's
    assert _lane_of(driver, failed["key"]) == "human" and _lane_of(driver, switched["key"]) == "robot"
    blocks = driver.find_elements(By.CSS_SELECTOR, ".lane-blocks .block")
    assert len(blocks) == len(steps)
    marked = dict(
        pair.split("=") for pair in driver.execute_script(f"return {VIEW}.dataset.progress").split()
    )
    assert marked == {f"{WIRE}{done['task']}": "done", f"{WIRE}{failed['task']}": "failed"}
    current = driver.find_elements(By.CSS_SELECTOR, "#plan-table tr.current")
    assert [r.get_attribute("data-key") for r in current] == [order[0]]
    # Read-only until the token is given: the switch buttons are disabled and say why.
    button = _row(driver, switched["key"]).find_element(By.TAG_NAME, "button")
    assert not button.is_enabled() and "token" in (button.get_attribute("title") or "")
    _give_token(driver)
    button = _row(driver, switched["key"]).find_element(By.TAG_NAME, "button")
    assert button.is_enabled() and button.text == "→ human"
    button.click()
    said = _replanned(driver, switched["key"])
    after = {s["key"]: s for s in _plan(writable)}
    assert after[switched["key"]]["performer"] == "human"
    assert f"{switched['task']} given to a person" in said and f"{switched['task']} (robot → human)" in said
    now = httpx.get(f"{writable}/api/plan", timeout=60).json()["summary"]
    for name, label in (("robot_time_s", "robot"), ("person_time_s", "person"), ("makespan_s", "makespan")):
        assert f"{label} {round(summary[name])} s → {round(now[name])} s" in said, said
    assert _cells(driver, switched["key"])[2] == "human" and _lane_of(driver, switched["key"]) == "human"
    # From the 3D view: the wire found and picked, its pick panel gives it back to the robot.
    driver.find_element(By.ID, "cell-component").send_keys(switched["task"])
    driver.find_element(By.ID, "cell-show").click()
    wait(driver, lambda d: picked(d) == f"{WIRE}{switched['task']}", 30, "the wire picked")
    pick = driver.find_element(By.ID, "pick-switch")
    assert pick.is_displayed() and "give to the robot" in pick.text
    pick.click()
    said = _replanned(driver, switched["key"])
    assert "given to the robot" in said and f"{switched['task']} (human → robot)" in said
    assert {s["key"]: s["performer"] for s in _plan(writable)}[switched["key"]] == "robot"
    assert health(driver, writable) == []
    driver.get("about:blank")


def test_without_the_token_the_panel_is_read_only_and_says_why(browser: Any, read_only: str) -> None:
    driver = browser
    _open_review(driver, read_only)
    assert "this server takes no changes" in text_of(driver, "plan-access")
    assert "--allow-update --token" in text_of(driver, "plan-access")
    assert not driver.find_element(By.ID, "plan-login").is_displayed()
    buttons = driver.find_elements(By.CSS_SELECTOR, "#plan-table button")
    assert buttons and not any(b.is_enabled() for b in buttons)
    assert all("takes no changes" in (b.get_attribute("title") or "") for b in buttons)
    assert driver.find_element(By.ID, "plan-review").get_attribute("data-writable") == "false"
    assert health(driver, read_only) == []
    driver.get("about:blank")


def test_an_elvez_operation_is_switched_from_its_row(browser: Any, elvez: str) -> None:
    driver = browser
    step = next(s for s in _plan(elvez) if s["task"] == "RC GR11")
    assert step["performer"] == "robot"
    _open_review(driver, elvez)
    _give_token(driver)
    _row(driver, step["key"]).find_element(By.TAG_NAME, "button").click()
    said = _replanned(driver, step["key"])
    assert "RC GR11 given to a person" in said and "RC GR11 (robot → human)" in said
    assert next(s for s in _plan(elvez) if s["key"] == step["key"])["performer"] == "human"
    assert _lane_of(driver, step["key"]) == "human"
    driver.get("about:blank")
