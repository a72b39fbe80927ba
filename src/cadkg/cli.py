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
            _err.print(f"cadkg: error: {_one_line(err)}", markup=False)
            sys.exit(2)

    return wrapper  # type: ignore[return-value]


def _one_line(err: BaseException) -> str:
    if isinstance(err, OSError) and err.filename and err.strerror:
        # As the readers' errors: the file first, then what went wrong ("[Errno 2] ..." is noise).
        return f"{err.filename}: {err.strerror}"
    return str(err)


def _store_auth(auth: str | None = None, auth_digest: str | None = None) -> Any:
    """Credentials for a remote store: the command's own, else ``cadkg --auth/--auth-digest``."""
    from cadkg.remote import parse_auth

    if not (auth or auth_digest):
        root = click.get_current_context().find_root().params
        auth, auth_digest = root.get("auth"), root.get("auth_digest")
    if auth_digest:
        return parse_auth(auth_digest, digest=True)
    return parse_auth(auth) if auth else None


def _open(target: str) -> KnowledgeGraph:
    """A store directory is opened read-only; a manifest is built in memory; an http(s) URL is a
    remote SPARQL endpoint (docs/remote.md)."""
    from cadkg.remote import RemoteGraph, is_url

    if is_url(target):
        return RemoteGraph(target, auth=_store_auth())
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
@click.option(
    "--auth", envvar="CADKG_STORE_AUTH", metavar="USER:PASSWORD", help="Basic auth for a store URL."
)
@click.option(
    "--auth-digest",
    envvar="CADKG_STORE_AUTH_DIGEST",
    metavar="USER:PASSWORD",
    help="Digest auth for a store URL.",
)
@click.version_option(package_name="cadkg")
def cli(debug: bool, auth: str | None, auth_digest: str | None) -> None:
    """cadkg: one knowledge graph of a robotic wiring cell, from the factory's own files."""


def _progress() -> Progress:
    """A progress bar on stderr, when stderr is a terminal."""
    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total}"),
        TimeElapsedColumn(),
        console=_err,
        transient=True,
        disable=not _err.is_terminal,
    )


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
    with _progress() as progress:
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
@click.argument("target", metavar="STORE_OR_MANIFEST")
@click.option("--endpoint", required=True, metavar="URL", help="The store's SPARQL (Update) endpoint.")
@click.option("--graph-store", metavar="URL", help="The store's Graph Store Protocol endpoint (if any).")
@click.option(
    "--method", type=click.Choice(["auto", "graph-store", "update"]), default="auto", show_default=True
)
@click.option("--auth", metavar="USER:PASSWORD", help="Basic auth (default: cadkg --auth).")
@click.option("--auth-digest", metavar="USER:PASSWORD", help="Digest auth (Virtuoso's *-auth endpoints).")
@click.option("--batch", type=click.IntRange(min=1), default=None, help="Most triples in one request.")
@_guarded
def push(
    target: str,
    endpoint: str,
    graph_store: str | None,
    method: str,
    auth: str | None,
    auth_digest: str | None,
    batch: int | None,
) -> None:
    """Upload every named graph of a store to an external SPARQL 1.1 store (docs/remote.md)."""
    from cadkg.push import push as push_graphs
    from cadkg.remote import is_url

    if is_url(target):
        raise click.BadParameter("push sends a store directory or a manifest, not a URL")
    kg = _open(target)
    credentials = _store_auth(auth, auth_digest)
    report = push_graphs(kg, endpoint, graph_store=graph_store, auth=credentials, method=method, batch=batch)
    table = Table("graph", "triples", "requests", "seconds", title=f"{report.method} → {report.target}")
    for sent in report.graphs:
        table.add_row(sent.graph, str(sent.triples), str(sent.requests), f"{sent.seconds:.3f}")
    _out.print(table)
    _out.print(f"{report.triples} triples in {len(report.graphs)} named graphs sent")
    for note in report.notes:
        _err.print(f"cadkg: note: {note}", markup=False)


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
    kg = _open(target)
    with _progress() as progress:
        task = progress.add_task("checks", total=3)

        def step(stage: str, done: int, total: int) -> None:
            progress.update(task, description=stage, completed=done, total=total)

        findings = run_validation(kg, shacl=not no_shacl, progress=step)
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
@click.option(
    "--view",
    type=click.Choice(["structure", "topology", "wires"]),
    default=None,
    help="GraphML only: every structural relation (default), or one harness's topology or wires.",
)
@click.option(
    "--harness", default=None, metavar="ID", help="The harness of --view (when the store holds several)."
)
@_guarded
def export(target: str, fmt: str | None, output: str, view: str | None, harness: str | None) -> None:
    """Write the graph as Turtle, N-Triples, N-Quads, TriG, JSON-LD or GraphML."""
    fmt = fmt or Path(output).suffix.lstrip(".").lower()
    if fmt not in (*EXPORT_FORMATS, "graphml"):
        raise click.BadParameter(f"cannot tell the format from {output!r}; give --format")
    if harness is not None and view in (None, "structure"):
        view = "topology"
    if view in ("topology", "wires"):
        from cadkg.query.graphml import write_harness_graphml

        if fmt != "graphml":
            raise click.BadParameter(f"--view {view} writes GraphML, not {fmt}")
        write_harness_graphml(_open(target), output, view, harness)
    else:
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


@cli.command()
@click.argument("target", metavar="STORE_OR_MANIFEST_OR_URL")
@click.option("--host", default="127.0.0.1", show_default=True, help="Address to listen on.")
@click.option("--port", type=click.IntRange(0, 65535), default=7878, show_default=True)
@click.option(
    "--allow-non-loopback", is_flag=True, help="Allow a --host other machines can reach (see docs/server.md)."
)
@click.option(
    "--allow-update", is_flag=True, help="Accept SPARQL Update and Graph Store writes (needs --token)."
)
@click.option(
    "--token", envvar="CADKG_SERVE_TOKEN", default=None, help="Bearer token for writes and /reload."
)
@click.option(
    "--timeout",
    type=click.FloatRange(min=0.1),
    default=30.0,
    show_default=True,
    help="Seconds a request may take.",
)
@click.option(
    "--max-rows",
    type=click.IntRange(min=1),
    default=10_000,
    show_default=True,
    help="Rows (or triples) per answer.",
)
@click.option(
    "--max-body",
    type=click.IntRange(min=1),
    default=1 << 20,
    show_default=True,
    help="Bytes per request body.",
)
@click.option(
    "--workers", type=click.IntRange(min=1), default=4, show_default=True, help="Queries evaluated at once."
)
@click.option(
    "--cache-mb", type=click.IntRange(min=0), default=64, show_default=True, help="Answer cache (0: none)."
)
@click.option(
    "--watch",
    type=click.FloatRange(min=0),
    default=2.0,
    show_default=True,
    help="Seconds between checks for a rebuilt store (0: never).",
)
@_guarded
def serve(
    target: str,
    host: str,
    port: int,
    allow_non_loopback: bool,
    allow_update: bool,
    token: str | None,
    timeout: float,
    max_rows: int,
    max_body: int,
    workers: int,
    cache_mb: int,
    watch: float,
) -> None:
    """Serve the graph over HTTP: SPARQL 1.1 Protocol at /sparql, services at /api, a web page at /.

    Read-only unless --allow-update with a --token; listens on loopback unless
    --allow-non-loopback. A rebuilt store directory is picked up without losing requests.
    """
    from cadkg.remote import RemoteGraph, is_url
    from cadkg.server import Limits, Settings
    from cadkg.server import serve as run_server

    if allow_update and not token:
        raise click.BadParameter("--allow-update needs --token (or CADKG_SERVE_TOKEN)")
    credentials = _store_auth() if is_url(target) else None

    def load() -> Any:
        if is_url(target):
            return RemoteGraph(target, auth=credentials)
        if allow_update and Path(target).is_dir():
            return KnowledgeGraph.open(target, read_only=False)
        return _open(target)

    limits = Limits(timeout=timeout, max_rows=max_rows, max_body=max_body, workers=workers)
    settings = Settings(
        limits=limits, allow_update=allow_update, token=token, cache_bytes=cache_mb << 20, watch_seconds=watch
    )
    run_server(load, settings, host, port, allow_non_loopback=allow_non_loopback)


def _ros_python() -> str | None:
    """The Python that has rclpy: $CADKG_ROS_PYTHON, else the checkout's .venv-ros (scripts/ros-setup.sh)."""
    import os

    configured = os.environ.get("CADKG_ROS_PYTHON")
    if configured:
        return configured
    candidate = Path(__file__).resolve().parents[2] / ".venv-ros" / "bin" / "python"
    return str(candidate) if candidate.exists() else None


@cli.command(name="ros", context_settings={"ignore_unknown_options": True})
@click.argument("source", metavar="STORE_OR_MANIFEST_OR_URL")
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

    from cadkg.remote import is_url

    args = [] if is_url(source) else [str(Path(source).resolve())]
    if is_url(source):
        # Handed to the node's 'source' parameter as is: a positional source is resolved as a path.
        ros_args = (*ros_args, "--ros-args", "-p", f"source:={source}")
    elif not Path(source).exists():
        raise click.BadParameter(f"{source!r} does not exist", param_hint="STORE_OR_MANIFEST_OR_URL")
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
