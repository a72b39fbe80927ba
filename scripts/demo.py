"""The main job on the bundled examples, told briefly (run by scripts/demo.sh).

Each use case gets a short section: the store built from its example cell and what it holds,
one named query's table, one service answer in a compact form, and the validation summary.
Every step is the ``cadkg`` command a user would type, shown before its answer; ``--verbose``
prints each command's whole output instead of the summary. Any command that fails ends the
demo with its own message and a non-zero status.
"""

from __future__ import annotations

import argparse
import json
import shlex
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
CADKG = ROOT / ".venv" / "bin" / "cadkg"
WIDTH = 92
TABLE_ROWS = 6
ANSWER_LINES = 12
CK = "https://w3id.org/cadkg#"
CLASS_COUNTS = (
    "SELECT ?c (COUNT(DISTINCT ?s) AS ?n) WHERE { ?s a ?c FILTER(STRSTARTS(STR(?c), STR(ck:))) } GROUP BY ?c"
)


@dataclass(frozen=True)
class Step:
    """One command of a section; ``args`` follow ``cadkg``, with STORE for the section's store."""

    title: str
    args: tuple[str, ...]
    show: str  # "table": a query's rows; "answer": a service's JSON; "file": a written file


@dataclass(frozen=True)
class Section:
    title: str
    manifest: str
    store: str
    counted: tuple[str, ...]  # the ontology classes named in the one-line summary
    steps: tuple[Step, ...] = field(default=())


SECTIONS = (
    Section(
        "IEMA switchgear cabinet (D3.1 section 4.1)",
        "examples/iema-switchgear/manifest.toml",
        "build/iema-store",
        ("Component", "Wire", "Pin", "Duct", "Rail", "TerminalBlock"),
        (
            Step(
                "the wires at fuse F1500.1",
                ("query", "STORE", "wires-of-component", "label=F1500.1"),
                "table",
            ),
            Step(
                "where the robot finds F1500.1", ("call", "STORE", "cad_service", "label=F1500.1"), "answer"
            ),
            Step("the next wire for the robot", ("call", "STORE", "group_connection_provider"), "answer"),
        ),
    ),
    Section(
        "ELVEZ harness assembly on jigs and guides (D3.1 section 4.3)",
        "examples/elvez-cell/manifest.toml",
        "build/elvez-store",
        ("Platform", "Element", "Harness", "Cable", "Connector", "Operation", "Tool"),
        (
            Step("the assembly sequence", ("query", "STORE", "elvez-plan"), "table"),
            Step(
                "guide J1's frames in the robot base frame",
                ("call", "STORE", "guide_info", "name=J1"),
                "answer",
            ),
        ),
    ),
    Section(
        "ELIMCO aeronautic harness on a pin bench (D3.1 section 4.2)",
        "examples/elimco-bench/manifest.toml",
        "build/elimco-store",
        ("BenchPin", "Cable", "Wire", "Connector", "RoutePath"),
        (
            Step(
                "the route of cable A4351-1677",
                ("query", "STORE", "elimco-route", "cable=A4351-1677"),
                "table",
            ),
            Step(
                "its pin poses around the pins' centroid",
                ("call", "STORE", "get_path_positions", "cable=A4351-1677"),
                "answer",
            ),
        ),
    ),
    Section(
        "Volkswagen wire harness for a detection system (D3.1 section 4.4)",
        "examples/vw-harness/manifest.toml",
        "build/vw-store",
        ("Harness", "Connector", "HarnessNode", "Segment", "Wire"),
        (
            Step(
                "the segments of DOOR-L",
                ("query", "STORE", "harness-segment-lengths", "harness=DOOR-L"),
                "table",
            ),
            Step(
                "its topology as GraphML",
                (
                    "export",
                    "STORE",
                    "--format",
                    "graphml",
                    "--view",
                    "topology",
                    "--harness",
                    "DOOR-L",
                    "-o",
                    "build/door-l.graphml",
                ),
                "file",
            ),
        ),
    ),
    Section(
        "ENKI hose handling (D3.1 section 4.5)",
        "examples/enki-hose/manifest.toml",
        "build/enki-store",
        ("Hose",),
        (Step("the hose in hand", ("call", "STORE", "hose_info", "product=HX-25"), "answer"),),
    ),
)

NEXT = (
    ("source .venv/bin/activate", "puts cadkg on the PATH"),
    ("cadkg serve build/iema-store", "the workbench and SPARQL endpoint at http://127.0.0.1:7878/"),
    ("cadkg queries", "the named queries and their parameters"),
    ("cadkg services", "the robot planner's services"),
    ('cadkg query build/iema-store "SELECT ?n WHERE { ?w a ck:Wire ; ck:wireNumber ?n } LIMIT 5"', "SPARQL"),
    ("cadkg validate examples/bad-cell/manifest.toml", "what a broken cell's findings look like"),
)


class DemoError(Exception):
    """A command ended with an unexpected status; its message is the command's own."""


def run(args: list[str], verbose: bool, shown: list[str] | None = None) -> subprocess.CompletedProcess[str]:
    """``cadkg ARGS`` from the checkout, shown as ``shown`` (what a user types for the same
    answer; nothing when empty); a non-zero exit ends the demo."""
    shown = args if shown is None else shown
    if shown:
        print(f"  $ cadkg {shlex.join(shown)}")
    done = subprocess.run([str(CADKG), *args], cwd=ROOT, capture_output=True, text=True, check=False)
    if verbose:
        for stream in (done.stdout, done.stderr):
            if stream.strip():
                print(_indent(stream.rstrip(), 4))
    if done.returncode != 0:
        raise DemoError(f"'cadkg {shlex.join(args)}' exited {done.returncode}:\n{done.stderr.strip()}")
    return done


def _indent(text: str, by: int) -> str:
    return "\n".join(" " * by + line for line in text.splitlines())


def _number(value: Any) -> str:
    """A scalar as JSON writes it, floats to four significant digits."""
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, str):
        return value or '""'
    return json.dumps(value)


def _clip(text: str, width: int) -> str:
    return text if len(text) <= width else text[: width - 1] + "…"


def compact(value: Any) -> str:
    """One line for a value of a service answer: poses and vectors as tuples, lists counted."""
    if isinstance(value, dict):
        keys = set(value)
        if keys == {"position", "orientation"}:
            p, q = value["position"], value["orientation"]
            return f"xyz {compact(p)} quat {compact(q)}"
        if keys and keys <= {"x", "y", "z", "w"}:
            return "(" + ", ".join(_number(value[k]) for k in "xyzw" if k in value) + ")"
        return "{" + ", ".join(f"{k}: {compact(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list):
        if all(not isinstance(v, dict | list) for v in value):
            return "[" + ", ".join(_number(v) for v in value) + "]"
        return f"{len(value)} items, first {compact(value[0])}"
    return _number(value)


def show_answer(stdout: str) -> None:
    answer = json.loads(stdout)
    lines = [f"{key}: {compact(value)}" for key, value in answer.items()]
    for line in lines[:ANSWER_LINES]:
        print("    " + _clip(line, WIDTH - 4))
    if len(lines) > ANSWER_LINES:
        print(f"    … {len(lines) - ANSWER_LINES} more fields (--verbose shows the whole answer)")


def show_table(stdout: str) -> None:
    result = json.loads(stdout)
    columns = [v for v in result["variables"] if not _is_iri_column(result["rows"], v)]
    rows = [[_number(row.get(c, "")) for c in columns] for row in result["rows"]]
    shown = rows[:TABLE_ROWS]
    widths = [max([len(c)] + [len(r[i]) for r in shown]) for i, c in enumerate(columns)]
    for line in [columns, *shown]:
        print(
            "    " + _clip("  ".join(cell.ljust(w) for cell, w in zip(line, widths, strict=True)), WIDTH - 4)
        )
    more = f", {len(rows) - len(shown)} not shown" if len(rows) > len(shown) else ""
    print(f"    ({len(rows)} rows{more})")


def _is_iri_column(rows: list[dict[str, Any]], column: str) -> bool:
    """A column of IRIs says little on a terminal; the labels beside it say it."""
    values = [row[column] for row in rows if column in row]
    return bool(values) and all(isinstance(v, str) and v.startswith(("http://", "https://")) for v in values)


def summary(section: Section, seconds: float, build: subprocess.CompletedProcess[str], verbose: bool) -> None:
    warnings = sum(1 for line in build.stderr.splitlines() if line.startswith("cadkg: warning"))
    size = build.stdout.strip().splitlines()[-1]  # "N triples in M named graphs"
    noted = f", {warnings} warning(s) (--verbose shows them)" if warnings and not verbose else ""
    print(f"    {section.store}: {size}, built in {seconds:.1f} s{noted}")
    counts = run(["query", section.store, CLASS_COUNTS, "--format", "rows-json"], verbose=False, shown=[])
    per_class = {row["c"].removeprefix(CK): int(row["n"]) for row in json.loads(counts.stdout)["rows"]}
    print("    holds " + ", ".join(f"{per_class.get(c, 0)} {c}" for c in section.counted))


def run_section(section: Section, verbose: bool) -> None:
    print(f"\n━━ {section.title} " + "━" * max(3, WIDTH - len(section.title) - 4))
    print("  build the store from the example's files")
    started = time.perf_counter()
    build = run(["build", section.manifest, "--store", section.store], verbose)
    summary(section, time.perf_counter() - started, build, verbose)
    for step in section.steps:
        print(f"  {step.title}")
        typed = [section.store if a == "STORE" else a for a in step.args]
        # The table a user sees is the same rows; the demo reads them as JSON to shorten them.
        args = [*typed, "--format", "rows-json"] if step.show == "table" and not verbose else typed
        done = run(args, verbose, shown=typed)
        if verbose:
            continue
        if step.show == "table":
            show_table(done.stdout)
        elif step.show == "answer":
            show_answer(done.stdout)
        else:
            written = ROOT / args[args.index("-o") + 1]
            print(f"    wrote {written.relative_to(ROOT)} ({written.stat().st_size:,} bytes)")
    print("  check what the files say")
    validated = run(["validate", section.store], verbose)
    if not verbose:
        print("    " + (validated.stderr.strip().splitlines() or ["no findings"])[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--verbose", action="store_true", help="print every command's whole output")
    verbose = parser.parse_args(argv).verbose
    print("cadkg: one knowledge graph per cell, built from the factory's own files")
    try:
        for section in SECTIONS:
            run_section(section, verbose)
    except DemoError as failed:
        print(f"\ndemo: {failed}", file=sys.stderr)
        return 1
    print("\n━━ Where things are " + "━" * (WIDTH - 20))
    for section in SECTIONS:
        print(f"  {section.store:<20} the store of {section.manifest}")
    print(f"  {'build/door-l.graphml':<20} the harness topology for the detection system")
    print("\n  Try next (in this folder):")
    for command, what in NEXT:
        print(f"    {command}\n        {what}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
