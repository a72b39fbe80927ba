"""``cadkg diff``: what changed between two revisions of a cell."""

from __future__ import annotations

import csv
import io
import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any

import click

from cadkg.cli.common import err, format_option, guarded, open_local, out, store_or_manifest, write_bytes
from cadkg.cli.cursor_file import read_cursors
from cadkg.services.session import Session, Work

if TYPE_CHECKING:
    from rich.table import Table

    from cadkg.changes import ChangeSet
    from cadkg.changes.impact import Impact

__all__ = ["diff"]


@click.command()
@store_or_manifest("old", "OLD_OR_STORE")
@store_or_manifest("new", "NEW", required=False)
@format_option(
    ["table", "json", "csv", "ttl"], "ttl: the change set as RDF statements, to patch the old graph with."
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
    # The revision diff is imported by this command only, not by every command of the CLI.
    from cadkg.changes import Tolerances, changes_turtle, diff_graphs, statement_changes
    from cadkg.changes.revisions import open_previous

    if new is None:
        before, old_name, new_name = open_previous(old)
        after = open_local(old)
        names = (f"{old}@{old_name}", f"{old}@{new_name}")
        generations: tuple[str | None, str | None] = (old_name, new_name)
    else:
        before, after = open_local(old), open_local(new)
        names = (old, new)
        generations = (before.generation, None)
    try:
        changes = diff_graphs(
            before, after, tolerances=Tolerances(move_tolerance, turn_tolerance), names=names
        )
        store = Path(old) if Path(old).is_dir() else None
        changes.impact = impact_of(changes, before, after, store, generations)
        if fmt == "ttl":
            removed, added = statement_changes(before, after)
            write_bytes(changes_turtle(removed, added, changes))
        elif fmt == "json":
            out.print_json(json.dumps(changes.to_json()))
        elif fmt == "csv":
            sys.stdout.write(changes_csv(changes))
        else:
            out.print(changes_table(changes))
            if changes.impact is not None:
                out.print(impact_table(changes.impact))
    finally:
        before.close()
        after.close()
    counts = changes.counts()
    err.print(f"{counts['added']} added, {counts['removed']} removed, {counts['changed']} changed")
    if changes.impact is not None:
        tasks = changes.impact.counts()
        err.print(
            f"tasks: {tasks['new']} new, {tasks['redo']} to redo, {tasks['changed']} changed, "
            f"{tasks['dropped']} dropped"
        )


def impact_of(
    changes: ChangeSet,
    before: Any,
    after: Any,
    store: Path | None,
    generations: tuple[str | None, str | None],
) -> Impact | None:
    """The impact on the old revision's plan and on the cursors kept beside ``store`` (the old
    revision's directory; ``generations`` the old and the live generation's names)."""
    from cadkg.changes.impact import plan_impact
    from cadkg.plan.graph import cell_base, read_plan

    plan, new_plan = read_plan(before, cell_base(before)), read_plan(after, cell_base(after))
    made_on, cursors = read_cursors(store) if store is not None else (None, {})
    done: dict[str, list[Work]] = {}
    notes: list[str] = []
    old_name = generations[0]
    if cursors and made_on is not None and made_on in generations:
        on_old = made_on == old_name
        session = Session((before if on_old else after).cell_model(), kg=before if on_old else after)
        session.load(cursors)
        done = session.done()
        if on_old:
            notes = Session(after.cell_model(), kg=after).carry_over(session)
    elif cursors and made_on is not None:
        notes = [f"the cursors were made on generation {made_on}, neither of these"]
    return plan_impact(changes, plan, done, new_plan, notes)


def impact_table(impact: Impact) -> Table:
    """A table of the tasks the changes touch: new, to redo, changed, dropped."""
    from rich.table import Table

    table = Table("task", "kind", "id", "step", "why")
    for name in ("new", "redo", "changed", "dropped"):
        for item in getattr(impact, name):
            table.add_row(name, item["kind"], item["id"], _text(item.get("step")), _why(name, item))
    for note in impact.cursors:
        table.add_row("cursor", "", "", "", note)
    return table


def _why(name: str, item: dict[str, Any]) -> str:
    if name == "new":
        return "added"
    if name == "dropped":
        return "removed" + (f", passed by {', '.join(item['passed_by'])}" if item["done"] else "")
    what = f"changed ({', '.join(item['attributes'])})"
    return (
        f"{what} after {', '.join(item['passed_by'])} passed it"
        if name == "redo"
        else f"{what}, not yet done"
    )


def _text(value: Any) -> str:
    if value is None:
        return "—"
    if isinstance(value, list):
        return "[" + ", ".join(_text(v) for v in value) + "]"
    return str(value)


def changes_table(changes: ChangeSet) -> Table:
    """A table of the changes: one row per thing, its changed attributes as ``old → new``."""
    from rich.table import Table

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
