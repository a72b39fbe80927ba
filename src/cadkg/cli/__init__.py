"""The ``cadkg`` command line: a thin layer over the Python API.

Exit codes: 0 ok, 1 validation findings, 2 usage or input error. Errors print one
line (file:line: what was found, what was expected); ``--debug`` adds the traceback.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

import click

from cadkg.cli.change_commands import diff
from cadkg.cli.common import err
from cadkg.cli.graph_commands import build, export, kinds, push, queries, query, validate
from cadkg.cli.plan_commands import plan
from cadkg.cli.serve_commands import ros, serve
from cadkg.cli.service_commands import assign, call_service, list_services, progress

__all__ = ["cli", "main"]


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


for command in (
    build,
    diff,
    query,
    push,
    queries,
    validate,
    export,
    call_service,
    list_services,
    assign,
    progress,
    plan,
    kinds,
    serve,
    ros,
):
    cli.add_command(command)


def main(argv: Sequence[str] | None = None) -> None:
    """Entry point of the ``cadkg`` command."""
    try:
        cli.main(args=list(argv) if argv is not None else None, prog_name="cadkg", standalone_mode=True)
    except KeyboardInterrupt:
        err.print("cadkg: interrupted")
        sys.exit(130)


if __name__ == "__main__":
    main()
