"""The page's 3D view, driven as a user would: open it, click where a label is drawn, read
what was picked and which labels show."""

from __future__ import annotations

from typing import Any

from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By

from tests.server.browser import open_page, settled, wait


def open_cell(driver: Any, base: str) -> None:
    open_page(driver, f"{base}/")
    driver.find_element(By.ID, "view-3d").click()
    script = "return document.getElementById('cell-view').dataset.ready"
    wait(driver, lambda d: d.execute_script(script) == "true", 120, "the 3D view")
    settled(driver)


def picture(driver: Any) -> bytes:
    png: bytes = driver.find_element(By.ID, "cell-view").screenshot_as_png
    return png


def click_on(driver: Any, label: str) -> None:
    """Click the 3D view where ``label`` (a component, a harness node) is drawn."""
    point = driver.execute_script(
        "return document.getElementById('cell-view').cellView.screenPosition(arguments[0])", label
    )
    assert point is not None, f"{label} is not in the 3D view"
    canvas = driver.find_element(By.CSS_SELECTOR, "#cell-view canvas")
    rect = canvas.rect
    dx = round(point["x"] - rect["x"] - rect["width"] / 2)
    dy = round(point["y"] - rect["y"] - rect["height"] / 2)
    ActionChains(driver).move_to_element_with_offset(canvas, dx, dy).click().perform()


def picked(driver: Any) -> str:
    iri: str = driver.find_element(By.ID, "cell-pick").get_attribute("data-iri") or ""
    return iri


def visible_labels(driver: Any, selector: str = ".cell-label") -> list[str]:
    labels = driver.find_elements(By.CSS_SELECTOR, f"#cell-view {selector}")
    return [str(e.get_attribute("textContent")) for e in labels if e.is_displayed()]
