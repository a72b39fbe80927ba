"""The ``cadkg`` command line: a thin layer over the Python API.

Exit codes: 0 ok, 1 validation findings, 2 usage or input error. Errors print one
line (file:line: what was found, what was expected); ``--debug`` adds the traceback.
"""

from __future__ import annotations

import csv
import io
import json
import sys
from collections.abc import Callable, Sequence
from datetime import date, datetime
from decimal import Decimal
from functools import wraps
from pathlib import Path
from typing import Any, TypeVar

import click
from rich.console import Console
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from cadkg.errors import CadkgError, QueryError
from cadkg.ingest.manifest import load_manifest
from cadkg.ingest.registry import kinds as registered_kinds
from cadkg.query.named import coerce_params, named_queries
from cadkg.query.validate import validate as run_validation
from cadkg.store import EXPORT_FORMATS, KnowledgeGraph, QueryResult

__all__ = ["main"]

F = TypeVar("F", bound=Callable[..., Any])
_err = Console(stderr=True, highlight=False, soft_wrap=True)
# Piped output is read by scripts and people alike: do not truncate table cells to 80 columns.
_out = Console(highlight=False, soft_wrap=True, width=None if sys.stdout.isatty() else 240)


def _plain(value: Any) -> Any:
    if isinstance(value, Decimal):
        return format(value, "f")
    if isinstance(value, datetime | date):
        return value.isoformat()
    return value


def _guarded(func: F) -> F:
    """Turn cadkg errors into one line on stderr and exit 2; no traceback without --debug."""

    @wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        debug = click.get_current_context().find_root().params.get("debug", False)
        try:
            return func(*args, **kwargs)
        except (CadkgError, OSError, MemoryError) as err:
            if debug:
                raise
            _err.print(f"cadkg: error: {err}", markup=False)
            sys.exit(2)

    return wrapper  # type: ignore[return-value]


def _open(target: str) -> KnowledgeGraph:
    """A store directory is opened read-only; a manifest is built in memory."""
    path = Path(target)
    if path.is_dir():
        return KnowledgeGraph.open(path)
    if path.is_file():
        kg = KnowledgeGraph.build(path)
        for report in kg.reports:
            for warning in report.warnings:
                _err.print(f"cadkg: warning: {warning}", markup=False)
        return kg
    raise click.BadParameter(f"{target!r} is neither a store directory nor a manifest file")


def _params(pairs: Sequence[str]) -> dict[str, str]:
    params = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise click.BadParameter(f"{pair!r}: parameters are written key=value")
        params[key] = value
    return params


def _print_result(result: QueryResult, fmt: str) -> None:
    if fmt == "json":
        rows = [{k: _plain(v) for k, v in row.items()} for row in result.rows]
        _out.print_json(json.dumps({"variables": list(result.variables), "rows": rows}))
    elif fmt == "csv":
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(result.variables)
        for row in result.rows:
            writer.writerow(["" if row[v] is None else _plain(row[v]) for v in result.variables])
        sys.stdout.write(buffer.getvalue())
    else:
        table = Table(*result.variables, show_lines=False)
        for row in result.rows:
            table.add_row(*("" if row[v] is None else str(_plain(row[v])) for v in result.variables))
        _out.print(table)
        _err.print(f"{len(result)} row(s)")


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.option("--debug", is_flag=True, help="Show tracebacks of errors.")
@click.version_option(package_name="cadkg")
def cli(debug: bool) -> None:
    """cadkg: one knowledge graph of a robotic wiring cell, from the factory's own files."""


@cli.command()
@click.argument("manifest", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--store",
    "store_dir",
    required=True,
    type=click.Path(file_okay=False),
    help="Store directory to write (replaced atomically).",
)
@_guarded
def build(manifest: str, store_dir: str) -> None:
    """Read every file of MANIFEST into a store directory."""
    spec = load_manifest(manifest)
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total}"),
        TimeElapsedColumn(),
        console=_err,
        transient=True,
        disable=not _err.is_terminal,
    ) as progress:
        task = progress.add_task("reading", total=len(spec.sources))

        def advance(source: Any) -> None:
            progress.update(task, description=f"reading {source.rel}")
            progress.advance(task)

        kg = KnowledgeGraph.build(spec, store_dir, on_source=advance)
    table = Table("file", "kind", "records", "triples", "seconds", title=f"{spec.cell.name} → {store_dir}")
    for report in kg.reports:
        table.add_row(
            report.rel_path, report.kind, str(report.records), str(report.triples), f"{report.seconds:.3f}"
        )
    _out.print(table)
    for report in kg.reports:
        for warning in report.warnings:
            _err.print(f"cadkg: warning: {warning}", markup=False)
    _out.print(f"{len(kg)} triples in {len(kg.named_graphs())} named graphs")
    kg.close()


@cli.command()
@click.argument("target", metavar="STORE_OR_MANIFEST")
@click.argument("query", metavar="QUERY_OR_FILE")
@click.argument("params", nargs=-1, metavar="[KEY=VALUE]...")
@click.option(
    "--format", "fmt", type=click.Choice(["table", "csv", "json"]), default="table", show_default=True
)
@_guarded
def query(target: str, query: str, params: tuple[str, ...], fmt: str) -> None:
    """Run a named query, a .rq file or SPARQL text; KEY=VALUE binds parameters."""
    bindings = _params(params)
    kg = _open(target)
    known = named_queries()
    if query in known:
        result = kg.query(known[query].text, **coerce_params(known[query], bindings))
    else:
        path = Path(query)
        text = path.read_text(encoding="utf-8") if path.suffix == ".rq" and path.is_file() else query
        if text is query and not any(
            word in query.upper() for word in ("SELECT", "ASK", "CONSTRUCT", "DESCRIBE")
        ):
            raise QueryError(
                f"{query!r} is not a named query, a .rq file or SPARQL; named: {', '.join(known)}"
            )
        result = kg.query(text, **bindings)
    _print_result(result, fmt)


@cli.command()
def queries() -> None:
    """List the named queries and their parameters."""
    table = Table("name", "parameters", "answers")
    for named in named_queries().values():
        params = ", ".join(f"{p.name} ({p.type})" for p in named.params)
        table.add_row(named.name, params, named.description)
    _out.print(table)


@cli.command()
@click.argument("target", metavar="STORE_OR_MANIFEST")
@click.option("--no-shacl", is_flag=True, help="Skip the SHACL shapes (semantic checks only).")
@click.option("--strict", is_flag=True, help="Warnings count as findings for the exit code.")
@_guarded
def validate(target: str, no_shacl: bool, strict: bool) -> None:
    """Check the graph: SHACL shapes, unknown labels, duplicate wire numbers, pins without data."""
    findings = run_validation(_open(target), shacl=not no_shacl)
    for finding in findings:
        _out.print(str(finding), markup=False)
    errors = sum(1 for f in findings if f.severity == "error")
    warnings_ = len(findings) - errors
    _err.print(f"{errors} error(s), {warnings_} warning(s)")
    if errors or (strict and warnings_):
        sys.exit(1)


@cli.command()
@click.argument("target", metavar="STORE_OR_MANIFEST")
@click.option(
    "--format",
    "fmt",
    type=click.Choice([*EXPORT_FORMATS, "graphml"]),
    default=None,
    help="Default: from the output suffix.",
)
@click.option("-o", "--output", required=True, type=click.Path(dir_okay=False))
@_guarded
def export(target: str, fmt: str | None, output: str) -> None:
    """Write the graph as Turtle, N-Triples, N-Quads, TriG, JSON-LD or GraphML."""
    fmt = fmt or Path(output).suffix.lstrip(".").lower()
    if fmt not in (*EXPORT_FORMATS, "graphml"):
        raise click.BadParameter(f"cannot tell the format from {output!r}; give --format")
    _open(target).export(output, fmt)
    _err.print(f"wrote {output}")


def _cursor_file(target: str) -> Path | None:
    path = Path(target)
    return path / "cursors.json" if path.is_dir() else None


@cli.command(name="call")
@click.argument("target", metavar="STORE_OR_MANIFEST")
@click.argument("service", metavar="SERVICE")
@click.argument("params", nargs=-1, metavar="[KEY=VALUE]...")
@click.option("--client", default="default", show_default=True, help="Cursor owner for the cursor services.")
@_guarded
def call_service(target: str, service: str, params: tuple[str, ...], client: str) -> None:
    """Call a service (see 'cadkg services') and print its result as JSON.

    Cursors (connection providers, rail scanner) are kept per client in STORE/cursors.json,
    so successive calls walk the list; a rebuilt store starts them afresh.
    """
    from cadkg.query.cursors import Session
    from cadkg.query.services import call, to_jsonable

    kg = _open(target)
    session = Session(kg.cell_model(), kg=kg)
    state_file = _cursor_file(target)
    generation = kg.generation
    if state_file is not None and state_file.is_file():
        try:
            saved = json.loads(state_file.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            saved = {}
        if isinstance(saved, dict) and saved.get("generation") == generation:
            session.load(saved.get("clients", {}))
    result = call(session, service, _params(params), client=client)
    if state_file is not None:
        state = {"generation": generation, "clients": session.dump()}
        temporary = state_file.with_suffix(".tmp")
        temporary.write_text(json.dumps(state, indent=1), encoding="utf-8")
        temporary.replace(state_file)
    _out.print_json(json.dumps(to_jsonable(result)))


@cli.command(name="services")
def list_services() -> None:
    """List the services 'cadkg call' and the ROS adapter serve."""
    from cadkg.query.services import SERVICES

    table = Table("profile", "service", "parameters", "answers")
    for service in sorted(SERVICES.values(), key=lambda s: s.profile):
        params = ", ".join(
            f"{k} ({t.__name__.lower()}{', optional' if k in service.optional else ''})"
            for k, t in service.params.items()
        )
        table.add_row(service.profile, service.name, params, service.description)
    _out.print(table)


@cli.command()
@click.argument("store_dir", metavar="STORE", type=click.Path(exists=True, file_okay=False))
@click.argument("kind", type=click.Choice(["wire", "component", "operation"]))
@click.argument("ident", metavar="ID")
@click.argument("performer", type=click.Choice(["robot", "human"]))
@_guarded
def assign(store_dir: str, kind: str, ident: str, performer: str) -> None:
    """Assign a wire (number), component (label) or operation (list position) to robot or human.

    The choice is kept in its own named graph, so rebuilding the store keeps it.
    """
    with KnowledgeGraph.open(store_dir, read_only=False) as kg:
        target = kg.assign(kind, ident, performer)
    _err.print(f"{kind} {ident} → {performer} ({target})")


@cli.command()
def kinds() -> None:
    """List the input file kinds cadkg reads."""
    table = Table("kind", "suffixes", "format")
    for reader in registered_kinds():
        table.add_row(reader.kind, " ".join(reader.suffixes), reader.description)
    _out.print(table)


def _ros_python() -> str | None:
    """The Python that has rclpy: $CADKG_ROS_PYTHON, else the checkout's .venv-ros (scripts/ros-setup.sh)."""
    import os

    configured = os.environ.get("CADKG_ROS_PYTHON")
    if configured:
        return configured
    candidate = Path(__file__).resolve().parents[2] / ".venv-ros" / "bin" / "python"
    return str(candidate) if candidate.exists() else None


@cli.command(name="ros", context_settings={"ignore_unknown_options": True})
@click.argument("source", metavar="STORE_OR_MANIFEST", type=click.Path(exists=True))
@click.option("--profile", default=None, help="Profile (default: the cell's).")
@click.option("--namespace", default=None, help="Service namespace (default /gearbox_handler for iema).")
@click.option("--approach-distance", type=float, default=None, help="Override the manifest's value (m).")
@click.argument("ros_args", nargs=-1, type=click.UNPROCESSED)
def ros(
    source: str,
    profile: str | None,
    namespace: str | None,
    approach_distance: float | None,
    ros_args: tuple[str, ...],
) -> None:
    """Serve a cell to ROS 2 (needs rclpy: runs in .venv-ros, see docs/ros.md)."""
    import importlib.util
    import os

    args = [str(Path(source).resolve())]
    for flag, value in (
        ("--profile", profile),
        ("--namespace", namespace),
        ("--approach-distance", approach_distance),
    ):
        if value is not None:
            args += [flag, str(value)]
    args += list(ros_args)
    if importlib.util.find_spec("rclpy") is not None:
        from cadkg.ros_adapter.node import main as ros_main

        sys.exit(ros_main(args))
    python = _ros_python()
    if python is None:
        _err.print(
            "cadkg: error: no rclpy here and no .venv-ros; run scripts/ros-setup.sh first", markup=False
        )
        sys.exit(2)
    os.execv(python, [python, "-m", "cadkg.ros_adapter", *args])


def main(argv: Sequence[str] | None = None) -> None:
    """Entry point of the ``cadkg`` command."""
    try:
        cli.main(args=list(argv) if argv is not None else None, prog_name="cadkg", standalone_mode=True)
    except KeyboardInterrupt:
        _err.print("cadkg: interrupted")
        sys.exit(130)


if __name__ == "__main__":
    main()
