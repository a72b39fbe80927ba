"""The plan and the change feed in the 3D view, in headless Chromium, on the IEMA example built
into a store and planned (``cadkg plan``), served writable with a token: Plan steps through the
task list, the current task picked and the next five marked; an assignment made over HTTP
(``/api/assign``) arrives as a change set whose changed wire is listed under "What changed"
and marked, a click on it showing it. A cell without a plan says how to make one. On the
ELVEZ example, planned likewise, each operation shows what it works on.

Expected values: the tasks come from ``/api/plan`` of the same server; wire IRIs are the
example's (``cell:wire/<number>``). ELVEZ's parts are read off its files:
``Assembly_sequence.csv`` (line 2: EC WH1 at C1.1; line 4: RC GR11 through J1.1-J2.1-J3.1;
line 6: T WH1 at J1.1-J2.1) and ``WH_configuration.xml`` (harness 1: cables CA1-CA5 from WH1,
branch GR11: CA1-CA3).
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import httpx
import pytest
from selenium.webdriver.common.by import By

from tests.cli import run
from tests.conftest import EXAMPLES, IEMA
from tests.server.browser import health, settled, text_of, wait
from tests.server.cell_view import open_cell, picked
from tests.server.serving import cadkg_serve

WIRE = "https://example.org/cell/iema-qe01/wire/"
OPERATION = "https://example.org/cell/elvez/operation/Assembly_sequence/"
HARNESS_1 = [f"wire CA{n}" for n in range(1, 6)]
TOKEN = "plan-and-changes"
VIEW = "const v = document.getElementById('cell-view').cellView;"


@pytest.fixture(scope="module")
def planned(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    store = tmp_path_factory.mktemp("planned") / "iema"
    built = run("build", IEMA, "--store", store)
    assert built.returncode == 0, built.stderr
    plan = run("plan", store)
    assert plan.returncode == 0, plan.stderr
    with cadkg_serve(str(store), "--allow-update", "--token", TOKEN, "--watch", "0") as base:
        yield base


@pytest.fixture(scope="module")
def planned_elvez(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    store = tmp_path_factory.mktemp("planned") / "elvez"
    built = run("build", EXAMPLES / "elvez-cell" / "manifest.toml", "--store", store)
    assert built.returncode == 0, built.stderr
    plan = run("plan", store)
    assert plan.returncode == 0, plan.stderr
    with cadkg_serve(str(store), "--watch", "0") as base:
        yield base


def data(driver: Any, name: str) -> str:
    return str(driver.find_element(By.ID, "cell-view").get_attribute(f"data-{name}") or "")


def test_stepping_through_the_plan(browser: Any, planned: str) -> None:
    driver = browser
    steps = httpx.get(f"{planned}/api/plan", timeout=60).json()["steps"]
    wires = [s for s in steps if s["kind"] == "wire"]
    assert len(wires) == len(steps) > 6
    open_cell(driver, planned)
    driver.find_element(By.ID, "cell-plan-toggle").click()
    wait(driver, lambda d: text_of(d, "plan-step") == f"step 1 of {len(steps)}", 30, "the plan")
    for index in (0, 1, 2):
        if index:
            driver.find_element(By.ID, "plan-next").click()
        step = steps[index]
        wait(driver, lambda d, s=step: picked(d) == f"{WIRE}{s['task']}", 30, f"step {index} picked")
        assert text_of(driver, "plan-step") == f"step {index + 1} of {len(steps)}"
        assert step["task"] in text_of(driver, "plan-task") and step["performer"] in text_of(
            driver, "plan-task"
        )
        upcoming = [f"{WIRE}{s['task']}" for s in steps[index + 1 : index + 6]]
        assert data(driver, "plan-next").split() == upcoming
        settled(driver)
        assert driver.execute_script(f"{VIEW} return v.markers.group.children.length") == 5
    driver.find_element(By.ID, "plan-prev").click()
    wait(driver, lambda d: picked(d) == f"{WIRE}{steps[1]['task']}", 30, "a step back")
    driver.find_element(By.ID, "cell-plan-toggle").click()
    assert driver.execute_script(f"{VIEW} return v.markers.group.children.length") == 0
    assert health(driver, planned) == []
    driver.get("about:blank")


def test_elvez_operations_show_what_they_work_on(browser: Any, planned_elvez: str) -> None:
    driver = browser
    steps = httpx.get(f"{planned_elvez}/api/plan", timeout=60).json()["steps"]
    expected = {  # task: (the operation's source line, what is shown)
        "EC WH1": (2, {"C1", "C1 guide 1", *HARNESS_1}),
        "RC GR11": (4, {"J1", "J2", "J3", "J1 guide 1", "J2 guide 1", "J3 guide 1", *HARNESS_1[:3]}),
        "T WH1": (6, {"J1", "J2", "J1.1: taping (operation 5)", "J2.1: taping (operation 5)", *HARNESS_1}),
    }
    open_cell(driver, planned_elvez)
    driver.find_element(By.ID, "cell-plan-toggle").click()
    wait(driver, lambda d: text_of(d, "plan-step") == f"step 1 of {len(steps)}", 30, "the plan")
    shown = {}
    for index, step in enumerate(steps):
        if index:
            driver.find_element(By.ID, "plan-next").click()
        wait(
            driver,
            lambda d, s=step: picked(d).startswith(OPERATION) and data(d, "plan-step") == str(s["step"]),
            30,
            f"step {index}",
        )
        shown[step["task"]] = set(data(driver, "plan-parts").split("|")) - {""}
        assert shown[step["task"]], f"{step['task']} shows nothing"
        assert "not drawn" not in text_of(driver, "cell-status")
        if step["task"] not in expected:
            continue
        line, parts = expected[step["task"]]
        assert picked(driver) == f"{OPERATION}{line}"
        assert shown[step["task"]] == parts
        settled(driver)
        # A tube for each route, a ball for each guide key and taping spot; the jigs painted.
        assert driver.execute_script(f"{VIEW} return v.extras.children.length") == len(
            [p for p in parts if " " in p]
        )
        painted = driver.execute_script(f"{VIEW} return v.picked.objects.map((i) => v.data.objects[i].label)")
        assert set(painted) == {p for p in parts if " " not in p}
        if index + 1 < len(steps):
            assert data(driver, "plan-next").split()[0].startswith(OPERATION)
            assert driver.execute_script(f"{VIEW} return v.markers.group.children.length") > 0
    assert expected.keys() <= shown.keys()
    assert shown["EC WH2"] >= {"C2", "C2 guide 1", "wire CA6", "wire CA7"}
    assert health(driver, planned_elvez) == []
    driver.get("about:blank")


def test_what_changed_is_listed_and_marked(browser: Any, planned: str) -> None:
    driver = browser
    assert httpx.get(f"{planned}/api/info", timeout=60).json()["changes"] is True
    open_cell(driver, planned)
    wait(driver, lambda d: data(d, "following") == "true", 30, "the change feed followed")
    wire = "1500.51"
    answer = httpx.post(
        f"{planned}/api/assign",
        data={"kind": "wire", "id": wire, "performer": "human"},
        headers={"Authorization": f"Bearer {TOKEN}"},
        timeout=60,
    )
    assert answer.status_code == 200, answer.text
    wait(driver, lambda d: d.find_element(By.ID, "changes").is_displayed(), 60, "the change set")
    items = driver.find_elements(By.CSS_SELECTOR, "#changes-list li")
    texts = [str(i.text) for i in items]
    assert any(t.startswith(f"changed wire {wire}") for t in texts), texts
    assert f"{WIRE}{wire}" in data(driver, "changed").split()
    item = next(i for i in items if i.text.startswith(f"changed wire {wire}"))
    item.click()
    wait(driver, lambda d: picked(d) == f"{WIRE}{wire}", 30, "the changed wire shown")
    driver.find_element(By.ID, "changes-clear").click()
    assert not driver.find_element(By.ID, "changes").is_displayed()
    assert health(driver, planned) == []
    driver.get("about:blank")  # the feed closed before its server stops


def test_a_cell_without_a_plan_says_how_to_make_one(browser: Any, iema_site: str) -> None:
    driver = browser
    open_cell(driver, iema_site)
    driver.find_element(By.ID, "cell-plan-toggle").click()
    wait(driver, lambda d: "cadkg plan" in text_of(d, "plan-task"), 30, "the note")
    assert text_of(driver, "plan-step") == ""
    assert data(driver, "following") == ""  # a graph in memory without the token cannot change
