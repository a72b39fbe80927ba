"""``cadkg diff``: what changed between two revisions of a cell."""

from __future__ import annotations

import csv
import io
import json
import sys
from typing import Any

import click
from rich.table import Table

from cadkg.changes import ChangeSet, Tolerances, changes_turtle, diff_graphs, statement_changes
from cadkg.changes.revisions import open_previous
from cadkg.cli.common import err, guarded, open_local, out, store_or_manifest, write_bytes

__all__ = ["diff"]


@click.command()
@store_or_manifest("old", "OLD_OR_STORE")
@store_or_manifest("new", "NEW", required=False)
@click.option(
    "--format",
    "fmt",
    type=click.Choice(["table", "json", "csv", "ttl"]),
    default="table",
    show_default=True,
    help="ttl: the change set as RDF statements, to patch the old graph with.",
)
@click.option(
    "--move-tolerance",
    type=float,
    default=0.001,
    show_default=True,
    help="Metres a thing may move unreported.",
)
@click.option(
    "--turn-tolerance",
    type=float,
    default=0.5,
    show_default=True,
    help="Degrees a thing may turn unreported.",
)
@guarded
def diff(old: str, new: str | None, fmt: str, move_tolerance: float, turn_tolerance: float) -> None:
    """What changed from OLD to NEW (each a store directory or a manifest), or in STORE since its
    previous build. Things are matched by what identifies them for an engineer: a wire by its
    number and ends, a component by its label and part number, never by IRI or XML id."""
    if new is None:
        before, old_name, new_name = open_previous(old)
        after = open_local(old)
        names = (f"{old}@{old_name}", f"{old}@{new_name}")
    else:
        before, after = open_local(old), open_local(new)
        names = (old, new)
    try:
        changes = diff_graphs(
            before, after, tolerances=Tolerances(move_tolerance, turn_tolerance), names=names
        )
        if fmt == "ttl":
            removed, added = statement_changes(before, after)
            write_bytes(changes_turtle(removed, added, changes))
        elif fmt == "json":
            out.print_json(json.dumps(changes.to_json()))
        elif fmt == "csv":
            sys.stdout.write(changes_csv(changes))
        else:
            out.print(changes_table(changes))
    finally:
        before.close()
        after.close()
    counts = changes.counts()
    err.print(f"{counts['added']} added, {counts['removed']} removed, {counts['changed']} changed")


def _text(value: Any) -> str:
    if value is None:
        return "—"
    if isinstance(value, list):
        return "[" + ", ".join(_text(v) for v in value) + "]"
    return str(value)


def changes_table(changes: ChangeSet) -> Table:
    """A table of the changes: one row per thing, its changed attributes as ``old → new``."""
    table = Table("change", "kind", "id", "what")
    for change in changes:
        what = "; ".join(f"{name}: {_text(a)} → {_text(b)}" for name, (a, b) in change.attributes.items())
        if change.offset is not None:
            what += f" (moved {change.offset['distance']} m, turned {change.offset['rotation_deg']}°)"
        table.add_row(change.change, change.kind, change.id, what)
    return table


def changes_csv(changes: ChangeSet) -> str:
    """``change,kind,id,attribute,old,new``: a row per changed attribute, one per added or removed thing."""
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(["change", "kind", "id", "attribute", "old", "new"])
    for change in changes:
        if not change.attributes:
            writer.writerow([change.change, change.kind, change.id, "", "", ""])
        for name, (a, b) in change.attributes.items():
            writer.writerow([change.change, change.kind, change.id, name, _cell(a), _cell(b)])
    return buffer.getvalue()


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, list):
        return " | ".join(_cell(v) for v in value)
    return str(value)
