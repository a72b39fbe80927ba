"""The things of one revision, as its kinds' queries find them."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from datetime import date, datetime
from decimal import Decimal
from typing import Any

import cadkg.registry as registry
from cadkg.changes.kinds import POSE, REFERENCE, ThingKind
from cadkg.geometry.poses import Pose

__all__ = ["Thing", "Value", "cell_profiles", "normal", "read_things"]

# An attribute's value: one text, or the sorted texts of a thing stated with several.
Value = str | tuple[str, ...] | None


def normal(value: Any) -> str:
    """``value`` as comparable text: numbers without the noise of their type or float rounding."""
    if type(value) is str:
        return value
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, Decimal):
        text = format(value.normalize(), "f")
        return text[:-2] if text.endswith(".0") else text
    if isinstance(value, float):
        return format(value, ".9g")
    if isinstance(value, datetime | date):
        return value.isoformat()
    return str(value)


@dataclass
class Thing:
    """One thing of a revision: its identity, attributes and pose."""

    kind: str
    id: str
    iri: str | None
    attributes: dict[str, Value] = field(default_factory=dict)
    pose: Pose | None = None
    keys: dict[str, Value] = field(default_factory=dict)
    # The identity as found; ``id`` may add the kind's detail to it where several share it.
    identity: str = ""

    def __post_init__(self) -> None:
        self.identity = self.identity or self.id

    def value(self, name: str) -> Value:
        """An attribute, a ``key_*`` value, or ``id``."""
        if name == "id":
            return self.identity
        return self.keys[name] if name in self.keys else self.attributes.get(name)

    def key(self, names: tuple[str, ...]) -> tuple[Value, ...] | None:
        """The values of ``names``, or None when one is missing."""
        if names == ("id",):  # most kinds' key: one per thing of a revision
            return (self.identity,)
        values = tuple([self.value(n) for n in names])
        return None if None in values else values


def _pose(row: Mapping[str, Any], names: tuple[str, ...]) -> Pose | None:
    values = [row.get(n) for n in names]
    if any(v is None for v in values):
        return None
    x, y, z, qx, qy, qz, qw = (float(v) for v in values if v is not None)
    return Pose((x, y, z), (qx, qy, qz, qw))


class _Columns:
    """Where a query's rows hold what: attributes, and whether a pose and a reference pose."""

    def __init__(self, row: Mapping[str, Any]) -> None:
        skip = {"id", "thing", "relativeTo", *POSE, *REFERENCE}
        self.attributes = tuple(name for name in row if name not in skip)
        self.pose = all(name in row for name in POSE)
        self.reference = all(name in row for name in REFERENCE)
        self.referent = "relativeTo" in row
        # Rows of references' poses, not of things.
        self.table = self.referent and self.reference and "thing" not in row


class _Gathered:
    """The rows of one thing, merged: each attribute's one value, or the set of its values once
    a second arrives (most attributes have one: no set made for them)."""

    def __init__(self, row: Mapping[str, Any]) -> None:
        self.id = normal(row["id"])
        self.iri = None if row.get("thing") is None else str(row["thing"])
        self.values: dict[str, str | set[str] | None] = {}
        self.pose: Pose | None = None
        self.reference: Pose | None = None
        self.referent: str | None = None

    @classmethod
    def of(cls, thing: Thing) -> _Gathered:
        """A thing found otherwise (a use case's model), to add the rows of queries to."""
        gathered = cls({"id": thing.id, "thing": thing.iri})
        values = gathered.values = {**thing.attributes, **thing.keys}  # type: ignore[dict-item]
        for name, value in values.items():
            if isinstance(value, tuple):
                values[name] = set(value)
        gathered.pose = thing.pose
        return gathered

    def _put(self, name: str, value: str | None) -> None:
        values = self.values
        held = values.get(name)
        if held is None:
            if value is not None or name not in values:
                values[name] = value
        elif value is None or held == value:
            pass
        elif type(held) is str:
            values[name] = {held, value}
        else:
            held.add(value)  # type: ignore[union-attr]

    def merge(self, thing: Thing) -> None:
        """Add what another statement of the same thing says, as another row would."""
        for name, value in (*thing.attributes.items(), *thing.keys.items()):
            if isinstance(value, tuple):
                for each in value:
                    self._put(name, each)
            else:
                self._put(name, value)
        if self.pose is None:
            self.pose = thing.pose

    def add(self, row: Mapping[str, Any], columns: _Columns) -> None:
        values = self.values
        for name in columns.attributes:  # _put inlined: the loop over every cell of every row
            value = row[name]
            held = values.get(name)
            if value is None:
                if held is None and name not in values:
                    values[name] = None
                continue
            if type(value) is not str:
                value = normal(value)
            if held is None:
                values[name] = value
            elif held == value:
                pass
            elif type(held) is str:
                values[name] = {held, value}
            else:
                held.add(value)  # type: ignore[union-attr]
        # Only the columns a query selects: most rows carry no pose.
        if columns.pose and self.pose is None:
            self.pose = _pose(row, POSE)
        if columns.reference and self.reference is None:
            self.reference = _pose(row, REFERENCE)
        if columns.referent and self.referent is None and row["relativeTo"] is not None:
            self.referent = str(row["relativeTo"])

    def thing(self, kind: ThingKind, references: Mapping[str, Pose]) -> Thing:
        attributes: dict[str, Value] = {}
        keys: dict[str, Value] = {}
        for name, held in self.values.items():
            value: Value = held if held is None or type(held) is str else tuple(sorted(held))
            (keys if name[:4] == "key_" else attributes)[name] = value
        pose, reference = self.pose, self.reference
        if self.referent is not None:
            reference = references.get(self.referent)
            # Relative to a reference without a pose: nothing to compare.
            pose = None if reference is None else pose
        if pose is not None and reference is not None:
            pose = reference.inverse() * pose
        return Thing(kind.name, self.id, self.iri, attributes, pose, keys)


def cell_profiles(graph: Any) -> list[str]:
    """The use-case profile of each cell ``graph`` holds, sorted (one entry per cell)."""
    rows = graph.query("SELECT ?profile WHERE { ?cell a ck:Cell ; ck:profile ?profile }").rows
    return sorted(str(row["profile"]) for row in rows)


def read_things(graph: Any, kind: ThingKind, cells: list[str] | None = None) -> list[Thing]:
    """The things of ``kind`` in ``graph`` (anything with ``query``), ids made unique with the
    kind's ``detail`` where several share one. ``cells``: the graph's :func:`cell_profiles`,
    where the caller has them.

    Raises
    ------
    QueryError
        When a query of the kind fails.
    """
    things = _derived_things(graph, kind, cells)
    if things is None:
        things = _queried_things(graph, kind)
    if kind.id_name != "id":
        for thing in things:
            thing.attributes[kind.id_name] = thing.id
    if kind.detail:
        seen: dict[str, int] = {}
        for thing in things:
            seen[thing.id] = seen.get(thing.id, 0) + 1
        for thing in things:
            if seen[thing.id] > 1:
                detail = " ".join(_text(thing.value(n)) for n in kind.detail)
                thing.id = f"{thing.id} ({detail})"
    return things


def _derived_things(graph: Any, kind: ThingKind, cells: list[str] | None = None) -> list[Thing] | None:
    """The things of ``kind`` found in the graph's derived model, where the kind's use case
    derives it and says so (``Derivation.things``) and the graph holds one cell, of that use
    case, and its model; with the attributes of the kind's queries the model does not stand
    for. Else None."""
    derivation = registry.use_case(kind.profile).derivation if kind.profile else None
    model_of = getattr(graph, "derived_model", None)
    if derivation is None or model_of is None or kind.name not in derivation.things:
        return None
    if (cell_profiles(graph) if cells is None else cells) != [kind.profile]:
        return None
    derived = derivation.things[kind.name]
    model = model_of()
    if model is None or not derivation.base(model):
        return None
    found = derived.read(model)
    rest = kind.queries[derived.queries :]
    if not rest and len({thing.iri or ("id", thing.id) for thing in found}) == len(found):
        return found  # each thing once and whole: nothing to gather
    gathered: dict[Any, _Gathered] = {}
    for thing in found:
        handle = thing.iri or ("id", thing.id)
        seen = gathered.get(handle)
        if seen is None:
            gathered[handle] = _Gathered.of(thing)
        else:
            seen.merge(thing)
    return _gather(graph, kind, gathered, rest)


def _queried_things(graph: Any, kind: ThingKind) -> list[Thing]:
    """The things of ``kind`` as its queries find them in ``graph``."""
    gathered: dict[Any, _Gathered] = {}
    first, *more = kind.queries
    rows = graph.query(first).rows
    columns = _Columns(rows[0] if rows else {})
    for row in rows:
        if row.get("id") is None:
            continue
        handle = row.get("thing") or ("id", normal(row["id"]))
        found = gathered.get(handle)
        if found is None:
            found = gathered[handle] = _Gathered(row)
        found.add(row, columns)
    return _gather(graph, kind, gathered, more)


def _gather(
    graph: Any, kind: ThingKind, gathered: dict[Any, _Gathered], queries: Iterable[str]
) -> list[Thing]:
    """The things ``gathered`` with the attributes ``queries`` add to them."""
    references: dict[str, Pose] = {}
    for query in queries:
        rows = graph.query(query).rows
        columns = _Columns(rows[0] if rows else {})
        if columns.table:
            for row in rows:
                pose = _pose(row, REFERENCE)
                if row["relativeTo"] is not None and pose is not None:
                    references.setdefault(str(row["relativeTo"]), pose)
            continue
        for row in rows:
            found = gathered.get(row.get("thing"))
            if found is not None:
                found.add(row, columns)
    return [g.thing(kind, references) for g in gathered.values()]


def _text(value: Value) -> str:
    if value is None:
        return ""
    return value if isinstance(value, str) else ", ".join(value)
