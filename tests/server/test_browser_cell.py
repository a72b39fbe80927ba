"""The 3D view of the page end to end in headless Chromium (WebGL by SwiftShader), against
``cadkg serve`` on the IEMA, ELVEZ, ELIMCO and VW examples: the cell drawn as a committed golden picture
shows it (within a tolerance), a click picks an object and shows its label, IRI, facts and (for
a component) its pins, a result row naming a component highlights it, and group_connection_provider
steps through the wires.

Expected values come from the examples (see tests/server/test_workbench.py): IEMA's 117 items
(56 distinct meshes) and 110 wires, ``cad_service`` giving ``F1500.1`` 10 pins with screw and
hole; ELVEZ's 7 guides (a key and a key corner each) and 3 taping spots; ELIMCO's 6 bench pins
(one double) and 3 routes; the KBL harness's 31 nodes and its connector ``TMR.2A1`` at
``Cartesian_point_231``.
"""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from selenium.webdriver.common.by import By

from tests.conftest import EXAMPLES
from tests.server.browser import compare_with_golden, health, set_editor, settled, text_of, wait
from tests.server.cell_view import click_on, open_cell, picked, picture, visible_labels
from tests.server.serving import cadkg_serve

IEMA = "https://example.org/cell/iema-qe01/"
ELVEZ = "https://example.org/cell/elvez/"


def test_the_iema_cell_in_3d(browser: Any, iema_site: str, tmp_path: Path) -> None:
    driver = browser
    open_cell(driver, iema_site)
    status = text_of(driver, "cell-status")
    assert "117 objects (56 distinct meshes)" in status and "110 wires" in status, status
    compare_with_golden(picture(driver), "iema-cell", tmp_path)

    click_on(driver, "F1500.1")
    wait(driver, lambda d: picked(d) == f"{IEMA}component/F1500.1", 30, "F1500.1 picked")
    assert text_of(driver, "pick-title") == "F1500.1"
    script = "return document.getElementById('cell-status').dataset.pins"
    wait(driver, lambda d: d.execute_script(script) == "10", 30, "its 10 pins")
    wait(driver, lambda d: "ck:hasPin" in text_of(d, "pick-facts"), 30, "its facts")
    driver.find_element(By.ID, "pick-zoom").click()
    settled(driver)
    pins = visible_labels(driver, ".cell-label.pin")
    assert len(pins) >= 8 and set(pins) <= {"1", "2", "3", "4", "5", "6", "13", "14", "21", "22"}, pins
    compare_with_golden(picture(driver), "iema-f1500", tmp_path)

    # The wire group_connection_provider gives first: 1500.51 from F1500.1:14 to Q1500.1:A1.
    driver.find_element(By.ID, "cell-next-wire").click()
    wait(driver, lambda d: text_of(d, "pick-title").startswith("wire 1500.51"), 30, "the first wire")
    assert picked(driver) == f"{IEMA}wire/1500.51"
    wait(driver, lambda d: {"F1500.1:14", "Q1500.1:A1"} <= set(visible_labels(d)), 30, "its ends")

    # A result row that names a component highlights it in the view.
    labels = "SELECT DISTINCT ?label ?c WHERE { ?c a ck:Component ; ck:label ?label } ORDER BY ?label"
    set_editor(driver, labels)
    driver.find_element(By.ID, "run").click()
    wait(driver, lambda d: "row(s)" in text_of(d, "status"), 60)
    row = driver.find_element(By.XPATH, "//table[@id='results']//tr[td[1][text()='Q1500.1']]")
    assert "locatable" in str(row.get_attribute("class"))
    row.find_element(By.XPATH, "td[1]").click()  # its label (a click on an IRI opens its graph)
    wait(driver, lambda d: picked(d) == f"{IEMA}component/Q1500.1", 30, "Q1500.1 highlighted")
    assert health(driver, iema_site) == []


@pytest.fixture(scope="module")
def elvez_site() -> Iterator[str]:
    with cadkg_serve(str(EXAMPLES / "elvez-cell" / "manifest.toml")) as base:
        yield base


def test_the_elvez_cell_with_its_platforms(browser: Any, elvez_site: str, tmp_path: Path) -> None:
    # The example in the real ELVEZ files: tables, jigs, combs, the box and the ATC slots, each
    # at its platform's frame with its mesh; the key centre and corner of the 7 guides, the 3
    # taping spots and the 7 cables' routes over the keys.
    driver = browser
    open_cell(driver, elvez_site)
    status = text_of(driver, "cell-status")
    assert "12 objects (11 distinct meshes)" in status and "17 points of interest" in status, status
    assert "7 wires" in status, status
    compare_with_golden(picture(driver), "elvez-cell", tmp_path)
    click_on(driver, "J3 guide 2")
    wait(driver, lambda d: picked(d) == f"{ELVEZ}element/platform/ID0004", 30, "J3's guide 2 picked")
    assert text_of(driver, "pick-title") == "J3 guide 2"
    assert health(driver, elvez_site) == []


def test_the_elimco_bench_with_its_pins(browser: Any, tmp_path: Path) -> None:
    driver = browser
    with cadkg_serve(str(EXAMPLES / "elimco-bench" / "manifest.toml")) as base:
        open_cell(driver, base)
        status = text_of(driver, "cell-status")
        # pin_info.xml: 6 pins, one of them double (its frame and one for each prong: 8 points);
        # path_info.xml: 3 routes.
        assert "8 points of interest" in status and "3 wires" in status, status
        compare_with_golden(picture(driver), "elimco-bench", tmp_path)
        click_on(driver, "A918VC1A")
        wait(driver, lambda d: picked(d).endswith("/bench-pin/A918VC1A"), 30, "the pin A918VC1A")
        assert text_of(driver, "pick-title") == "A918VC1A"
        wait(driver, lambda d: "ck:BenchPin" in text_of(d, "pick-facts"), 30, "its facts")
        assert health(driver, base) == []


def test_the_vw_harness_at_its_coordinates(browser: Any, tmp_path: Path) -> None:
    driver = browser
    with cadkg_serve(str(EXAMPLES / "vw-harness" / "manifest.toml")) as base:
        open_cell(driver, base)
        status = text_of(driver, "cell-status")
        assert "harness 000971619: 31 nodes at the coordinates of their harness file" in status, status
        assert "harness DOOR-L: 6 nodes at a layout (the graph has no coordinates)" in status, status
        assert "TMR.2A1" in visible_labels(driver)
        compare_with_golden(picture(driver), "vw-harness", tmp_path)
        click_on(driver, "TMR.2A1")
        wait(driver, lambda d: picked(d).endswith("/node/000971619/Node_1"), 30, "the node of TMR.2A1")
        assert "TMR.2A1" in text_of(driver, "pick-title")
        assert health(driver, base) == []
