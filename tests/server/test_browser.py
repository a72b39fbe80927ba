"""The web page end to end in headless Chromium (see tests/server/browser.py), against
``cadkg serve`` on the IEMA example in a subprocess: the SPARQL editor (completion, tabs,
permalinks, local storage), named queries that keep their parameters, the result table
(paging, sorting, filtering), the chart, downloads, and the graph view.

Expected values come from the example's files: ``lista-cablaggio.csv`` has 110 wires, 8 of
them at ``F1500.1``; ``ids.wri`` labels 63 components, the root item's ``1`` first.
"""

from __future__ import annotations

import time
from typing import Any

import httpx
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import Select

from tests.server.browser import (
    chord,
    column,
    editor,
    editor_text,
    health,
    keys,
    open_page,
    set_editor,
    text_of,
    wait,
)

SRJ = "application/sparql-results+json"


def completion_options(driver: Any) -> list[str]:
    shadow = driver.find_element(By.ID, "query").shadow_root
    return [
        str(li.get_attribute("textContent"))
        for li in shadow.find_elements(By.CSS_SELECTOR, ".cm-completionLabel")
    ]


def complete(driver: Any, typed: str, wanted: str) -> None:
    """Type ``typed``, wait for ``wanted`` among the completions, pick it with the arrows and Enter."""
    keys(driver, typed)
    options = wait(driver, lambda d: (o := completion_options(d)) and wanted in o and o, 20, wanted)
    time.sleep(0.3)  # the editor takes no Enter in the first 75 ms of a completion, against slips
    keys(driver, *[Keys.ARROW_DOWN] * options.index(wanted), Keys.ENTER)


def clear_editor(driver: Any) -> None:
    editor(driver).click()
    chord(driver, Keys.CONTROL, "a")
    keys(driver, Keys.BACKSPACE)
    wait(driver, lambda d: editor_text(d) == "", 10, "an empty editor")


def run_and_wait(driver: Any, expect: str = "row(s)") -> str:
    before = driver.execute_script("return document.getElementById('status').textContent")
    driver.find_element(By.ID, "run").click()
    wait(driver, lambda d: ((s := text_of(d, "status")) != before and expect in s) or text_of(d, "error"), 60)
    assert not driver.find_element(By.ID, "error").is_displayed(), text_of(driver, "error")
    return text_of(driver, "status")


def test_a_query_typed_with_completion_pages_and_travels_by_link(browser: Any, iema_site: str) -> None:
    driver = browser
    open_page(driver, f"{iema_site}/")
    clear_editor(driver)
    keys(driver, "SELECT ?wire ?number WHERE { ?wire a ")
    complete(driver, "Wi", "ck:Wire")
    keys(driver, " ; ")
    complete(driver, "ck:wireN", "ck:wireNumber")
    keys(driver, " ?number", Keys.END, Keys.ENTER, "ORDER BY ?")
    complete(driver, "num", "?number")
    text = editor_text(driver)
    # Completing a ck: term declared the prefix.
    assert text.startswith("PREFIX ck: <https://w3id.org/cadkg#>\n"), text
    assert "?wire a ck:Wire ; ck:wireNumber ?number}" in text and text.endswith("ORDER BY ?number")
    chord(driver, Keys.CONTROL, Keys.ENTER)
    wait(driver, lambda d: "110 row(s)" in text_of(d, "status"), 60, "110 rows")
    assert text_of(driver, "page-info") == "page 1 of 2"
    first = column(driver, 2)
    assert len(first) == 100 and first[0] == "0010.01"
    driver.find_element(By.ID, "page-next").click()
    wait(driver, lambda d: text_of(d, "page-info") == "page 2 of 2", 10)
    second = column(driver, 2)
    assert len(second) == 10 and first + second == sorted(first + second)
    assert all(w.startswith("cell:wire/") for w in column(driver, 1))  # the cell's base IRI as a prefix

    link = str(driver.find_element(By.ID, "permalink").get_attribute("value"))
    assert "#query=" in link and driver.current_url == link
    driver.switch_to.new_window("tab")
    try:
        driver.get(link)
        wait(driver, lambda d: "110 row(s)" in text_of(d, "status"), 60, "the link's rows")
        assert column(driver, 2) == first
        assert editor_text(driver) == text
        # The tabs are kept in local storage: the page without a link has the query too.
        open_page(driver, f"{iema_site}/")
        assert editor_text(driver) == text
        # A new tab starts afresh; the first keeps its text.
        tabs = len(driver.find_elements(By.CSS_SELECTOR, "#tab-list .tab"))
        driver.find_element(By.ID, "tab-add").click()
        assert len(driver.find_elements(By.CSS_SELECTOR, "#tab-list .tab")) == tabs + 1
        assert "SELECT * WHERE" in editor_text(driver)
        driver.find_elements(By.CSS_SELECTOR, "#tab-list .tab")[0].click()
        assert editor_text(driver) != "" and "SELECT * WHERE {\n  \n}" not in editor_text(driver)
        assert health(driver, iema_site) == []
    finally:
        driver.close()
        driver.switch_to.window(driver.window_handles[0])


def test_an_edited_named_query_keeps_its_parameter(browser: Any, iema_site: str) -> None:
    driver = browser
    open_page(driver, f"{iema_site}/")
    Select(driver.find_element(By.ID, "examples")).select_by_value("wires-of-component")
    block = 'VALUES (?label) { ("F1500.1") }'
    wait(driver, lambda d: block in editor_text(d), 20, "the bound query")
    assert driver.find_element(By.ID, "param-label").get_property("value") == "F1500.1"
    assert block in text_of(driver, "binding")
    # Edit the text: a space after SELECT.
    editor(driver).click()
    chord(driver, Keys.CONTROL, Keys.HOME)
    text = editor_text(driver)
    line = text[: text.index("SELECT")].count("\n")
    keys(driver, *[Keys.ARROW_DOWN] * line, Keys.END, " ")
    assert editor_text(driver) != text and block in editor_text(driver)
    assert "8 row(s)" in run_and_wait(driver)
    assert set(column(driver, 3)) == {
        "1500.51", "1500.50", "1500.01", "1500.02", "1500.03", "0010.03", "0010.04", "0010.05",
    }  # fmt: skip
    # Another label: the field rewrites the VALUES block in the edited text.
    field = driver.find_element(By.ID, "param-label")
    field.clear()
    field.send_keys("Q1500.1")
    status = run_and_wait(driver)
    expected = httpx.get(f"{iema_site}/api/queries/wires-of-component", params={"label": "Q1500.1"}).json()
    count = len(expected["results"]["bindings"])
    assert count > 0 and f"{count} row(s)" in status
    assert 'VALUES (?label) { ("Q1500.1") }' in editor_text(driver)
    assert "SELECT  DISTINCT" in editor_text(driver) or "SELECT DISTINCT " in editor_text(driver)
    assert set(column(driver, 1)) == {"Q1500.1"}
    # The permalink carries the parameter.
    link = str(driver.find_element(By.ID, "permalink").get_attribute("value"))
    assert "named=wires-of-component" in link and "p.label=Q1500.1" in link


def test_results_sort_filter_chart_and_download(browser: Any, iema_site: str) -> None:
    driver = browser
    open_page(driver, f"{iema_site}/")
    driver.find_element(By.ID, "tab-add").click()
    set_editor(
        driver,
        "SELECT ?colour (COUNT(?w) AS ?wires) WHERE { ?w a ck:Wire ; ck:colour ?colour }\n"
        "GROUP BY ?colour ORDER BY DESC(?wires) ?colour",
    )
    run_and_wait(driver)
    colours = column(driver, 1)
    counts = [int(c) for c in column(driver, 2)]
    assert counts == sorted(counts, reverse=True) and sum(counts) == 110
    # Sort by colour, ascending then descending.
    header = driver.find_elements(By.CSS_SELECTOR, "#results thead th")[0]
    header.click()
    assert column(driver, 1) == sorted(colours)
    driver.find_elements(By.CSS_SELECTOR, "#results thead th")[0].click()
    assert column(driver, 1) == sorted(colours, reverse=True)
    # Filter.
    driver.find_element(By.ID, "filter").send_keys(colours[0])
    wait(driver, lambda d: column(d, 1) == [colours[0]], 10)
    assert text_of(driver, "status").startswith("1 of ")
    driver.find_element(By.ID, "filter").send_keys(Keys.CONTROL, "a")
    driver.find_element(By.ID, "filter").send_keys(Keys.BACKSPACE)
    wait(driver, lambda d: len(column(d, 1)) == len(colours), 10)
    # A chart of the numeric column: one bar per colour, the tallest the first row's.
    driver.find_element(By.ID, "show-chart").click()
    bars = driver.find_elements(By.CSS_SELECTOR, "#chart rect.bar")
    assert len(bars) == len(colours)
    heights = [float(b.get_attribute("height") or 0) for b in bars]
    assert (
        max(heights) > 0
        and Select(driver.find_element(By.ID, "chart-y")).first_selected_option.text == "wires"
    )
    driver.find_element(By.ID, "show-table").click()
    # Downloads: CSV of this answer.
    save(driver, "csv", "query.csv")
    lines = (driver.downloads / "query.csv").read_text().splitlines()
    assert lines[0] == "colour,wires" and len(lines) == len(colours) + 1

    # SELECT * keeps the query's column order; a CONSTRUCT answers triples, saved as Turtle.
    set_editor(driver, "SELECT * WHERE { ?wire ck:wireNumber ?number ; ck:colour ?c } LIMIT 3")
    run_and_wait(driver)
    names = [th.text for th in driver.find_elements(By.CSS_SELECTOR, "#results thead th")]
    assert names == ["wire", "number", "c"]
    cell = driver.find_element(By.CSS_SELECTOR, "#results tbody td")
    assert cell.value_of_css_property("white-space") == "nowrap"
    set_editor(driver, "CONSTRUCT { ?w ck:wireNumber ?n } WHERE { ?w ck:wireNumber ?n } ORDER BY ?n LIMIT 5")
    assert "5 triple(s)" in run_and_wait(driver, "triple(s)")
    assert column(driver, 2) == ["ck:wireNumber"] * 5
    formats = [
        o.get_attribute("value") for o in Select(driver.find_element(By.ID, "download-format")).options
    ]
    assert formats == ["ttl", "nt", "jsonld", "rdfxml"]
    save(driver, "ttl", "query.ttl")
    turtle = (driver.downloads / "query.ttl").read_text()
    assert "@prefix ck: <https://w3id.org/cadkg#>" in turtle and turtle.count("ck:wireNumber") == 5
    assert health(driver, iema_site) == []


def save(driver: Any, fmt: str, name: str) -> None:
    target = driver.downloads / name
    target.unlink(missing_ok=True)
    Select(driver.find_element(By.ID, "download-format")).select_by_value(fmt)
    driver.find_element(By.ID, "download").click()
    deadline = time.monotonic() + 30
    while not (target.is_file() and target.stat().st_size > 0):
        assert time.monotonic() < deadline, f"{name} was not downloaded"
        time.sleep(0.1)


def boxes(driver: Any, selector: str) -> list[dict[str, float]]:
    found: list[dict[str, float]] = driver.execute_script(
        """return [...document.querySelectorAll(arguments[0])]
             .filter(e => getComputedStyle(e).display !== 'none')
             .map(e => e.getBoundingClientRect())
             .map(r => ({x: r.x, y: r.y, w: r.width, h: r.height}));""",
        selector,
    )
    return found


def overlapping(found: list[dict[str, float]]) -> list[tuple[int, int]]:
    pairs = []
    for i, a in enumerate(found):
        for j, b in enumerate(found[:i]):
            if (
                a["x"] + 1 < b["x"] + b["w"]
                and b["x"] + 1 < a["x"] + a["w"]
                and a["y"] + 1 < b["y"] + b["h"]
                and b["y"] + 1 < a["y"] + a["h"]
            ):
                pairs.append((j, i))
    return pairs


def test_graph_view_walks_zooms_and_keeps_labels_apart(browser: Any, iema_site: str) -> None:
    driver = browser
    open_page(driver, f"{iema_site}/")
    driver.find_element(By.ID, "view-graph").click()
    field = driver.find_element(By.ID, "component")
    field.clear()
    field.send_keys("F1500.1", Keys.ENTER)
    wait(driver, lambda d: text_of(d, "graph-status").startswith("component F1500.1"), 30)
    labels = {
        e.get_attribute("textContent")
        for e in driver.find_elements(By.CSS_SELECTOR, "#graph text.node-label")
    }
    assert {"F1500.1", "Q1500.1", "X1600", "Q0010", "14", "13"} <= labels
    assert len(driver.find_elements(By.CSS_SELECTOR, "#graph line.edge.wire")) == 8
    shown = boxes(driver, "#graph text.node-label, #graph text.edge-label")
    assert len(shown) >= 12 and overlapping(shown) == []

    # Zoom in with the button, pan by dragging the background: the viewBox follows.
    def view_box() -> list[float]:
        box = driver.execute_script("return document.getElementById('graph').getAttribute('viewBox')")
        return [float(v) for v in str(box).split()]

    before = view_box()
    driver.find_element(By.ID, "graph-zoom-in").click()
    zoomed = view_box()
    assert zoomed[2] < before[2] * 0.8
    from selenium.webdriver.common.action_chains import ActionChains

    canvas = driver.find_element(By.ID, "graph")
    ActionChains(driver).move_to_element_with_offset(canvas, -250, 200).click_and_hold().move_by_offset(
        120, 0
    ).release().perform()
    assert view_box()[0] < zoomed[0]
    # Labels stay apart at the new zoom too.
    time.sleep(0.3)
    assert overlapping(boxes(driver, "#graph text.node-label, #graph text.edge-label")) == []
    driver.find_element(By.ID, "graph-fit").click()
    # Walk on to a neighbour, and back.
    target = driver.find_element(
        By.CSS_SELECTOR, "#graph g.node.kind-component[data-id$='/component/Q1500.1'] circle"
    )
    target.click()
    wait(driver, lambda d: text_of(d, "graph-status").startswith("component Q1500.1"), 30)
    driver.find_element(By.ID, "graph-back").click()
    wait(driver, lambda d: text_of(d, "graph-status").startswith("component F1500.1"), 30)
    assert health(driver, iema_site) == []
