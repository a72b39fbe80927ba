"""Headless Chromium for the page's end-to-end tests: Debian's ``chromium`` and ``chromedriver``
driven by Selenium, WebGL drawn by SwiftShader (on the CPU, the same on every machine).

Chromedriver and the browser run in a process group of their own, killed as a whole when the
session ends or after :data:`CAP_SECONDS` (generous: the tests take about a minute). Each page
records the Content-Security-Policy violations it meets, so a test can assert there are none.
"""

from __future__ import annotations

import contextlib
import io
import os
import signal
import subprocess
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from tests.conftest import ROOT

SETUP = ROOT / "scripts" / "browser-setup.sh"
GOLDEN = Path(__file__).resolve().parent / "golden"
CANNOT_INSTALL = ("needs apt-get", "needs root", "apt-get update", "apt-get install")
CAP_SECONDS = 900
WIDTH, HEIGHT = 1400, 1000
CHROMIUM_ARGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--force-device-scale-factor=1",
    "--font-render-hinting=none",
    f"--window-size={WIDTH},{HEIGHT}",
)
# Kept per page from its first script on: what the Content-Security-Policy refused.
_RECORD_CSP = """
window.__cspViolations = [];
document.addEventListener("securitypolicyviolation", (e) =>
  window.__cspViolations.push(`${e.violatedDirective} ${e.blockedURI} ${e.sourceFile}:${e.lineNumber}`));
"""


@contextlib.contextmanager
def chromium(downloads: Path) -> Iterator[Any]:
    """A headless Chromium session that saves downloads into ``downloads``."""
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
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    service = Service(executable_path="/usr/bin/chromedriver", popen_kw={"start_new_session": True})
    driver = webdriver.Chrome(service=service, options=options)
    group = service.process.pid

    def kill() -> None:
        with contextlib.suppress(ProcessLookupError):
            os.killpg(group, signal.SIGKILL)

    cap = threading.Timer(CAP_SECONDS, kill)
    cap.daemon = True
    cap.start()
    try:
        driver.execute_cdp_cmd("Page.addScriptToEvaluateOnNewDocument", {"source": _RECORD_CSP})
        driver.execute_cdp_cmd(
            "Browser.setDownloadBehavior", {"behavior": "allow", "downloadPath": str(downloads)}
        )
        yield driver
    finally:
        cap.cancel()
        with contextlib.suppress(Exception):
            driver.quit()
        kill()


def wait(driver: Any, condition: Any, seconds: float = 60, message: str = "") -> Any:
    from selenium.webdriver.support.ui import WebDriverWait

    return WebDriverWait(driver, seconds, poll_frequency=0.1).until(condition, message)


def open_page(driver: Any, url: str) -> None:
    """Load the page and wait until it has read the endpoint (info, terms, named queries)."""
    driver.get(url)
    wait(driver, lambda d: d.execute_script("return document.body.dataset.ready") == "true", 60, "page ready")


def editor_text(driver: Any) -> str:
    text: str = driver.execute_script(
        "return document.getElementById('query').editorView.state.doc.toString()"
    )
    return text


def set_editor(driver: Any, text: str) -> None:
    """Replace the editor's text (as a paste would)."""
    driver.execute_script(
        "const v = document.getElementById('query').editorView;"
        "v.dispatch({changes: {from: 0, to: v.state.doc.length, insert: arguments[0]}})",
        text,
    )


def editor(driver: Any) -> Any:
    from selenium.webdriver.common.by import By

    return driver.find_element(By.ID, "query").shadow_root.find_element(By.CSS_SELECTOR, ".cm-content")


def keys(driver: Any, *typed: str) -> None:
    """Type into the element that has the focus (the editor keeps its caret: no refocusing)."""
    from selenium.webdriver.common.action_chains import ActionChains

    ActionChains(driver).send_keys(*typed).perform()


def chord(driver: Any, modifier: str, key: str) -> None:
    from selenium.webdriver.common.action_chains import ActionChains

    ActionChains(driver).key_down(modifier).send_keys(key).key_up(modifier).perform()


def text_of(driver: Any, element_id: str) -> str:
    from selenium.webdriver.common.by import By

    return str(driver.find_element(By.ID, element_id).text)


def column(driver: Any, index: int) -> list[str]:
    from selenium.webdriver.common.by import By

    cells = driver.find_elements(By.CSS_SELECTOR, f"#results tbody tr td:nth-child({index})")
    return [str(td.get_attribute("textContent")) for td in cells]


def health(driver: Any, base: str) -> list[str]:
    """What went wrong on the page: CSP violations, console errors, requests to elsewhere."""
    problems = [f"CSP: {v}" for v in driver.execute_script("return window.__cspViolations || []")]
    for entry in driver.get_log("browser"):
        if entry["level"] == "SEVERE":
            problems.append(f"console: {entry['message'][:300]}")
    resources = driver.execute_script("return performance.getEntriesByType('resource').map(r => r.name)")
    problems += [
        f"request elsewhere: {r}" for r in resources if not r.startswith(base) and not r.startswith("blob:")
    ]
    return problems


def settled(driver: Any, element_id: str = "cell-view", quiet: float = 0.4, seconds: float = 60) -> None:
    """Wait until the 3D view has drawn and then drawn nothing more for ``quiet`` seconds."""
    script = f"return document.getElementById('{element_id}').dataset.frames || ''"
    deadline = time.monotonic() + seconds
    last, since = None, time.monotonic()
    while time.monotonic() < deadline:
        frames = driver.execute_script(script)
        if frames != last:
            last, since = frames, time.monotonic()
        elif frames and time.monotonic() - since >= quiet:
            return
        time.sleep(0.05)
    raise AssertionError(f"the 3D view #{element_id} did not settle in {seconds} s")


def compare_with_golden(png: bytes, name: str, out: Path, tolerance: float = 0.04) -> None:
    """Compare a screenshot with ``golden/<name>.png``: at most ``tolerance`` of its pixels may
    differ by more than 48 (of 255) in a channel, and the mean difference must stay under 6.

    ``CADKG_UPDATE_GOLDEN=1`` writes the golden instead. A failure saves the actual picture
    next to the test's temporary files and names it.
    """
    from PIL import Image, ImageChops

    golden = GOLDEN / f"{name}.png"
    actual = Image.open(io.BytesIO(png)).convert("RGB")
    if os.environ.get("CADKG_UPDATE_GOLDEN") == "1":
        GOLDEN.mkdir(exist_ok=True)
        actual.save(golden, optimize=True)
        return
    saved = out / f"{name}.actual.png"
    actual.save(saved)
    assert golden.is_file(), f"no golden {golden}; look at {saved} and run with CADKG_UPDATE_GOLDEN=1"
    expected = Image.open(golden).convert("RGB")
    assert actual.size == expected.size, f"{name}: size {actual.size} != golden {expected.size} ({saved})"
    difference = ImageChops.difference(actual, expected)
    channels = difference.split()
    histogram = [sum(c.histogram()[k] for c in channels) for k in range(256)]
    total = actual.size[0] * actual.size[1] * 3
    far = sum(histogram[49:]) / total
    mean = sum(k * n for k, n in enumerate(histogram)) / total
    assert far <= tolerance and mean < 6, (
        f"{name}: {far:.1%} of the pixels differ from the golden (mean difference {mean:.1f}); see {saved}"
    )
