"""The web page end to end in headless Chromium (Debian's chromium and chromium-driver, driven by
Selenium), against ``cadkg serve`` on the IEMA example in a subprocess.

``scripts/browser-setup.sh`` installs the browser when it is missing; the test is skipped only
when apt cannot install it on this machine (no root, no apt, no package), and says why.
"""

from __future__ import annotations

import os
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from tests.conftest import IEMA, ROOT
from tests.server.serving import cadkg_serve

SETUP = ROOT / "scripts" / "browser-setup.sh"
CANNOT_INSTALL = ("needs apt-get", "needs root", "apt-get update", "apt-get install")
CHROMIUM_ARGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--window-size=1400,1000",
)
LABELS = "SELECT DISTINCT ?label WHERE { ?c a ck:Component ; ck:label ?label } ORDER BY ?label"


@pytest.fixture(scope="module")
def browser() -> Iterator[Any]:
    setup = subprocess.run(["bash", str(SETUP)], cwd=ROOT, capture_output=True, text=True, timeout=900)
    if setup.returncode != 0:
        line = (setup.stderr.strip().splitlines() or ["(no output)"])[-1]
        if any(reason in line for reason in CANNOT_INSTALL):
            pytest.skip(f"chromium cannot be installed on this machine: {line}")
        pytest.fail(f"scripts/browser-setup.sh failed: {line}\n{setup.stdout}")
    os.environ["SE_OFFLINE"] = "true"  # Selenium must never look for a driver or browser online
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = "/usr/bin/chromium"
    for argument in CHROMIUM_ARGS:
        options.add_argument(argument)
    driver = webdriver.Chrome(service=Service(executable_path="/usr/bin/chromedriver"), options=options)
    try:
        yield driver
    finally:
        driver.quit()


def column(driver: Any, index: int) -> list[str]:
    from selenium.webdriver.common.by import By

    return [
        td.text for td in driver.find_elements(By.CSS_SELECTOR, f"#results tbody tr td:nth-child({index})")
    ]


def test_page_end_to_end(browser: Any, tmp_path: Path) -> None:
    from selenium.webdriver.common.by import By
    from selenium.webdriver.common.keys import Keys
    from selenium.webdriver.support.ui import Select, WebDriverWait

    driver = browser
    wait = WebDriverWait(driver, 30)
    with cadkg_serve(str(IEMA)) as base:
        driver.get(f"{base}/")
        editor = driver.find_element(By.ID, "query")
        wait.until(lambda d: "PREFIX ck: <https://w3id.org/cadkg#>" in editor.get_property("value"))
        wait.until(lambda d: "triples" in d.find_element(By.ID, "info").text)

        # Type a query and run it: the component labels of ids.wri, sorted by the query.
        editor.clear()
        editor.send_keys(LABELS)
        driver.find_element(By.ID, "run").click()
        wait.until(lambda d: "row(s)" in d.find_element(By.ID, "status").text)
        labels = column(driver, 1)
        assert len(labels) == 62
        assert labels[0] == "A0080.1"
        assert {"F1500.1", "Q1500.1", "X1600", "Q0010"} <= set(labels)

        # Sort the column: first click ascending, second descending.
        driver.find_element(By.CSS_SELECTOR, "#results thead th").click()
        header = driver.find_element(By.CSS_SELECTOR, "#results thead th")
        assert header.get_attribute("aria-sort") == "ascending"
        ascending = column(driver, 1)
        assert ascending[0] == "A0080.1" and sorted(ascending) == sorted(labels)
        header.click()
        header = driver.find_element(By.CSS_SELECTOR, "#results thead th")
        assert header.get_attribute("aria-sort") == "descending"
        assert column(driver, 1) == ascending[::-1]

        # A syntax error shows the parser's position.
        editor = driver.find_element(By.ID, "query")
        editor.clear()
        editor.send_keys("SELECT ?x WHERE { ?x ck:label }")
        editor.send_keys(Keys.CONTROL, Keys.ENTER)
        wait.until(lambda d: d.find_element(By.ID, "error").is_displayed())
        assert "SPARQL syntax error at line 1" in driver.find_element(By.ID, "error").text

        # Pick a named query: its parameter comes filled with the example of its header.
        Select(driver.find_element(By.ID, "examples")).select_by_value("wires-of-component")
        assert driver.find_element(By.ID, "param-label").get_property("value") == "F1500.1"
        driver.find_element(By.ID, "run").click()
        wait.until(lambda d: "8 row(s)" in d.find_element(By.ID, "status").text)
        numbers = column(driver, 3)
        assert numbers[0] == "1500.51"
        assert set(numbers) == {
            "1500.51",
            "1500.50",
            "1500.01",
            "1500.02",
            "1500.03",
            "0010.03",
            "0010.04",
            "0010.05",
        }
        # Numbers sort as numbers: sequence 46 first when descending.
        sequence = driver.find_elements(By.CSS_SELECTOR, "#results thead th")[1]
        sequence.click()
        driver.find_elements(By.CSS_SELECTOR, "#results thead th")[1].click()
        assert column(driver, 2) == ["46", "45", "44", "21", "20", "19", "4", "1"]
        csv_link = driver.find_element(By.ID, "download-csv").get_attribute("href")
        assert csv_link is not None and "format=csv" in csv_link
        download = httpx.get(csv_link)
        assert download.text.splitlines()[0] == "label,sequence,wireNumber,pin,otherEnd,section,colour,wire"
        assert len(download.text.splitlines()) == 9

        # The graph view: F1500.1, its pins and the components its wires reach.
        field = driver.find_element(By.ID, "component")
        field.send_keys("F1500.1")
        driver.find_element(By.ID, "show-graph").click()
        wait.until(lambda d: d.find_elements(By.CSS_SELECTOR, "#graph g.node"))
        nodes = {n.text for n in driver.find_elements(By.CSS_SELECTOR, "#graph g.node text")}
        assert {"F1500.1", "Q1500.1", "X1600", "Q0010", "14", "13"} <= nodes
        assert len(driver.find_elements(By.CSS_SELECTOR, "#graph line.edge.wire")) == 8
        driver.save_screenshot(str(tmp_path / "graph.png"))
        # Click a neighbour: the view walks on to it.
        target = driver.find_element(
            By.XPATH,
            "//*[local-name()='g'][*[local-name()='text' and text()='Q1500.1']]/*[local-name()='circle']",
        )
        target.click()
        wait.until(lambda d: d.find_element(By.ID, "graph-status").text.startswith("component Q1500.1"))
        assert driver.find_element(By.ID, "graph-back").is_enabled()
