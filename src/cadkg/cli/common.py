"""What every ``cadkg`` command shares: the consoles, one-line errors, opening a target,
``key=value`` parameters and printing query results."""

from __future__ import annotations

import contextlib
import csv
import io
import json
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterator, Sequence
from datetime import date, datetime
from decimal import Decimal
from functools import wraps
from pathlib import Path
from typing import Any, TypeVar

import click
import pyoxigraph as ox
from rich.console import Console
from rich.table import Table

from cadkg.errors import CadkgError, QueryError
from cadkg.graph import KnowledgeGraph
from cadkg.limited import DEFAULT_QUERY_MEMORY
from cadkg.store import QueryResult

__all__ = [
    "err",
    "format_option",
    "guarded",
    "max_query_memory",
    "open_local",
    "open_target",
    "out",
    "parse_params",
    "print_result",
    "sparql_json",
    "store_auth",
    "store_or_manifest",
    "warn",
    "write_bytes",
    "write_output",
]

F = TypeVar("F", bound=Callable[..., Any])
err = Console(stderr=True, highlight=False, soft_wrap=True)
# Piped output is read by scripts and people alike: do not truncate table cells to 80 columns.
out = Console(highlight=False, soft_wrap=True, width=None if sys.stdout.isatty() else 240)


def _plain(value: Any) -> Any:
    if isinstance(value, Decimal):
        return format(value, "f")
    if isinstance(value, datetime | date):
        return value.isoformat()
    return value


max_query_memory = click.option(
    "--max-query-memory",
    type=click.IntRange(min=0),
    default=DEFAULT_QUERY_MEMORY,
    show_default=True,
    metavar="MIB",
    help="MiB of memory one query may take; past it the query is stopped (0: no limit).",
)
"""The option of the memory a query may take (``cadkg query``, ``cadkg serve``)."""


def guarded(func: F) -> F:
    """Turn cadkg errors into one line on stderr and exit 2; no traceback without --debug."""

    @wraps(func)
    def wrapper(*args: Any, **kwargs: Any) -> Any:
        debug = click.get_current_context().find_root().params.get("debug", False)
        try:
            return func(*args, **kwargs)
        except (CadkgError, OSError, MemoryError) as error:
            if debug:
                raise
            err.print(f"cadkg: error: {_one_line(error)}", markup=False)
            sys.exit(2)

    return wrapper  # type: ignore[return-value]


def _one_line(err: BaseException) -> str:
    if isinstance(err, OSError) and err.filename and err.strerror:
        # As the readers' errors: the file first, then what went wrong ("[Errno 2] ..." is noise).
        return f"{err.filename}: {err.strerror}"
    # A message quoting a library over several lines is still printed as one.
    text = " ".join(line.strip() for line in str(err).splitlines() if line.strip())
    if isinstance(err, MemoryError):
        # Python's own says nothing ("MemoryError()"), and the command must not print a bare prefix.
        detail = f": {text}" if text else ""
        return f"out of memory{detail} (a file or an answer larger than this process may hold)"
    return text or type(err).__name__


def store_auth(auth: str | None = None, auth_digest: str | None = None) -> Any:
    """Credentials for a remote store: the command's own, else ``cadkg --auth/--auth-digest``."""
    from cadkg.remote import parse_auth

    if not (auth or auth_digest):
        root = click.get_current_context().find_root().params
        auth, auth_digest = root.get("auth"), root.get("auth_digest")
    if auth_digest:
        return parse_auth(auth_digest, digest=True)
    return parse_auth(auth) if auth else None


def open_target(target: str, *, timeout: float | None = None, writable: bool = False) -> KnowledgeGraph:
    """A store directory (read-only unless ``writable``), a manifest built in memory with its
    warnings on stderr, or an http(s) URL: a remote SPARQL endpoint (docs/remote.md) asked with
    the command's credentials and ``timeout`` when given (see :func:`cadkg.served.target.open_target`)."""
    from cadkg.remote import is_url
    from cadkg.served.target import open_target as open_cell

    auth = store_auth() if is_url(target) else None
    return open_cell(target, writable=writable, auth=auth, timeout=timeout, warn=warn)


def warn(warning: str) -> None:
    """A reader's warning, one line on stderr."""
    err.print(f"cadkg: warning: {warning}", markup=False)


def store_or_manifest(
    name: str = "target", metavar: str = "STORE_OR_MANIFEST", *, required: bool = True
) -> Callable[[F], F]:
    """The argument naming a store directory or a manifest, opened with :func:`open_local`."""
    decorator: Callable[[F], F] = click.argument(name, metavar=metavar, required=required)
    return decorator


def format_option(choices: Sequence[str], help: str | None = None) -> Callable[[F], F]:
    """``--format``: how a command prints its answer, a table unless another of ``choices`` is
    asked for (the table is the first choice)."""
    decorator: Callable[[F], F] = click.option(
        "--format", "fmt", type=click.Choice(list(choices)), default="table", show_default=True, help=help
    )
    return decorator


def open_local(target: str, *, writable: bool = False) -> KnowledgeGraph:
    """A store directory or a manifest (see :func:`open_target`); a URL is refused, since the
    command works on local files."""
    from cadkg.served.target import open_target as open_cell

    return open_cell(target, writable=writable, local=True, warn=warn)


def parse_params(pairs: Sequence[str]) -> dict[str, str]:
    params = {}
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise click.BadParameter(f"{pair!r}: parameters are written key=value")
        params[key] = value
    return params


def print_result(result: QueryResult, fmt: str) -> None:
    if fmt == "rows-json":
        rows = [{k: _plain(v) for k, v in row.items()} for row in result.rows]
        out.print_json(json.dumps({"variables": list(result.variables), "rows": rows}))
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
        out.print(table)
        err.print(f"{len(result)} row(s)")


def sparql_json(graph: Any, sparql: str, bindings: dict[str, Any]) -> bytes:
    """A SELECT or ASK answer in the SPARQL 1.1 Query Results JSON format, as ``/sparql`` gives it.

    Raises
    ------
    QueryError
        On a CONSTRUCT or DESCRIBE, and as the query raises.
    """
    result = graph.raw_query(sparql, bindings)
    if not isinstance(result, ox.QuerySolutions | ox.QueryBoolean):
        raise QueryError(
            "--format json prints SELECT and ASK answers; export a CONSTRUCT with 'cadkg export'"
        )
    return bytes(result.serialize(format=ox.QueryResultsFormat.JSON) or b"")


def write_bytes(data: bytes) -> None:
    """``data`` and a newline on stdout."""
    sys.stdout.flush()
    sys.stdout.buffer.write(data + b"\n")
    sys.stdout.buffer.flush()


@contextlib.contextmanager
def write_output(output: str, suffix: str) -> Iterator[Path]:
    """The path to write ``output`` to: the file itself, or for ``-`` a temporary file whose
    content goes to stdout once written (every export writes to a path)."""
    if output != "-":
        yield Path(output)
        return
    with tempfile.TemporaryDirectory(prefix="cadkg-export-") as folder:
        path = Path(folder) / f"export{suffix}"
        yield path
        sys.stdout.flush()
        with path.open("rb") as handle:
            shutil.copyfileobj(handle, sys.stdout.buffer)
        sys.stdout.buffer.flush()
