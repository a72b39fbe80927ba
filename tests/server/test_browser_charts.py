"""Charts of several series in headless Chromium, on the IEMA example: an answer with two
measures is drawn as grouped bars, one pair per colour, with a legend naming both; an answer
with a grouping column (wires per cross-section, by colour) as a bar per colour at each
cross-section, the legend naming the colours; "(one)" goes back to a single series.

Expected values: the colours and cross-sections of the example's connection list, read from the
served graph by the test itself.
"""

from __future__ import annotations

from typing import Any

import httpx
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select

from tests.server.browser import health, open_page, set_editor, text_of, wait

MEASURES = """SELECT ?colour (COUNT(?w) AS ?wires) (SUM(?len) AS ?totalLength)
WHERE { ?w a ck:Wire ; ck:colour ?colour ; ck:lengthM ?len } GROUP BY ?colour ORDER BY ?colour"""
GROUPED = """SELECT (STR(?cs) AS ?section) ?colour (COUNT(?w) AS ?wires)
WHERE { ?w a ck:Wire ; ck:colour ?colour ; ck:crossSectionMm2 ?cs }
GROUP BY ?cs ?colour ORDER BY ?cs ?colour"""


def run(driver: Any, text: str) -> None:
    set_editor(driver, text)
    driver.execute_script("document.getElementById('status').textContent = ''")
    driver.find_element(By.ID, "run").click()
    wait(driver, lambda d: "row(s)" in text_of(d, "status"), 60, "the answer")
    driver.find_element(By.ID, "show-chart").click()


def legend(driver: Any) -> list[str]:
    return [str(t.text) for t in driver.find_elements(By.CSS_SELECTOR, "#chart .legend-text")]


def fills(driver: Any) -> list[str]:
    bars = driver.find_elements(By.CSS_SELECTOR, "#chart rect.series-bar")
    return [str(b.get_attribute("fill")) for b in bars]


def rows(base: str, text: str) -> list[dict[str, str]]:
    answer = httpx.post(
        f"{base}/sparql", data={"query": text}, headers={"Accept": "application/sparql-results+json"}
    )
    return [{k: v["value"] for k, v in b.items()} for b in answer.json()["results"]["bindings"]]


def test_grouped_series_and_their_legend(browser: Any, iema_site: str) -> None:
    driver = browser
    open_page(driver, f"{iema_site}/")
    colours = rows(iema_site, MEASURES)
    assert len(colours) >= 2
    run(driver, MEASURES)
    assert Select(driver.find_element(By.ID, "chart-series")).first_selected_option.text == "every measure"
    assert legend(driver) == ["wires", "totalLength"]
    assert len(fills(driver)) == 2 * len(colours) and len(set(fills(driver))) == 2
    ticks = [str(t.text) for t in driver.find_elements(By.CSS_SELECTOR, "#chart text.tick")]
    assert ticks == [c["colour"] for c in colours]

    grouped = rows(iema_site, GROUPED)
    names = sorted({r["colour"] for r in grouped})
    run(driver, GROUPED)
    assert Select(driver.find_element(By.ID, "chart-x")).first_selected_option.text == "section"
    assert Select(driver.find_element(By.ID, "chart-series")).first_selected_option.text == "by colour"
    assert sorted(legend(driver)) == names
    assert len(fills(driver)) == len(grouped) and len(set(fills(driver))) == len(names)
    titles = {
        str(t.get_attribute("textContent"))
        for t in driver.find_elements(By.CSS_SELECTOR, "#chart rect.series-bar title")
    }
    assert titles == {f"{r['section']}, {r['colour']}: {int(r['wires']):,}" for r in grouped}

    Select(driver.find_element(By.ID, "chart-series")).select_by_visible_text("(one)")
    assert not fills(driver) and driver.find_elements(By.CSS_SELECTOR, "#chart rect.bar")
    assert health(driver, iema_site) == []
