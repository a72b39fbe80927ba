"""``cadkg plan``: make the robot's task list of a cell, store it, and print it (docs/plan.md)."""

from __future__ import annotations

import csv
import importlib.util
import io
import json
import sys
from pathlib import Path

import click
from rich.table import Table

from cadkg.cli.common import err, format_option, guarded, open_local, out, store_or_manifest
from cadkg.graph import KnowledgeGraph

__all__ = ["plan"]


@click.command()
@store_or_manifest()
@click.option(
    "--rules",
    type=click.Path(exists=True, dir_okay=False, path_type=Path),
    default=None,
    help="The robot's rules (TOML); default: the manifest's [plan] rules, else the use case's.",
)
@format_option(["table", "csv", "json", "ttl"])
@click.option(
    "-o", "--output", type=click.Path(dir_okay=False, allow_dash=True), default="-", help="A file, or -."
)
@click.option(
    "--explain",
    "task",
    metavar="TASK",
    default=None,
    help="Say why TASK (wire number, op3 ...) is where it is.",
)
@click.option(
    "--solve",
    "budget",
    type=click.FloatRange(min=0),
    default=0.0,
    metavar="SECONDS",
    help="Improve the order with OR-Tools CP-SAT for this much of its deterministic time "
    "(pip install 'cadkg[solver]').",
)
@click.option(
    "--balance/--no-balance",
    default=None,
    help="Move robot's tasks to a person while that shortens the makespan "
    "(default: the rules' [time] balance).",
)
@guarded
def plan(
    target: str,
    rules: Path | None,
    fmt: str,
    output: str,
    task: str | None,
    budget: float,
    balance: bool | None,
) -> None:
    """Make (or refresh) the robot's task list of a cell and print it.

    A store keeps it as the named graph {base}plan, which the cursor services follow; a
    manifest is built in memory and its plan printed. The summary goes to stderr.
    """
    from cadkg.plan.cell import store_plan
    from cadkg.plan.graph import plan_graph
    from cadkg.plan.progress import read_progress, statuses
    from cadkg.plan.report import CSV_COLUMNS, as_json, explain, rows, summary

    if budget > 0 and importlib.util.find_spec("ortools") is None:
        raise click.UsageError("--solve needs OR-Tools: pip install 'cadkg[solver]'")
    kg = open_local(target, writable=True)
    try:
        stored = store_plan(kg, rules, budget, balance)
        err.print(summary(stored), markup=False)
        if task is not None:
            text = explain(stored, task)
            if text is None:
                err.print(f"cadkg: no task {task!r} in the plan (a wire number, an operation label or key)")
                sys.exit(2)
            out.print(text, markup=False)
            return
        if fmt == "ttl":
            text = kg.serialize("ttl", graphs=[plan_graph(_base(kg))]).decode("utf-8").rstrip("\n")
        elif fmt == "json":
            status = statuses(stored, read_progress(kg))
            text = json.dumps(as_json(stored, status), indent=1, ensure_ascii=False)
        elif fmt == "csv":
            buffer = io.StringIO()
            writer = csv.writer(buffer, lineterminator="\n")
            writer.writerow(CSV_COLUMNS)
            writer.writerows(rows(stored))
            text = buffer.getvalue().rstrip("\n")
        else:
            table = Table(*CSV_COLUMNS)
            for row in rows(stored):
                table.add_row(*row)
            if output == "-":
                out.print(table)
                return
            text = _render(table)
        _write(output, text)
    finally:
        kg.close()


def _base(kg: KnowledgeGraph) -> str:
    from cadkg.plan.cell import cell_base

    return cell_base(kg)


def _render(table: Table) -> str:
    from rich.console import Console

    console = Console(file=io.StringIO(), width=240, highlight=False)
    console.print(table)
    return str(console.file.getvalue()).rstrip("\n")  # type: ignore[attr-defined]


def _write(output: str, text: str) -> None:
    if output == "-":
        sys.stdout.write(text + "\n")
        sys.stdout.flush()
        return
    Path(output).write_text(text + "\n", encoding="utf-8")
