"""The commands that serve a cell: over HTTP (serve) and to ROS 2 (ros)."""

from __future__ import annotations

import re
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any, TypeVar

import click

from cadkg.cli.common import err, guarded, max_query_memory, store_auth, warn

__all__ = ["ros", "serve"]

F = TypeVar("F", bound=Callable[..., Any])


def _number(name: str, kind: click.ParamType[Any], default: float, help: str) -> Callable[[F], F]:
    """An option taking a number in ``kind``'s range, with its default shown in --help."""
    return click.option(name, type=kind, default=default, show_default=True, help=help)


@click.command()
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
@_number("--timeout", click.FloatRange(min=0.1), 30.0, "Seconds a request may take.")
@_number("--max-rows", click.IntRange(min=1), 10_000, "Rows (or triples) per answer.")
@_number("--max-body", click.IntRange(min=1), 1 << 20, "Bytes per request body.")
@_number("--workers", click.IntRange(min=1), 4, "Queries evaluated at once.")
@max_query_memory
@_number(
    "--header-timeout",
    click.FloatRange(min=0.1),
    10.0,
    "Seconds a connection has to send a request head (and a body between two chunks).",
)
@_number(
    "--max-connections",
    click.IntRange(min=0),
    0,
    "Connections open at once; past them a 503 (0: from the descriptor limit, less 256).",
)
@_number("--cache-mb", click.IntRange(min=0), 64, "Answer cache (0: none).")
@_number("--watch", click.FloatRange(min=0), 2.0, "Seconds between checks for a rebuilt store (0: never).")
@click.option(
    "--allow-service",
    "allow_service",
    multiple=True,
    metavar="URL",
    help="An endpoint a query's SERVICE may reach (repeatable); without, federated queries are refused.",
)
@click.option(
    "--cors",
    multiple=True,
    metavar="ORIGIN",
    help="A web origin (https://host:port) whose pages may query the endpoint (repeatable).",
)
@click.option(
    "--files-root",
    type=click.Path(exists=True, file_okay=False),
    default=None,
    metavar="DIR",
    help="The only directory load_files reads from over HTTP (needs --allow-update).",
)
@guarded
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
    max_query_memory: int,
    header_timeout: float,
    max_connections: int,
    cache_mb: int,
    watch: float,
    allow_service: tuple[str, ...],
    cors: tuple[str, ...],
    files_root: str | None,
) -> None:
    """Serve the graph over HTTP: SPARQL 1.1 Protocol at /sparql, services at /api, a web page at /.

    Read-only unless --allow-update with a --token; listens on loopback unless
    --allow-non-loopback; makes no outbound request unless --allow-service; answers no web page
    of another origin unless --cors. A rebuilt store directory is picked up without losing
    requests. See docs/server.md, Security.
    """
    from cadkg.remote import is_url
    from cadkg.served.target import open_target
    from cadkg.server import Limits, Settings
    from cadkg.server import serve as run_server

    if allow_update and not token:
        raise click.BadParameter("--allow-update needs --token (or CADKG_SERVE_TOKEN)")
    for origin in cors:
        if not re.fullmatch(r"https?://[^/\s]+", origin):
            raise click.BadParameter(f"{origin!r} is not a web origin: scheme://host[:port], no path")
    credentials = store_auth() if is_url(target) else None

    def load() -> Any:
        return open_target(target, writable=allow_update, auth=credentials, warn=warn)

    limits = Limits(
        timeout=timeout,
        max_rows=max_rows,
        max_body=max_body,
        workers=workers,
        query_memory=max_query_memory,
        header_timeout=header_timeout,
        max_connections=max_connections,
    )
    settings = Settings(
        limits=limits,
        allow_update=allow_update,
        token=token,
        cache_bytes=cache_mb << 20,
        watch_seconds=watch,
        files_root=Path(files_root) if files_root is not None else None,
        cors=tuple(cors),
        allowed_services=tuple(allow_service),
    )
    run_server(load, settings, host, port, allow_non_loopback=allow_non_loopback)


def _ros_python() -> str | None:
    """The Python that has rclpy: $CADKG_ROS_PYTHON, else the checkout's .venv-ros (scripts/ros-setup.sh)."""
    import os

    configured = os.environ.get("CADKG_ROS_PYTHON")
    if configured:
        return configured
    candidate = Path(__file__).resolve().parents[3] / ".venv-ros" / "bin" / "python"
    return str(candidate) if candidate.exists() else None


@click.command(name="ros", context_settings={"ignore_unknown_options": True})
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
        err.print(
            "cadkg: error: no rclpy here and no .venv-ros; run scripts/ros-setup.sh first", markup=False
        )
        sys.exit(2)
    os.execv(python, [python, "-m", "cadkg.ros_adapter", *args])
