"""The page on every example cell in headless Chromium, as a new user meets it: the header names
the cell and its profile; the named queries offered are the cell's own and cadkg's (those of
other profiles behind a box); the IEMA cabinet's controls show on IEMA only; an empty scene
(ENKI) and an answer without rows say so in words; every kind of thing the 3D view draws
(components, jigs and tools, guides' keys, taping spots, bench pins, harness nodes by
connector, wires) is found by search, zoomed to and highlighted, and picked by a click; the
graph view offers only labels it can show and says why when it cannot.

Expected values: the examples' manifests name the cells; ``/api/cell`` and the query folders
(``src/cadkg/usecases/<profile>/queries``) give which queries are whose; the labels and IRIs
are the examples' (see tests/server/test_workbench.py).
"""

from __future__ import annotations

import math
import re
from typing import Any

import httpx
import pytest
from PIL import Image
from selenium.webdriver.common.by import By
from selenium.webdriver.support.ui import Select

from tests.conftest import EXAMPLES
from tests.server.browser import editor_text, health, open_page, set_editor, settled, text_of, wait
from tests.server.cell_view import click_on, open_cell, picked
from tests.server.serving import cadkg_serve

CORE = {
    "components",
    "pins-of-component",
    "plan-steps",
    "sources",
    "wire-endpoints",
    "wires-by-colour-section",
    "wires-of-component",
}
OWN = {
    "iema": {"connections-in-order"},
    "elvez": {
        "elvez-cable-length-per-harness",
        "elvez-harness-cables",
        "elvez-operations-at-spot",
        "elvez-plan",
    },
    "elimco": {"elimco-route", "elimco-wires-of-cable"},
    "vw": {"harness-segment-lengths", "harness-wires-of-connector", "harness-wires-through-segment"},
    "enki": set(),
}
ELVEZ = "https://example.org/cell/elvez/"
# Per profile: what a search finds (label typed, title shown, IRI or "" for an object the graph
# names by label only), and what a click on the view picks.
SEARCHES = {
    "iema": [
        ("F1500.1", "F1500.1", "https://example.org/cell/iema-qe01/component/F1500.1"),
        ("1500.51", "wire 1500.51", "https://example.org/cell/iema-qe01/wire/1500.51"),
    ],
    "elvez": [
        ("J3", "J3", ""),
        ("Agripper", "Agripper", ""),
        ("J3 guide 2", "J3 guide 2", f"{ELVEZ}element/platform/ID0004"),
        (
            "J1.1: taping (operation 5)",
            "J1.1: taping (operation 5)",
            f"{ELVEZ}operation/Assembly_sequence/6/spot/1",
        ),
        ("CA1", "wire CA1", ""),
    ],
    "elimco": [
        ("A918VC1A", "A918VC1A", "https://example.org/cell/elimco-f929a/bench-pin/A918VC1A"),
        ("A4351-1669", "wire A4351-1669", "https://example.org/cell/elimco-f929a/cable/A4351-1669"),
    ],
    "vw": [
        ("X1", "X1", "https://example.org/cell/vw-harness/node/DOOR-L/X1"),
        ("TMR.2A1", "TMR.2A1", "https://example.org/cell/vw-harness/node/000971619/Node_1"),
    ],
    "enki": [],
}
# Facts as read: each once (F1500.1's label and type are stated by four files), numbers rounded
# (the derived rail position is 0.009999999999999995), with the unit the ontology gives.
FACTS = {
    "F1500.1": {
        "ck:railPosition": "0.01 m",
        "ck:xDim": "0.054 m",
        "ck:label": "F1500.1",
        "@stated by several graphs": "ck:label",
    },
    "1500.51": {"ck:crossSectionMm2": "0.75 mm²", "ck:lengthM": "0.746 m", "ck:sequenceIndex": "1"},
}
CLICKS = {
    "iema": [("Q1500.1", "https://example.org/cell/iema-qe01/component/Q1500.1")],
    "elvez": [("J4 guide 1", f"{ELVEZ}element/platform/ID0005"), ("Agripper", "Agripper")],
    "elimco": [("A350VC-A", "https://example.org/cell/elimco-f929a/bench-pin/A350VC-A")],
    "vw": [("X2", "https://example.org/cell/vw-harness/node/DOOR-L/X2")],
    "enki": [],
}
COUNT = "(count of rows)"
DEFAULT_Y = {
    "components": "pins",
    "connections-in-order": "lengthM",
    "pins-of-component": "wires",
    "sources": "triples",
    "wire-endpoints": COUNT,
    "wires-by-colour-section": "wires",
    "wires-of-component": COUNT,
    "elvez-cable-length-per-harness": "cables",
    "elvez-harness-cables": "lengthM",
    "elvez-operations-at-spot": COUNT,
    "elvez-plan": COUNT,
    "elimco-route": "y",
    "elimco-wires-of-cable": "lengthM",
    "harness-segment-lengths": "length",
    "harness-wires-of-connector": "length",
    "harness-wires-through-segment": COUNT,
}
# Columns of identifiers that look like numbers: text, not right-aligned numbers.
IDENTIFIERS = {
    "wires-of-component": ("wireNumber",),
    "connections-in-order": ("wireNumber",),
    "harness-segment-lengths": ("harness",),
    "elvez-cable-length-per-harness": ("harness",),
}
# Components without pins, which the graph view shows as nodes with their neighbours.
GRAPH_LABELS = {"elvez": ("K1",), "vw": ("X1",)}
CELLS = [
    ("iema-switchgear", "IEMA switchgear QE01", "iema"),
    ("elvez-cell", "ELVEZ harness assembly cell", "elvez"),
    ("elimco-bench", "ELIMCO harness F929A on the pin workbench", "elimco"),
    ("vw-harness", "Volkswagen harness detection", "vw"),
    ("enki-hose", "ENKI hose handling", "enki"),
]


def offered(driver: Any) -> set[str]:
    options = driver.find_elements(By.CSS_SELECTOR, "#examples option")
    return {str(o.get_attribute("value")) for o in options} - {""}


def shown(driver: Any, element_id: str) -> bool:
    return bool(driver.find_element(By.ID, element_id).is_displayed())


@pytest.mark.parametrize(("example", "name", "profile"), CELLS, ids=[c[2] for c in CELLS])
def test_the_page_is_the_cells_own(browser: Any, example: str, name: str, profile: str) -> None:
    driver = browser
    with cadkg_serve(str(EXAMPLES / example / "manifest.toml")) as base:
        open_page(driver, f"{base}/")
        assert text_of(driver, "cell-name") == name
        assert text_of(driver, "cell-profile") == profile
        assert name in driver.title

        others = set().union(*OWN.values()) - OWN[profile]
        assert offered(driver) == CORE | OWN[profile]
        driver.find_element(By.ID, "examples-all").click()
        assert offered(driver) == CORE | set().union(*OWN.values())
        driver.find_element(By.ID, "examples-all").click()
        assert not offered(driver) & others

        # A query that matches nothing says so, not just a bare header.
        set_editor(driver, "SELECT ?s WHERE { ?s a <urn:nothing:here> }")
        driver.find_element(By.ID, "run").click()
        wait(driver, lambda d: shown(d, "no-results"), 60, "the no-results line")
        assert "No results" in text_of(driver, "no-results")
        assert "0 row(s)" in text_of(driver, "status")
        assert not driver.find_elements(By.CSS_SELECTOR, "#results tbody tr")

        # The default chart of each of the cell's named queries (those with rows) is a measure,
        # never an identifier, over a column that tells the rows apart or groups them.
        for query in sorted(CORE | OWN[profile]):
            Select(driver.find_element(By.ID, "examples")).select_by_value(query)
            wait(driver, lambda d, q=query: f"{q}:" in editor_text(d) or q in editor_text(d), 30, query)
            driver.execute_script("document.getElementById('status').textContent = ''")
            driver.find_element(By.ID, "run").click()
            wait(driver, lambda d: "row(s)" in text_of(d, "status"), 60, f"{query} answered")
            if text_of(driver, "status").startswith("0 row(s)"):
                assert shown(driver, "no-results"), query
                continue
            driver.find_element(By.ID, "show-chart").click()
            y = Select(driver.find_element(By.ID, "chart-y")).first_selected_option.text
            assert y == DEFAULT_Y[query], (query, y)
            marks = driver.find_elements(
                By.CSS_SELECTOR,
                "#chart rect.bar, #chart polyline.line, #chart rect.series-bar, #chart polyline.series-line",
            )
            assert marks and driver.find_elements(By.CSS_SELECTOR, "#chart .legend-text"), query
            driver.find_element(By.ID, "show-table").click()
            for name in IDENTIFIERS.get(query, ()):
                index = [th.text for th in driver.find_elements(By.CSS_SELECTOR, "#results thead th")].index(
                    name
                )
                cells = driver.find_elements(By.CSS_SELECTOR, f"#results tbody td:nth-child({index + 1})")
                assert cells and not [c for c in cells if "num" in str(c.get_attribute("class"))], (
                    query,
                    name,
                )
        # The editor keeps its height whatever the query's length (the results stay in view),
        # and is resized by its corner.
        editor_box = driver.find_element(By.ID, "query")
        assert editor_box.size["height"] <= 300 and editor_box.value_of_css_property("resize") == "vertical"
        assert driver.find_element(By.ID, "results-pane").location["y"] < 900
        driver.execute_script("document.getElementById('query').style.height = '480px'")
        inner = "return document.getElementById('query').shadowRoot.querySelector('.cm-editor').offsetHeight"
        wait(driver, lambda d: abs(d.execute_script(inner) - 480) <= 2, 10, "the editor resized")
        driver.execute_script("document.getElementById('query').style.height = ''")
        driver.find_element(By.ID, "tab-add").click()

        # Every label the graph view offers, it shows; one it does not have, it says so.
        labels = [
            str(o.get_attribute("value"))
            for o in driver.find_elements(By.CSS_SELECTOR, "#graph-labels option")
        ]
        assert labels, "the graph view offers no label"
        for label in {labels[0], labels[len(labels) // 2], labels[-1], *GRAPH_LABELS.get(profile, ())}:
            assert label in labels
            show_graph(driver, label)
            wait(driver, lambda d: graph_status(d) not in ("", "loading…"), 30, f"the graph of {label}")
            status = graph_status(driver)
            assert "nodes" in status and "failed" not in graph_class(driver), (label, status)
            assert driver.find_elements(By.CSS_SELECTOR, "svg#graph .node")
        show_graph(driver, "no such label")
        wait(driver, lambda d: "failed" in graph_class(d), 30, "the graph view's refusal")
        assert "Nothing in the graph is labelled “no such label”" in graph_status(driver)
        assert not driver.find_elements(By.CSS_SELECTOR, "svg#graph .node")

        open_cell(driver, base)
        iema = profile == "iema"
        assert shown(driver, "cell-next-wire") is iema
        assert text_of(driver, "cell-show") == ("Show pins" if iema else "Show")
        assert (
            "F1500.1" not in str(driver.find_element(By.ID, "component").get_attribute("placeholder")) or iema
        )
        empty = driver.find_elements(By.CSS_SELECTOR, "#cell-view .cell-empty")
        if profile == "enki":
            assert empty and "Nothing to draw" in empty[0].text
            assert "nothing to draw" in text_of(driver, "cell-status")
        else:
            assert not empty
        for typed, title, iri in SEARCHES[profile]:
            search(driver, typed)
            wait(driver, lambda d, t=title: text_of(d, "pick-title") == t, 30, f"{typed} found")
            assert highlighted(driver) == (iri or title)
            assert picked(driver) == iri
            if typed in FACTS:
                check_facts(driver, FACTS[typed])
        offered_3d = driver.find_elements(By.CSS_SELECTOR, "#cell-labels option")
        assert {t for t, _, _ in SEARCHES[profile]} <= {str(o.get_attribute("value")) for o in offered_3d}
        search(driver, "no such thing")
        wait(driver, lambda d: "is not drawn in the 3D view" in text_of(d, "cell-status"), 30, "not drawn")
        for label, expected in CLICKS[profile]:
            driver.find_element(By.ID, "cell-fit").click()
            settled(driver)
            click_on(driver, label)
            wait(
                driver,
                lambda d, e=expected: highlighted(d) == e,
                30,
                f"{label} picked by a click, not {highlighted(driver)!r} {text_of(driver, 'pick-title')!r}",
            )
        check_presets_ortho_and_screenshot(driver, profile)
        if profile in MEASURES:
            check_measure(driver, base, *MEASURES[profile])
        assert health(driver, base) == []


# Two things picked for a distance: pins at their poses (exact), components where the click
# meets them (a distance within the cabinet).
MEASURES = {"elimco": ("A918VC1A", "A350VC-A"), "iema": ("F1500.1", "Q1500.1")}


def check_measure(driver: Any, base: str, first: str, second: str) -> None:
    driver.find_element(By.ID, "view-front").click()
    settled(driver)
    driver.find_element(By.ID, "cell-measure").click()
    click_on(driver, first)
    wait(driver, lambda d: "pick the second point" in text_of(d, "cell-status"), 30, "the first point")
    click_on(driver, second)
    wait(
        driver, lambda d: d.find_element(By.ID, "cell-view").get_attribute("data-distance"), 30, "a distance"
    )
    distance = float(driver.find_element(By.ID, "cell-view").get_attribute("data-distance"))
    status = text_of(driver, "cell-status")
    assert f"from {first}" in status and f"to {second}" in status, status
    frames = {f["name"]: f for f in httpx.get(f"{base}/api/scene", timeout=60).json()["frames"]}
    a, b = frames.get(f"pin_{first}"), frames.get(f"pin_{second}")
    if a and b:  # bench pins of one parent frame: the distance of their poses
        assert a["parent"] == b["parent"]
        assert distance == pytest.approx(math.dist(a["t"], b["t"]), abs=1e-6)
        shown_text = f"{distance:.4f} m" if distance >= 1 else f"{distance * 1000:.1f} mm"
        assert shown_text in status
    else:
        assert 0.005 < distance < 2.0, distance
    driver.find_element(By.ID, "cell-measure").click()
    assert driver.find_element(By.ID, "cell-view").get_attribute("data-distance") is None


EYE = (
    "const v = document.getElementById('cell-view').cellView;"
    "return v.camera.position.clone().sub(v.controls.target).normalize().toArray()"
)


def check_presets_ortho_and_screenshot(driver: Any, profile: str) -> None:
    """Front, top and side look along three perpendicular axes and iso between them; the
    orthographic camera still picks; the screenshot is the view's PNG."""
    eyes = {}
    for preset in ("front", "top", "side", "iso"):
        driver.find_element(By.ID, f"view-{preset}").click()
        settled(driver)
        assert driver.find_element(By.ID, "cell-view").get_attribute("data-preset") == preset
        eyes[preset] = driver.execute_script(EYE)

    def dot(a: str, b: str) -> float:
        return float(sum(x * y for x, y in zip(eyes[a], eyes[b], strict=True)))

    if not SEARCHES[profile]:  # nothing drawn: nothing to look at
        eyes = {"front": [0, 0, 1], "top": [0, 1, 0], "side": [1, 0, 0], "iso": [3**-0.5] * 3}
    for a, b in [("front", "top"), ("front", "side"), ("top", "side")]:
        assert abs(dot(a, b)) < 1e-6, (a, b, eyes)
    for a in ("front", "top", "side"):
        assert abs(dot("iso", a) - 3**-0.5) < 1e-6, (a, eyes)
    driver.find_element(By.ID, "view-front").click()  # from a corner, things hide each other
    driver.find_element(By.ID, "view-ortho").click()
    settled(driver)
    script = "return document.getElementById('cell-view').cellView.camera.isOrthographicCamera === true"
    assert driver.execute_script(script)
    for label, expected in CLICKS[profile][:1]:
        click_on(driver, label)
        wait(
            driver, lambda d, e=expected: highlighted(d) == e, 30, f"{label} picked in the orthographic view"
        )
    driver.find_element(By.ID, "view-ortho").click()
    settled(driver)
    assert not driver.execute_script(script)
    saved = driver.downloads / f"cell-{profile}.png"
    saved.unlink(missing_ok=True)
    driver.find_element(By.ID, "cell-screenshot").click()
    wait(driver, lambda d: saved.is_file() and saved.stat().st_size > 1000, 30, "the screenshot")
    canvas = driver.find_element(By.CSS_SELECTOR, "#cell-view canvas")
    with Image.open(saved) as picture:
        assert picture.size == (canvas.size["width"], canvas.size["height"])


def show_graph(driver: Any, label: str) -> None:
    driver.find_element(By.ID, "view-graph").click()
    field = driver.find_element(By.ID, "component")
    field.clear()
    field.send_keys(label)
    driver.execute_script("document.getElementById('graph-status').textContent = ''")
    driver.find_element(By.ID, "show-graph").click()


def graph_status(driver: Any) -> str:
    return text_of(driver, "graph-status")


def graph_class(driver: Any) -> str:
    return str(driver.find_element(By.ID, "graph-status").get_attribute("class") or "")


def fact_rows(driver: Any) -> list[list[str]]:
    rows = driver.find_elements(By.CSS_SELECTOR, "#pick-facts tbody tr")
    return [[str(td.get_attribute("textContent")) for td in r.find_elements(By.TAG_NAME, "td")] for r in rows]


def check_facts(driver: Any, expected: dict[str, str]) -> None:
    wait(driver, lambda d: len(fact_rows(d)) > len(expected), 30, "the facts")
    rows = fact_rows(driver)
    pairs = [(r[0], r[1]) for r in rows]
    assert len(pairs) == len(set(pairs)), pairs
    names = [p for p, _ in pairs]
    first = [p for p in names if p in ("rdf:type", "ck:label")]
    assert names[: len(first)] == first and first[0] == "rdf:type", names
    rest = names[len(first) :]
    assert rest == sorted(rest, key=str.lower), rest
    values = dict(pairs)
    for name, value in expected.items():
        assert name.startswith("@") or values[name] == value, (name, values.get(name))
    assert not [v for _, v in pairs if re.search(r"\d\.\d{9,}", v)], pairs
    driver.find_element(By.ID, "pick-graphs").click()
    graphs = fact_rows(driver)
    assert all(len(r) == 3 and r[2].startswith("cell:") for r in graphs), graphs
    several = expected.get("@stated by several graphs")
    if several:
        assert len(next(r for r in graphs if r[0] == several)[2].split(", ")) >= 2, graphs
    driver.find_element(By.ID, "pick-graphs").click()
    assert all(len(r) == 2 for r in fact_rows(driver))


def search(driver: Any, label: str) -> None:
    field = driver.find_element(By.ID, "cell-component")
    field.clear()
    field.send_keys(label)
    driver.find_element(By.ID, "cell-show").click()


def highlighted(driver: Any) -> str:
    return str(driver.find_element(By.ID, "cell-view").get_attribute("data-highlighted") or "")
