"""The commands on a cell's graph: build, query, queries, validate, export, push, kinds."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import click
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

import cadkg.registry as registry
from cadkg.cli.common import err, guarded, open_target, out, parse_params, print_result, store_auth
from cadkg.errors import QueryError
from cadkg.graph import KnowledgeGraph
from cadkg.ingest.manifest import load_manifest
from cadkg.query.named import coerce_params, named_queries
from cadkg.query.validate import validate as run_validation
from cadkg.store import EXPORT_FORMATS
from cadkg.usecase import ExportOptions

__all__ = ["build", "export", "kinds", "push", "queries", "query", "validate"]


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
    with Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        TextColumn("{task.completed}/{task.total}"),
        TimeElapsedColumn(),
        console=err,
        transient=True,
        disable=not err.is_terminal,
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
    out.print(table)
    for report in kg.reports:
        for warning in report.warnings:
            err.print(f"cadkg: warning: {warning}", markup=False)
    out.print(f"{len(kg)} triples in {len(kg.named_graphs())} named graphs")
    kg.close()


@click.command()
@click.argument("target", metavar="STORE_OR_MANIFEST")
@click.argument("query", metavar="QUERY_OR_FILE")
@click.argument("params", nargs=-1, metavar="[KEY=VALUE]...")
@click.option(
    "--format", "fmt", type=click.Choice(["table", "csv", "json"]), default="table", show_default=True
)
@guarded
def query(target: str, query: str, params: tuple[str, ...], fmt: str) -> None:
    """Run a named query, a .rq file or SPARQL text; KEY=VALUE binds parameters."""
    bindings = parse_params(params)
    kg = open_target(target)
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
    print_result(result, fmt)


@click.command()
@click.argument("target", metavar="STORE_OR_MANIFEST")
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
@click.argument("target", metavar="STORE_OR_MANIFEST")
@click.option("--no-shacl", is_flag=True, help="Skip the SHACL shapes (semantic checks only).")
@click.option("--strict", is_flag=True, help="Warnings count as findings for the exit code.")
@guarded
def validate(target: str, no_shacl: bool, strict: bool) -> None:
    """Check the graph: SHACL shapes, unknown labels, duplicate wire numbers, pins without data."""
    findings = run_validation(open_target(target), shacl=not no_shacl)
    for finding in findings:
        out.print(str(finding), markup=False)
    errors = sum(1 for f in findings if f.severity == "error")
    warnings_ = len(findings) - errors
    err.print(f"{errors} error(s), {warnings_} warning(s)")
    if errors or (strict and warnings_):
        sys.exit(1)


@click.command()
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
    fmt = fmt or Path(output).suffix.lstrip(".").lower()
    if fmt not in (*EXPORT_FORMATS, "graphml"):
        raise click.BadParameter(f"cannot tell the format from {output!r}; give --format")
    if (harness is not None or modules is not None or yed) and view in (None, "structure"):
        view = "topology"
    views = {name: write for case in registry.use_cases() for name, write in case.views.items()}
    if view not in (None, "structure", *views):
        raise click.BadParameter(f"unknown view {view!r}; one of structure, {', '.join(sorted(views))}")
    if view in views:
        if fmt != "graphml":
            raise click.BadParameter(f"--view {view} writes GraphML, not {fmt}")
        options = ExportOptions(tuple(m.strip() for m in (modules or "").split(",") if m.strip()), yed)
        for warning in views[view](open_target(target), output, harness, options):
            err.print(f"cadkg: warning: {warning}", markup=False)
    else:
        open_target(target).export(output, fmt)
    err.print(f"wrote {output}")


@click.command()
@guarded
def kinds() -> None:
    """List the input file kinds cadkg reads."""
    table = Table("kind", "suffixes", "format")
    for reader in registry.kinds():
        table.add_row(reader.kind, " ".join(reader.suffixes), reader.description)
    out.print(table)
