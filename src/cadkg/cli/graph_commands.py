"""The commands on a cell's graph: build, query, queries, validate, export, push, kinds."""

from __future__ import annotations

import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import click
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

import cadkg.registry as registry
from cadkg.cli.common import (
    err,
    format_option,
    guarded,
    max_query_memory,
    open_target,
    out,
    parse_params,
    print_result,
    sparql_json,
    store_auth,
    store_or_manifest,
    write_bytes,
    write_output,
)
from cadkg.errors import QueryError
from cadkg.graph import KnowledgeGraph
from cadkg.ingest.manifest import load_manifest
from cadkg.query.named import coerce_params, named_queries
from cadkg.query.validate import validate as run_validation
from cadkg.store import EXPORT_FORMATS
from cadkg.usecase import ExportOptions

__all__ = ["build", "export", "kinds", "push", "queries", "query", "validate"]


def _progress(count: str) -> Progress:
    """A bar on stderr while a command works, shown only on a terminal; ``count`` is its
    ``done/total`` column."""
    return Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn(count),
        TimeElapsedColumn(),
        console=err,
        transient=True,
        disable=not err.is_terminal,
    )


@click.command()
@click.argument("manifest", type=click.Path(exists=True, dir_okay=False))
@click.option(
    "--store",
    "store_dir",
    required=True,
    type=click.Path(file_okay=False),
    help="Store directory to write (replaced atomically).",
)
@guarded
def build(manifest: str, store_dir: str) -> None:
    """Read every file of MANIFEST into a store directory."""
    spec = load_manifest(manifest)
    with _progress("{task.completed}/{task.total} files") as progress:
        task = progress.add_task("reading", total=len(spec.sources))

        def stage(name: str) -> None:
            progress.update(task, description=name)

        kg = KnowledgeGraph.build(spec, store_dir, on_source=lambda _: progress.advance(task), on_stage=stage)
    out.print(build_table(kg, f"{spec.cell.name} → {store_dir}"))
    for report in kg.reports:
        for warning in report.warnings:
            err.print(f"cadkg: warning: {warning}", markup=False)
    out.print(f"{len(kg)} triples in {len(kg.named_graphs())} named graphs")
    kg.close()


@click.command()
@store_or_manifest()
@click.argument("query", metavar="QUERY_OR_FILE")
@click.argument("params", nargs=-1, metavar="[KEY=VALUE]...")
@format_option(
    ["table", "csv", "json", "rows-json"],
    "json: SPARQL 1.1 Query Results JSON, as /sparql answers; rows-json: {variables, rows} of plain values.",
)
@click.option(
    "--timeout",
    type=click.FloatRange(min=0.1),
    default=None,
    metavar="SECONDS",
    help="Stop the query after this long (its process is then killed).",
)
@max_query_memory
@click.option(
    "--allow-service",
    "allow_service",
    multiple=True,
    metavar="URL",
    help="An endpoint SERVICE may reach (repeatable); without, federated queries are refused.",
)
@guarded
def query(
    target: str,
    query: str,
    params: tuple[str, ...],
    fmt: str,
    timeout: float | None,
    max_query_memory: int,
    allow_service: tuple[str, ...],
) -> None:
    """Run a named query, a .rq file or SPARQL text; KEY=VALUE binds parameters.

    A local graph is queried in a child process that has no network (unless --allow-service)
    and may take --max-query-memory MiB; a remote store evaluates the query itself.
    """
    from cadkg.cli.limited_query import run_limited_query
    from cadkg.remote import is_url

    bindings: dict[str, Any] = dict(parse_params(params))
    known = named_queries()
    if query in known:
        text = known[query].text
        bindings = coerce_params(known[query], bindings)
    else:
        path = Path(query)
        text = path.read_text(encoding="utf-8") if path.suffix == ".rq" and path.is_file() else query
        if text is query and not any(
            word in query.upper() for word in ("SELECT", "ASK", "CONSTRUCT", "DESCRIBE")
        ):
            raise QueryError(
                f"{query!r} is not a named query, a .rq file or SPARQL; named: {', '.join(known)}"
            )

    def answer(ready: Callable[[], None]) -> None:
        kg = open_target(target, timeout=timeout)
        kg.allowed_services = frozenset(allow_service)
        ready()
        if fmt == "json":
            write_bytes(sparql_json(kg, text, bindings))
        else:
            print_result(kg.query(text, **bindings), fmt)

    if is_url(target):  # a remote store evaluates the query: the timeout is its HTTP client's
        answer(lambda: None)
    else:
        run_limited_query(answer, seconds=timeout, memory=max_query_memory, network=bool(allow_service))


@click.command()
@store_or_manifest()
@click.option("--endpoint", required=True, metavar="URL", help="The store's SPARQL (Update) endpoint.")
@click.option("--graph-store", metavar="URL", help="The store's Graph Store Protocol endpoint (if any).")
@click.option(
    "--method", type=click.Choice(["auto", "graph-store", "update"]), default="auto", show_default=True
)
@click.option("--auth", metavar="USER:PASSWORD", help="Basic auth (default: cadkg --auth).")
@click.option("--auth-digest", metavar="USER:PASSWORD", help="Digest auth (Virtuoso's *-auth endpoints).")
@click.option("--batch", type=click.IntRange(min=1), default=None, help="Most triples in one request.")
@guarded
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
    kg = open_target(target)
    credentials = store_auth(auth, auth_digest)
    report = push_graphs(kg, endpoint, graph_store=graph_store, auth=credentials, method=method, batch=batch)
    table = Table("graph", "triples", "requests", "seconds", title=f"{report.method} → {report.target}")
    for sent in report.graphs:
        table.add_row(sent.graph, str(sent.triples), str(sent.requests), f"{sent.seconds:.3f}")
    out.print(table)
    out.print(f"{report.triples} triples in {len(report.graphs)} named graphs sent")
    for note in report.notes:
        err.print(f"cadkg: note: {note}", markup=False)


@click.command()
@guarded
def queries() -> None:
    """List the named queries and their parameters."""
    table = Table("name", "parameters", "answers")
    for named in named_queries().values():
        params = ", ".join(f"{p.name} ({p.type})" for p in named.params)
        table.add_row(named.name, params, named.description)
    out.print(table)


@click.command()
@store_or_manifest()
@click.option("--no-shacl", is_flag=True, help="Skip the SHACL shapes (semantic checks only).")
@click.option("--strict", is_flag=True, help="Warnings count as findings for the exit code.")
@guarded
def validate(target: str, no_shacl: bool, strict: bool) -> None:
    """Check the graph: SHACL shapes, unknown labels, duplicate wire numbers, pins without data."""
    kg = open_target(target)
    with _progress("{task.completed}/{task.total}") as progress:
        task = progress.add_task("checks", total=3)

        def step(stage: str, done: int, total: int) -> None:
            progress.update(task, description=stage, completed=done, total=total)

        findings = run_validation(kg, shacl=not no_shacl, progress=step)
    for finding in findings:
        out.print(str(finding), markup=False)
    errors = sum(1 for f in findings if f.severity == "error")
    warnings_ = len(findings) - errors
    err.print(f"{errors} error(s), {warnings_} warning(s)")
    if errors or (strict and warnings_):
        sys.exit(1)


@click.command()
@store_or_manifest()
@click.option(
    "--format",
    "fmt",
    type=click.Choice([*EXPORT_FORMATS, "graphml"]),
    default=None,
    help="Default: from the output suffix.",
)
@click.option(
    "-o",
    "--output",
    required=True,
    type=click.Path(dir_okay=False, allow_dash=True),
    help="A file, or - for stdout.",
)
@click.option(
    "--view",
    default=None,
    metavar="VIEW",
    help="GraphML only: 'structure' (every structural relation, the default), or a use case's view "
    "(the harness 'topology' or 'wires').",
)
@click.option(
    "--harness", default=None, metavar="ID", help="The harness of --view (when the store holds several)."
)
@click.option(
    "--modules",
    default=None,
    metavar="M1,M2",
    help="The variant of --view holding these modules of a modular harness (or a configuration's name).",
)
@click.option("--yed", is_flag=True, help="GraphML views: add yEd's node geometry and labels.")
@guarded
def export(
    target: str,
    fmt: str | None,
    output: str,
    view: str | None,
    harness: str | None,
    modules: str | None,
    yed: bool,
) -> None:
    """Write the graph as Turtle, N-Triples, N-Quads, TriG, JSON-LD or GraphML."""
    fmt = fmt or ("" if output == "-" else Path(output).suffix.lstrip(".").lower())
    if fmt not in (*EXPORT_FORMATS, "graphml"):
        raise click.BadParameter(f"cannot tell the format from {output!r}; give --format")
    if (harness is not None or modules is not None or yed) and view in (None, "structure"):
        view = "topology"
    views = {name: write for case in registry.use_cases() for name, write in case.views.items()}
    if view not in (None, "structure", *views):
        raise click.BadParameter(f"unknown view {view!r}; one of structure, {', '.join(sorted(views))}")
    if view in views and fmt != "graphml":
        raise click.BadParameter(f"--view {view} writes GraphML, not {fmt}")
    kg = open_target(target)
    what = f"the {view} view" if view in views else "the graph"
    with err.status(f"exporting {what} as {fmt}"), write_output(output, "." + fmt) as path:
        if view in views:
            options = ExportOptions(tuple(m.strip() for m in (modules or "").split(",") if m.strip()), yed)
            for warning in views[view](kg, str(path), harness, options):
                err.print(f"cadkg: warning: {warning}", markup=False)
        else:
            kg.export(path, fmt)
    if output != "-":
        err.print(f"wrote {output}")


@click.command()
@guarded
def kinds() -> None:
    """List the input file kinds cadkg reads."""
    table = Table("kind", "suffixes", "format")
    for reader in registry.kinds():
        table.add_row(reader.kind, " ".join(reader.suffixes), reader.description)
    out.print(table)


def build_table(kg: KnowledgeGraph, title: str) -> Table:
    """Each file's records and triples and every stage's seconds, adding up to the whole build."""
    table = Table("file or stage", "kind", "records", "triples", "seconds", title=title)
    reports = {f"reading {r.rel_path}": r for r in kg.reports}
    for name, seconds in kg.stages:
        report = reports.get(name)
        if report is not None:
            table.add_row(
                report.rel_path, report.kind, str(report.records), str(report.triples), f"{seconds:.3f}"
            )
        else:
            table.add_row(name, "", "", "", f"{seconds:.3f}")
    table.add_row("total", "", "", "", f"{sum(s for _, s in kg.stages):.3f}", end_section=True)
    return table
