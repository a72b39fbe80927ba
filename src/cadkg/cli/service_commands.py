"""The commands of the services: call, services, assign, progress."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import Any

import click
from rich.table import Table

from cadkg.cli.common import err, guarded, open_target, out, parse_params
from cadkg.cli.cursor_file import resume_cursors, write_cursors
from cadkg.graph import KnowledgeGraph
from cadkg.plan.decision import Performer

__all__ = ["assign", "call_service", "list_services", "progress"]


@click.command(name="call")
@click.argument("target", metavar="STORE_OR_MANIFEST")
@click.argument("service", metavar="SERVICE")
@click.argument("params", nargs=-1, metavar="[KEY=VALUE]...")
@click.option("--client", default="default", show_default=True, help="Cursor owner for the cursor services.")
@guarded
def call_service(target: str, service: str, params: tuple[str, ...], client: str) -> None:
    """Call a service (see 'cadkg services') and print its result as JSON.

    Exit status: 0 when the service answered, 1 when its answer says ``success: false``,
    2 on a usage or input error (an unknown service or parameter, a malformed value).

    Cursors (connection providers, rail scanner, sequence) are kept per client in
    STORE/cursors.json, so successive calls walk the list; after a rebuild of the store each
    stays on its wire or operation (stderr says where it is, or why it starts afresh).
    """
    from cadkg.services.service import Effect
    from cadkg.services.table import find
    from cadkg.store import cell_profile

    store = Path(target) if Path(target).is_dir() else None
    kg = open_target(target)
    profile = cell_profile(kg)
    declared = find(service, profile)
    if declared is not None and declared.effect is Effect.WRITES and store is not None:
        # A service that writes (assign) changes a store in a new generation, as cadkg assign does.
        kg.close()
        kg = open_target(target, writable=True)
    try:
        answer = _answer(kg, store, profile, service, params, client, declared)
    finally:
        kg.close()  # a refused call as well: one process may call again (a notebook, a test)
    out.print_json(json.dumps(answer))
    if isinstance(answer, dict) and answer.get("success") is False:
        sys.exit(1)  # the service answered, and said it could not do it


def _answer(
    kg: KnowledgeGraph,
    store: Path | None,
    profile: str,
    service: str,
    params: tuple[str, ...],
    client: str,
    declared: Any,
) -> Any:
    from cadkg.services.service import Effect, to_jsonable
    from cadkg.services.session import Session
    from cadkg.services.table import call

    session = Session(kg.cell_model(), kg=kg, profile=profile)
    generation = kg.generation
    if store is not None:
        for note in resume_cursors(session, store, generation):
            err.print(f"cadkg: {note}", markup=False)
    result = call(session, service, parse_params(params), client=client)
    # Only a service declared to move a cursor writes the cursor file.
    if store is not None and declared is not None and declared.effect is Effect.CURSOR:
        write_cursors(store, generation, session)
    return to_jsonable(result)


@click.command(name="services")
@guarded
def list_services() -> None:
    """List the services 'cadkg call' and the ROS adapter serve."""
    from cadkg.services.table import SERVICES

    table = Table("profile", "service", "parameters", "changes", "answers")
    for service in sorted(SERVICES.values(), key=lambda s: s.profile):
        params = ", ".join(
            f"{k} ({t.__name__.lower()}{', optional' if k in service.optional else ''})"
            for k, t in service.params.items()
        )
        changes = service.effect.value if service.effect.changes else "-"
        table.add_row(service.profile, service.name, params, changes, service.description)
    out.print(table)


@click.command()
@click.argument("store_dir", metavar="STORE", type=click.Path(exists=True, file_okay=False))
@click.argument("kind", type=click.Choice(["wire", "component", "operation"]))
@click.argument("ident", metavar="ID")
@click.argument("performer", type=click.Choice([p.value for p in Performer]))
@guarded
def assign(store_dir: str, kind: str, ident: str, performer: str) -> None:
    """Assign a wire (number), component (label) or operation (list position) to robot or human.

    The choice is kept in its own named graph, so rebuilding the store keeps it. The same as
    ``cadkg call STORE assign kind=... id=... performer=...``.
    """
    from cadkg.services.session import Session
    from cadkg.services.table import call

    with KnowledgeGraph.open(store_dir, read_only=False) as kg:
        done = call(Session(None, kg=kg), "assign", {"kind": kind, "id": ident, "performer": performer})
    err.print(f"{kind} {ident} → {performer} ({done.target})")


@click.command()
@click.argument("store_dir", metavar="STORE", type=click.Path(exists=True, file_okay=False))
@click.argument("task", metavar="TASK")
@click.argument("state", metavar="started|done|failed")
@click.option("--reason", default="", help="What happened (why it failed).")
@click.option("--client", default="cli", show_default=True, help="Who reports it.")
@guarded
def progress(store_dir: str, task: str, state: str, reason: str, client: str) -> None:
    """Report what the cell did with TASK (a wire number, an operation label or a task key).

    Kept in the store as a new generation, across rebuilds; a failed robot task goes to a
    person and a stored plan is refreshed around the tasks done. The same as ``cadkg call
    STORE progress task=... state=... reason=...``.
    """
    from cadkg.services.session import Session
    from cadkg.services.table import call

    with KnowledgeGraph.open(store_dir, read_only=False) as kg:
        params = {"task": task, "state": state, **({"reason": reason} if reason else {})}
        done = call(Session(None, kg=kg), "progress", params, client=client)
    err.print(done.message, markup=False)
