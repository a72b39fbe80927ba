"""The web page on a large cabinet, in headless Chromium (WebGL on the CPU by SwiftShader).

A complete synthetic cabinet (``synthetic.write_cabinet``: WRI, models, terminal schema, X3D
scene with a mesh per item, connection list) is built into a store, served by ``cadkg serve``
in a subprocess, and opened in headless Chromium (``tests/server/browser.py``), fresh for each
run:

1. **scene**: ``GET /api/scene``: the first request computes it (seconds), the next is the
   answer cache's; its size in MB;
2. **3D view**: from opening the view to the scene read, the objects built and every mesh
   drawn; then per frame the median milliseconds of 30 frames while the camera turns around
   the cell (each frame waited for), and of frames as drawn while the camera is dragged (the
   wires left out, on a cell whose frames take over 40 ms), the draw calls and triangles of a
   frame, and the median
   milliseconds of a pick (a ray through the view, as a click casts). Three ways of drawing
   the objects in the same run: merged into a few large geometries (the page's way),
   instanced (one InstancedMesh per distinct mesh file, ``?drawing=instanced``), and the
   baseline, one three.js mesh per object (``?drawing=meshes``);
3. **results**: ``SELECT ?s ?p ?o WHERE { ?s ?p ?o } LIMIT 10000`` from Run to the table drawn
   (two animation frames after the status says so), paged at 100 rows, against the same
   table with all 10,000 rows in the page (what the page did before paging).

Figures are medians of ``--runs`` page loads with their spread (min–max). Nothing is asserted.

Usage::

    python benchmarks/bench_page.py [--wires 10000] [--runs 3] [--store DIR]
    python benchmarks/bench_page.py --quick     # a smoke test (its settings: --help)
"""

from __future__ import annotations

import argparse
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

import httpx

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))

import synthetic  # noqa: E402
from quick import add_quick, parse  # noqa: E402
from tests.server.browser import chromium, open_page, settled, wait  # noqa: E402
from tests.server.serving import cadkg_serve  # noqa: E402

ROWS = "SELECT ?s ?p ?o WHERE { ?s ?p ?o } LIMIT 10000"
# Run the query; resolve with the milliseconds until the table is drawn.
_TIME_RUN = """
const [pageSize, done] = [arguments[0], arguments[arguments.length - 1]];
const select = document.getElementById("page-size");
if (![...select.options].some((o) => o.value === pageSize)) select.add(new Option(pageSize, pageSize));
select.value = pageSize;
const view = document.getElementById("query").editorView;
view.dispatch({changes: {from: 0, to: view.state.doc.length, insert: arguments[1]}});
const status = document.getElementById("status");
status.textContent = "";
const start = performance.now();
new MutationObserver((_, observer) => {
  if (!status.textContent.includes("row(s)")) return;
  observer.disconnect();
  requestAnimationFrame(() => requestAnimationFrame(() =>
    done({ms: performance.now() - start, rows: document.querySelectorAll("#results tbody tr").length})));
}).observe(status, {childList: true, characterData: true, subtree: true});
document.getElementById("run").click();
"""


def spread(values: Sequence[float], digits: int = 0) -> str:
    median = statistics.median(values)
    if len(values) == 1:
        return f"{median:.{digits}f}"
    return f"{median:.{digits}f} ({min(values):.{digits}f}–{max(values):.{digits}f})"


def build_store(wires: int, directory: Path) -> Path:
    manifest = synthetic.write_cabinet(directory / "cell", wires)
    store = directory / "store"
    started = time.perf_counter()
    subprocess.run(
        [sys.executable, "-m", "cadkg.cli", "build", str(manifest), "--store", str(store)],
        check=True, cwd=ROOT, capture_output=True, timeout=3600,
    )  # fmt: skip
    print(f"built {wires:,}-wire cabinet into {store} in {time.perf_counter() - started:.1f} s")
    return store


def open_view(driver: Any, url: str) -> dict[str, Any]:
    open_page(driver, url)
    driver.find_element("id", "view-3d").click()
    ready = "return document.getElementById('cell-view').dataset.ready"
    wait(driver, lambda d: d.execute_script(ready) == "true", 600, "the 3D view")
    settled(driver, quiet=0.5, seconds=600)
    view = "document.getElementById('cell-view').cellView"
    timings: dict[str, Any] = driver.execute_script(f"return {view}.timings")
    timings["frame"] = driver.execute_script(f"return {view}.measure(30)")
    timings["pick"] = driver.execute_script(f"return {view}.measurePick(20)")
    timings["status"] = driver.find_element("id", "cell-status").text
    return timings


def time_table(driver: Any, url: str, page_size: str) -> dict[str, Any]:
    open_page(driver, url)
    driver.set_script_timeout(300)
    result: dict[str, Any] = driver.execute_async_script(_TIME_RUN, page_size, ROWS)
    return result


def measure(base: str, runs: int, downloads: Path) -> None:
    started = time.perf_counter()
    first = httpx.get(f"{base}/api/scene", timeout=600)
    computed = time.perf_counter() - started
    started = time.perf_counter()
    httpx.get(f"{base}/api/scene", timeout=600)
    cached = time.perf_counter() - started
    scene = first.json()
    print(
        f"\n/api/scene: computed in {computed:.2f} s, then from the cache in {cached * 1000:.0f} ms; "
        f"{len(first.content) / 1e6:.1f} MB: {len(scene['objects']):,} objects, {len(scene['meshes']):,} "
        f"distinct meshes, {len(scene['routes']):,} wires, {len(scene['frames']):,} frames"
    )
    drawings = {"merged": "", "instanced": "?drawing=instanced", "one mesh per object": "?drawing=meshes"}
    views: dict[str, list[dict[str, Any]]] = {name: [] for name in drawings}
    tables: dict[str, list[dict[str, Any]]] = {"paged (100 rows)": [], "all rows in the page": []}
    with chromium(downloads) as driver:
        for _ in range(runs):
            for name, query in drawings.items():
                views[name].append(open_view(driver, f"{base}/{query}"))
            tables["paged (100 rows)"].append(time_table(driver, f"{base}/", "100"))
            tables["all rows in the page"].append(time_table(driver, f"{base}/", "10000"))
    print(f"\n3D view ({runs} run(s); median (min–max)):\n")
    print("| drawing | scene read (ms) | built (ms) | meshes in (ms) | frame (ms) ", end="")
    print("| frame, moving (ms) | draw calls | triangles | pick (ms) |")
    print("|---|---|---|---|---|---|---|---|---|")
    frames: dict[str, float] = {}
    for name, results in views.items():
        pick: Callable[[str], list[float]] = lambda key, rs=results: [float(r[key]) for r in rs]  # noqa: E731
        frame = [float(r["frame"]["median"]) for r in results]
        frames[name] = statistics.median(frame)
        print(
            f"| {name} | {spread(pick('scene'))} | {spread(pick('built'))} | {spread(pick('meshes'))} "
            f"| {spread(frame, 1)} | {spread([float(r['frame']['moving']) for r in results], 1)} "
            f"| {results[0]['frame']['calls']:,} | {results[0]['frame']['triangles']:,} "
            f"| {spread([float(r['pick']['median']) for r in results], 2)} |"
        )
    baseline = frames["one mesh per object"]
    ratios = ", ".join(f"{name} {baseline / frames[name]:.1f}×" for name in ("merged", "instanced"))
    print(f"\nframe time of one mesh per object / frame time: {ratios}")
    print(f"\n10,000 rows from Run to the table drawn ({runs} run(s)):\n")
    print("| table | ms | rows in the page |")
    print("|---|---|---|")
    shown: dict[str, float] = {}
    for name, results in tables.items():
        shown[name] = statistics.median(float(r["ms"]) for r in results)
        print(f"| {name} | {spread([float(r['ms']) for r in results])} | {results[0]['rows']:,} |")
    print(f"\nall rows / paged: {shown['all rows in the page'] / shown['paged (100 rows)']:.1f}×")


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wires", type=int, default=10000)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--store", type=Path, help="an existing store to serve instead of building one")
    add_quick(parser, wires=300, runs=1)
    args = parse(parser, argv)
    machine = platform.processor() or platform.machine()
    print(f"machine: {machine}, {os.cpu_count()} cores, Python {platform.python_version()}")
    scratch = Path(tempfile.mkdtemp(prefix="bench-page-"))
    try:
        store = args.store or build_store(args.wires, scratch)
        with cadkg_serve(str(store), wait=600) as base:
            measure(base, args.runs, scratch)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
