"""What changed between two revisions of a cell: things matched by engineering identity (never
by IRI or XML id), their changed attributes and moves, and the change set as RDF statements."""

from cadkg.changes.changeset import Change, ChangeSet
from cadkg.changes.compare import Tolerances, diff_graphs, diff_things
from cadkg.changes.kinds import ThingKind, kinds_for, parse_kind
from cadkg.changes.statements import apply_changes, changes_turtle, read_changes, statement_changes
from cadkg.changes.things import Thing, read_things

__all__ = [
    "Change",
    "ChangeSet",
    "Thing",
    "ThingKind",
    "Tolerances",
    "apply_changes",
    "changes_turtle",
    "diff_graphs",
    "diff_things",
    "kinds_for",
    "parse_kind",
    "read_changes",
    "read_things",
    "statement_changes",
]
