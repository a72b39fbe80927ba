"""The kinds of things a revision diff compares, each declared by one SPARQL query.

A use case names a folder of ``.rq`` files (``UseCase.changes``), one per kind; cadkg adds
its own (``changes/kinds``: the source files). Each file starts with a comment header::

    # wire: a wire of a connection list, by its number and its two ends
    # id: number
    # key: id key_ends
    # match: key_ends; id
    # detail: key_ends

followed by one or more SELECT queries, each after a line ``# ---``. The first finds the
things, the others add attributes to the things it found (by ``?thing``): each a query of its
own, DISTINCT, since the default graph is the union of the files' graphs and one query joining
OPTIONAL attributes would multiply what several files state. A thing stated in several rows,
or with several values of an attribute, is gathered by ``?thing``, else by its id. Variables:

- ``?id`` the engineering identity shown (wire number, label); the header's ``id`` line
  names it as an attribute (a renumbered wire reports ``number: [old, new]``);
- ``?thing`` its IRI (optional), for the statements of the change set and the cursors;
- ``?tx ?ty ?tz ?qx ?qy ?qz ?qw`` its pose (optional), compared within the move and turn
  tolerances; ``?rtx`` ... ``?rqw`` a reference pose it is compared relative to (a pin
  inside its component);
- ``?relativeTo`` the IRI of a thing whose pose is that reference, given by a query of the
  file selecting ``?relativeTo ?rtx ... ?rqw`` and no ``?thing`` (each component's pose read
  once, not joined to each of its pins); a thing whose reference has no pose has no pose;
- ``?key_*`` values to match by that are no attribute;
- every other variable an attribute.

``key`` lists what identifies a thing (by default ``id``); things of the two revisions
with equal keys are the same thing. ``match`` lists, separated by ``;``, what the things
left over are matched by next, in order, when it is unique on both sides (same ends, new
number: a renumbered wire). ``detail`` is added to the id of things that share one.

A use case whose derivation writes a kind's things from its cell model may give them from the
model instead (``Derivation.things``: the first queries it stands for), where the graph holds
one cell of that use case and its model; a test holds both ways to the same things.
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Iterable
from dataclasses import dataclass
from functools import cache
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path

import cadkg.registry as registry
from cadkg.errors import QueryError

__all__ = ["POSE", "REFERENCE", "ThingKind", "kinds_for", "parse_kind"]

POSE = ("tx", "ty", "tz", "qx", "qy", "qz", "qw")
REFERENCE = tuple(f"r{name}" for name in POSE)
_HEAD = re.compile(r"^#\s*([\w-]+)\s*:\s*(.+)$")
_VARIABLES = re.compile(r"\?(\w+)")
_SEPARATOR = re.compile(r"^#\s*---+\s*$", re.MULTILINE)


@dataclass(frozen=True)
class ThingKind:
    """One kind of thing: its name, how it is found and how it is identified."""

    name: str
    description: str
    queries: tuple[str, ...]
    id_name: str = "id"
    key: tuple[str, ...] = ("id",)
    match: tuple[tuple[str, ...], ...] = ()
    detail: tuple[str, ...] = ()
    # The use case that declares it ("" for cadkg's own): its model may give the things.
    profile: str = ""


def parse_kind(name: str, text: str) -> ThingKind:
    """The kind declared by the ``.rq`` file ``name`` holding ``text``.

    Raises
    ------
    QueryError
        When the header does not start with ``# NAME: description`` or the query selects no ``?id``.
    """
    lines = text.splitlines()
    head = _HEAD.match(lines[0]) if lines else None
    if head is None or head.group(1) != name:
        raise QueryError(f"{name}.rq: the first line must be '# {name}: what the things are'")
    fields: dict[str, str] = {}
    for line in lines[1:]:
        found = _HEAD.match(line)
        if not line.startswith("#"):
            break
        if found is not None:
            fields[found.group(1)] = found.group(2).strip()
    queries = tuple(part.strip() for part in _SEPARATOR.split(text) if "SELECT" in part.upper())
    if not queries or "id" not in _VARIABLES.findall(queries[0]):
        raise QueryError(f"{name}.rq: the first query must select ?id, the identity of each thing")
    return ThingKind(
        name=name,
        description=head.group(2).strip(),
        queries=queries,
        id_name=fields.get("id", "id"),
        key=tuple(fields.get("key", "id").split()),
        match=tuple(tuple(part.split()) for part in fields.get("match", "").split(";") if part.strip()),
        detail=tuple(fields.get("detail", "").split()),
    )


def _folder_kinds(folder: Traversable | Path) -> list[ThingKind]:
    return [
        parse_kind(entry.name.removesuffix(".rq"), entry.read_text(encoding="utf-8"))
        for entry in sorted(folder.iterdir(), key=lambda e: e.name)
        if entry.name.endswith(".rq")
    ]


@cache
def _kinds_of(profile: str) -> tuple[ThingKind, ...]:
    case = registry.use_case(profile)
    if case.changes is None:
        return ()
    return tuple(dataclasses.replace(kind, profile=profile) for kind in _folder_kinds(case.changes))


def kinds_for(profiles: Iterable[str]) -> list[ThingKind]:
    """cadkg's own kinds, then those of each profile's use case (a kind once, by name).

    Raises
    ------
    KeyError
        On an unknown profile.
    """
    found = {kind.name: kind for kind in _folder_kinds(resources.files("cadkg.changes").joinpath("kinds"))}
    for profile in profiles:
        for kind in _kinds_of(profile):
            found.setdefault(kind.name, kind)
    return list(found.values())
