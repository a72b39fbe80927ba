"""The 3D view as a CAD viewer, on every example cell in headless Chromium: tags name the
components and items, and labels hidden behind solid geometry are not shown (the cabinet seen
from the back shows none of its tags); a grid under every drawn cell and a scale bar of a round
length; hover names and lights what is under the pointer; the model tree hides, isolates and
shows again. And the page's panes: the splitter, the results beside the views or at full width,
the views as tall as the window and on the whole screen.

Labels and IRIs are the examples' (see tests/server/test_browser_profiles.py).
"""

from __future__ import annotations

from typing import Any

import pytest
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By

from tests.conftest import EXAMPLES
from tests.server.browser import health, settled, wait
from tests.server.cell_view import click_on, open_cell, visible_labels
from tests.server.serving import cadkg_serve

ELVEZ = "https://example.org/cell/elvez/"
# Per cell: a thing to hover and isolate (label, what the view names it by), another thing,
# and tags that show at Fit.
CELLS = {
    "iema": (
        "iema-switchgear",
        ("Q1500.1", "https://example.org/cell/iema-qe01/component/Q1500.1"),
        "A0080.1",
        {"CN1", "CN2"},
    ),
    "elvez": (
        "elvez-cell",
        ("J4 guide 1", f"{ELVEZ}element/platform/ID0005"),
        "Agripper",
        {"T1", "Agripper"},
    ),
    "elimco": (
        "elimco-bench",
        ("A350VC-A", "https://example.org/cell/elimco-f929a/bench-pin/A350VC-A"),
        "A918VC1A",
        set(),
    ),
    "vw": ("vw-harness", ("X2", "https://example.org/cell/vw-harness/node/DOOR-L/X2"), "X1", set()),
    "enki": ("enki-hose", None, None, set()),
}
PLACE = (
    "const s = document.getElementById('results-place');"
    "s.value = arguments[0]; s.dispatchEvent(new Event('change'))"
)
VIEW = "const v = document.getElementById('cell-view').cellView;"


def data(driver: Any, name: str) -> str:
    return str(driver.find_element(By.ID, "cell-view").get_attribute(f"data-{name}") or "")


def hover(driver: Any, label: str) -> None:
    point = driver.execute_script(f"{VIEW} return v.screenPosition(arguments[0])", label)
    canvas = driver.find_element(By.CSS_SELECTOR, "#cell-view canvas")
    rect = canvas.rect
    dx = round(point["x"] - rect["x"] - rect["width"] / 2)
    dy = round(point["y"] - rect["y"] - rect["height"] / 2)
    ActionChains(driver).move_to_element_with_offset(canvas, dx, dy).perform()


@pytest.mark.parametrize("profile", list(CELLS))
def test_the_viewer_on_every_cell(browser: Any, profile: str) -> None:
    driver = browser
    example, first, second, tags = CELLS[profile]
    with cadkg_serve(str(EXAMPLES / example / "manifest.toml")) as base:
        open_cell(driver, base)
        grid = driver.execute_script(f"{VIEW} return v.ground.children.map((c) => c.name)")
        scale = driver.find_element(By.CSS_SELECTOR, "#cell-view .scale-bar")
        if first is None:  # nothing drawn: nothing to stand on, nothing to measure
            assert grid == [] and not scale.is_displayed()
            assert health(driver, base) == []
            return
        metres = float(scale.get_attribute("data-metres"))
        bar = driver.find_element(By.CSS_SELECTOR, "#cell-view .scale-bar .bar").size["width"]
        text = driver.find_element(By.CSS_SELECTOR, "#cell-view .scale-bar .text").text
        assert grid == ["plate", "grid"]
        assert 46 <= bar <= 122 and f"{metres:e}"[0] in "125", (metres, bar)
        assert text in (f"{metres:g} m", f"{metres * 1000:g} mm"), text
        assert tags <= set(visible_labels(driver, ".cell-label.tag")), visible_labels(
            driver, ".cell-label.tag"
        )

        # Hover names and lights what is under the pointer; nothing is picked by it.
        label, named = first
        driver.find_element(By.ID, "cell-fit").click()
        settled(driver)
        hover(driver, label)
        wait(
            driver,
            lambda d: data(d, "hovered") == named,
            30,
            f"{label} hovered, not {data(driver, 'hovered')!r}",
        )
        tip = driver.find_element(By.CSS_SELECTOR, "#cell-view .cell-hover")
        assert tip.is_displayed() and label in tip.text
        assert data(driver, "highlighted") == ""

        # The model tree: isolate one thing, and nothing else is picked or labelled; show all again.
        driver.find_element(By.ID, "cell-tree-toggle").click()
        tree = driver.find_element(By.ID, "cell-tree")
        assert tree.is_displayed()
        total = driver.execute_script(f"{VIEW} return v.things.list.length")
        thing = driver.execute_script(f"{VIEW} return v.things.find(arguments[0]).kind", label)
        group = tree.find_element(By.CSS_SELECTOR, f"details[data-kind='{thing}']")
        group.find_element(By.TAG_NAME, "summary").find_element(By.CSS_SELECTOR, ".name").click()
        row = group.find_element(By.CSS_SELECTOR, f".row[data-name='{label}']")
        row.find_element(By.TAG_NAME, "button").click()
        wait(driver, lambda d: data(d, "hidden") == str(total - 1), 30, "all but one hidden")
        settled(driver)
        click_on(driver, second)
        wait(
            driver, lambda d: not d.find_element(By.ID, "cell-pick").is_displayed(), 30, f"{second} is hidden"
        )
        assert set(visible_labels(driver, ".cell-label:not(.title)")) <= {label}
        click_on(driver, label)
        wait(driver, lambda d: data(d, "highlighted") == named, 30, f"{label} still picked")
        tree.find_element(By.XPATH, ".//button[text()='show all']").click()
        wait(driver, lambda d: data(d, "hidden") == "0", 30, "all shown")
        # A kind's box hides the kind.
        driver.find_element(By.ID, "cell-tree").find_element(
            By.CSS_SELECTOR, f"details[data-kind='{thing}'] summary input"
        ).click()
        count = driver.execute_script(
            f"{VIEW} return v.things.list.filter((t) => t.kind === arguments[0]).length", thing
        )
        wait(driver, lambda d: data(d, "hidden") == str(count), 30, f"the {thing}s hidden")
        driver.find_element(By.XPATH, "//aside[@id='cell-tree']//button[text()='show all']").click()
        wait(driver, lambda d: data(d, "hidden") == "0", 30, "all shown")
        driver.find_element(By.ID, "cell-tree-toggle").click()
        assert health(driver, base) == []


def tags_shown(driver: Any) -> list[str]:
    settled(driver)
    return visible_labels(driver, ".cell-label.tag")


def test_labels_behind_the_cabinet_are_hidden(browser: Any, iema_site: str) -> None:
    # Face on, the cabinet's tags show; from behind its mounting plate none does but the
    # plate's own (its far face is a plate's thickness away), though each is still in the view.
    driver = browser
    open_cell(driver, iema_site)
    driver.find_element(By.ID, "view-front").click()
    front = tags_shown(driver)
    assert len(front) >= 10, front
    driver.execute_script(
        f"{VIEW} const t = v.controls.target; v.camera.position.sub(t).negate().add(t);"
        "v.controls.update(); v.requestRender();"
    )
    wait(driver, lambda d: int(data(d, "behind") or 0) >= len(front) - 1, 30, "the tags behind the plate")
    assert set(tags_shown(driver)) <= {"PLATE"}  # the plate's own tag, on its far face
    driver.find_element(By.ID, "view-front").click()
    assert len(tags_shown(driver)) == len(front)
    driver.find_element(By.ID, "layer-tags").click()
    assert tags_shown(driver) == []
    driver.find_element(By.ID, "layer-tags").click()
    assert health(driver, iema_site) == []


def box(driver: Any, element_id: str) -> dict[str, float]:
    rect: dict[str, float] = driver.execute_script(
        "return document.getElementById(arguments[0]).getBoundingClientRect().toJSON()", element_id
    )
    return rect


def test_the_panes(browser: Any, iema_site: str) -> None:
    driver = browser
    open_cell(driver, iema_site)
    driver.execute_script("localStorage.removeItem('cadkg.layout')")
    height = driver.execute_script("return window.innerHeight")
    width = driver.execute_script("return document.documentElement.clientWidth")
    view = box(driver, "view-pane")
    # The views reach down to the window's bottom; the results sit beside them, under the editor.
    assert view["bottom"] <= height + 1 and view["bottom"] >= height - 40, (view, height)
    results = box(driver, "results-pane")
    assert results["right"] < view["left"] and results["top"] >= box(driver, "editor-pane")["bottom"]

    # The splitter moves the boundary; the 3D view follows.
    canvas = driver.find_element(By.CSS_SELECTOR, "#cell-view canvas").size["width"]
    splitter = driver.find_element(By.ID, "splitter")
    ActionChains(driver).click_and_hold(splitter).move_by_offset(-200, 0).release().perform()
    settled(driver)
    assert box(driver, "editor-pane")["width"] == pytest.approx(box(driver, "results-pane")["width"], abs=2)
    wider = driver.find_element(By.CSS_SELECTOR, "#cell-view canvas").size["width"]
    assert wider >= canvas + 150, (canvas, wider)

    # The results at full width, under the editor and the views; and back.
    driver.execute_script(PLACE, "under")
    results = box(driver, "results-pane")
    assert results["width"] >= width - 60 and results["top"] >= box(driver, "view-pane")["bottom"] - 1
    driver.refresh()  # the choice is kept
    wait(driver, lambda d: d.execute_script("return document.body.dataset.ready") == "true", 60, "page")
    assert driver.execute_script("return document.body.dataset.results") == "under"
    driver.execute_script(PLACE, "beside")
    assert box(driver, "results-pane")["right"] < box(driver, "view-pane")["left"]

    # Full screen: the views take the whole window, and give it back.
    open_cell(driver, iema_site)
    driver.find_element(By.ID, "cell-fullscreen").click()
    wait(
        driver, lambda d: d.find_element(By.ID, "view-pane").get_attribute("data-full") == "true", 30, "full"
    )
    settled(driver)
    full = box(driver, "view-pane")
    screen = driver.execute_script("return [window.innerWidth, window.innerHeight]")
    assert full["width"] >= screen[0] - 2 and full["height"] >= screen[1] - 2, (full, screen)
    assert driver.find_element(By.CSS_SELECTOR, "#cell-view canvas").size["height"] >= screen[1] * 0.5
    driver.find_element(By.ID, "cell-fullscreen").click()
    wait(
        driver, lambda d: d.find_element(By.ID, "view-pane").get_attribute("data-full") == "false", 30, "back"
    )
    driver.execute_script("localStorage.removeItem('cadkg.layout')")
    assert health(driver, iema_site) == []
