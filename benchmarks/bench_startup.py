"""Start-up: ``import cadkg`` and one ``cadkg call``, each against importing what cadkg stands on.

Every figure is a fresh process, timed from the outside (wall time, start to exit). The
baseline is ``python -c "import pyoxigraph, click"``, the two libraries every command needs,
measured in the same run and interleaved with the others so that a busy machine weighs on
every row alike. Rows, each the median of ``--runs`` processes with the lowest and highest,
and its ratio to the baseline's median:

- ``import cadkg``: ``python -c "import cadkg"``;
- ``cadkg --help``;
- ``cadkg kinds``: every reader's kind listed (the registry loaded, no reader imported);
- ``cadkg call``: ``cadkg call STORE cad_service label=F1500.1`` on a store built once from
  ``examples/iema-switchgear/manifest.toml``.

Targets: ``import cadkg`` at most 3×, ``cadkg call`` at most 6× the baseline.

Usage::

    python benchmarks/bench_startup.py [--runs 7]
"""

from __future__ import annotations

import argparse
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from medians import median, spread, verdict

ROOT = Path(__file__).resolve().parent.parent
MANIFEST = ROOT / "examples" / "iema-switchgear" / "manifest.toml"
# What the ratios are to: the libraries any cadkg command imports, and nothing of cadkg.
BASELINE = "baseline: import pyoxigraph, click"
TARGETS = {"import cadkg": 3.0, "cadkg call": 6.0}


def commands(store: Path) -> dict[str, list[str]]:
    python = [sys.executable]
    cli = [*python, "-m", "cadkg.cli"]
    return {
        BASELINE: [*python, "-c", "import pyoxigraph, click"],
        "import cadkg": [*python, "-c", "import cadkg"],
        "cadkg --help": [*cli, "--help"],
        "cadkg kinds": [*cli, "kinds"],
        "cadkg call": [*cli, "call", str(store), "cad_service", "label=F1500.1"],
    }


def seconds(command: list[str]) -> float:
    start = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    return time.perf_counter() - start


def measure(runs: int, store: Path) -> dict[str, list[float]]:
    table = commands(store)
    for command in table.values():  # once each, unmeasured: the file cache warm for every row alike
        seconds(command)
    times: dict[str, list[float]] = {name: [] for name in table}
    for _ in range(runs):
        for name, command in table.items():
            times[name].append(seconds(command))
    return times


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    parser.add_argument("--runs", type=int, default=7, help="fresh processes per row (median)")
    args = parser.parse_args()
    import pyoxigraph

    print(
        f"Python {platform.python_version()}, pyoxigraph {pyoxigraph.__version__}, "
        f"median (lowest–highest) of {args.runs} fresh processes per row\n"
    )
    with tempfile.TemporaryDirectory(prefix="cadkg-startup-") as tmp:
        store = Path(tmp) / "store"
        build = [sys.executable, "-m", "cadkg.cli", "build", str(MANIFEST), "--store", str(store)]
        subprocess.run(build, check=True, capture_output=True)
        times = measure(args.runs, store)
    base = median(times[BASELINE])
    print("| command | s | ratio to the baseline | target | |")
    print("|---|---:|---:|---:|---|")
    for name, values in times.items():
        ratios = [value / base for value in values]
        target = TARGETS.get(name)
        goal = f"≤ {target:g}×" if target is not None else ""
        met = verdict(ratios, target, at_most=True) if target is not None else ""
        print(f"| {name} | {spread(values, 3)} | {spread(ratios, 1, '×')} | {goal} | {met} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
