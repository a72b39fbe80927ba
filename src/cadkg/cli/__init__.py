"""The ``cadkg`` command line: a thin layer over the Python API.

Exit codes: 0 ok, 1 validation findings, 2 usage or input error. Errors print one
line (file:line: what was found, what was expected); ``--debug`` adds the traceback.
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Sequence

import click

from cadkg.cli.common import err

__all__ = ["cli", "main"]

# Each command's module is imported when the command runs (or --help lists them): one command
# does not pay for importing every other's.
COMMANDS = {
    "build": "cadkg.cli.graph_commands:build",
    "diff": "cadkg.cli.change_commands:diff",
    "query": "cadkg.cli.graph_commands:query",
    "push": "cadkg.cli.graph_commands:push",
    "queries": "cadkg.cli.graph_commands:queries",
    "validate": "cadkg.cli.graph_commands:validate",
    "export": "cadkg.cli.graph_commands:export",
    "call": "cadkg.cli.service_commands:call_service",
    "services": "cadkg.cli.service_commands:list_services",
    "assign": "cadkg.cli.service_commands:assign",
    "progress": "cadkg.cli.service_commands:progress",
    "plan": "cadkg.cli.plan_commands:plan",
    "kinds": "cadkg.cli.graph_commands:kinds",
    "serve": "cadkg.cli.serve_commands:serve",
    "ros": "cadkg.cli.serve_commands:ros",
}


class _Commands(click.Group):
    """A group whose commands are named in :data:`COMMANDS`."""

    def list_commands(self, ctx: click.Context) -> list[str]:
        return sorted(COMMANDS)

    def get_command(self, ctx: click.Context, cmd_name: str) -> click.Command | None:
        spec = COMMANDS.get(cmd_name)
        if spec is None:
            return None
        module, _, name = spec.partition(":")
        found: click.Command = getattr(importlib.import_module(module), name)
        return found


@click.group(cls=_Commands, context_settings={"help_option_names": ["-h", "--help"]})
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


def main(argv: Sequence[str] | None = None) -> None:
    """Entry point of the ``cadkg`` command."""
    try:
        cli.main(args=list(argv) if argv is not None else None, prog_name="cadkg", standalone_mode=True)
    except KeyboardInterrupt:
        err.print("cadkg: interrupted")
        sys.exit(130)


if __name__ == "__main__":
    main()
