"""What the services of one served cell share: the graph, its derived model, the models each
use case builds from the graph on first use, and every client's cursors.

A cursor (the next wire, the next operation) belongs to one client (a ROS node, a CLI user,
an HTTP caller) and one use case; :meth:`Session.dump` and :meth:`Session.load` carry them
between processes (``cadkg call`` keeps them beside the store). After a rebuild, a reload or
an assignment, :meth:`Session.carry_over` moves them onto the same wire or operation of the
new graph, found by what identifies it (the use case's :func:`cursor_rebase`), not by index.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
from collections.abc import Callable, Hashable, Iterator, Sequence
from typing import Any, TypeVar, cast

from cadkg.errors import CadkgError, QueryError

__all__ = ["Done", "Rebase", "Session", "Work", "cursor_done", "cursor_rebase", "follow"]

T = TypeVar("T")
S = TypeVar("S")
Item = TypeVar("Item")

# rebase(old, new, cursor): moves ``cursor`` (a copy of one of ``old``'s) onto ``new``'s graph;
# says where it now is, or why it could not stay on its thing.
Rebase = Callable[["Session", "Session", Any], str]
_REBASES: dict[str, Rebase] = {}


@dataclasses.dataclass(frozen=True)
class Work:
    """A wire or an operation a cursor has passed: its kind and identity as a diff names them
    (:mod:`cadkg.changes`), and its IRI where the use case knows it."""

    kind: str
    id: str
    iri: str = ""


# done(session, cursor): the work ``cursor`` has passed in ``session``'s graph, in order.
Done = Callable[["Session", Any], Sequence[Work]]
_DONE: dict[str, tuple[Callable[..., Any], Done]] = {}


def cursor_done(key: str, state: Callable[..., Any]) -> Callable[[Done], Done]:
    """Register what the cursors of the use case ``key`` (made by ``state``) have passed."""

    def register(done: Done) -> Done:
        _DONE[key] = (state, done)
        return done

    return register


def cursor_rebase(key: str) -> Callable[[Rebase], Rebase]:
    """Register how the cursors of the use case ``key`` move to a rebuilt graph."""

    def register(rebase: Rebase) -> Rebase:
        _REBASES[key] = rebase
        return rebase

    return register


def follow(
    old: Sequence[Item], position: int, new: Sequence[Item], identities: Sequence[Callable[[Item], Hashable]]
) -> tuple[int, int]:
    """Where the item at ``position`` of ``old`` is in ``new``: by the first of ``identities``
    that finds it (each tried only where it is unique in ``new``); an item no longer there is
    replaced by the next one of ``old`` that is. Returns the new position (``len(new)`` when
    none is left) and how many items of ``old`` were passed over."""
    tables = []
    for identity in identities:
        table: dict[Hashable, int | None] = {}
        for index, item in enumerate(new):
            key = identity(item)
            table[key] = None if key in table else index
        tables.append((identity, table))
    for skipped, item in enumerate(old[position:]):
        for identity, table in tables:
            found = table.get(identity(item))
            if found is not None:
                return found, skipped
    return len(new), len(old) - position


class Session:
    """``model`` is the cell's derived model (see :func:`cadkg.registry.derivation`); ``kg`` the
    graph; ``profile`` the use case whose frames the cell shows (:func:`cadkg.store.cell_profile`
    of the graph, as a transport opens it; ``""``: the default profile).

    A served cell sets :attr:`reopen`: what the ``reload`` service calls to serve the store's
    current generation (previous and new generation). A one-shot caller leaves it ``None``.
    """

    def __init__(self, model: Any, kg: Any = None, profile: str = "") -> None:
        self.model = model
        self.kg = kg
        self.profile = profile
        self.reopen: Callable[[], tuple[str, str]] | None = None
        self._memo: dict[str, Any] = {}
        self._cursors: dict[str, dict[str, Any]] = {}
        # Cursors read by load() and not asked for yet: their type is known only on first use.
        self._saved: dict[str, dict[str, dict[str, Any]]] = {}
        # The service running now when it is declared as only reading (see reading()).
        self._reading = ""

    def memo(self, key: str, build: Callable[[], T]) -> T:
        """``build()``, computed once per session (so once per reload of the graph)."""
        if key not in self._memo:
            self._memo[key] = build()
        return cast(T, self._memo[key])

    def profile_model(self, key: str, build: Callable[[Any], T]) -> T:
        """The model ``build(kg)`` of a use case, built once per session.

        Raises
        ------
        QueryError
            When the session has no graph to build it from.
        """
        if key not in self._memo and self.kg is None:
            raise QueryError(f"the {key} services need a graph; this session has none")
        return self.memo(key, lambda: build(self.kg))

    def forget(self, key: str) -> None:
        """Drop what :meth:`memo` keeps under ``key``, so the next call rebuilds it from the graph."""
        self._memo.pop(key, None)

    @contextlib.contextmanager
    def reading(self, service: str) -> Iterator[None]:
        """Run a service declared as only reading: asking for a cursor inside is an error, so a
        reading service cannot move one, whatever its code does."""
        outer, self._reading = self._reading, service
        try:
            yield
        finally:
            self._reading = outer

    def cursor(self, key: str, client: str, new: Callable[..., S]) -> S:
        """The cursor of ``client`` for the use case ``key``: ``new()`` when it has none, or
        ``new(**fields)`` with what :meth:`load` read for it.

        Raises
        ------
        QueryError
            Inside :meth:`reading`: the service is declared as changing nothing.
        """
        if self._reading:
            raise QueryError(
                f"{self._reading} is declared as only reading, yet asks for a {key} cursor; "
                "declare it Effect.CURSOR"
            )
        cursors = self._cursors.setdefault(key, {})
        if client not in cursors:
            saved = self._saved.get(key, {}).pop(client, None) or {}
            try:
                cursors[client] = new(**saved)
            except (TypeError, ValueError):  # written by another version: start afresh
                cursors[client] = new()
        return cast(S, cursors[client])

    def dump(self) -> dict[str, dict[str, dict[str, Any]]]:
        """Every client's cursors (dataclasses) as JSON-ready data: use case → client → fields."""
        data = {key: dict(clients) for key, clients in self._saved.items()}
        for key, clients in self._cursors.items():
            data.setdefault(key, {}).update(
                {client: dataclasses.asdict(state) for client, state in clients.items()}
            )
        return data

    def _take_saved(self) -> None:
        """Make the cursors :meth:`load` read whose use case says what they are."""
        for key, (state, _) in _DONE.items():
            for client in list(self._saved.get(key, {})):
                self.cursor(key, client, state)

    def done(self) -> dict[str, list[Work]]:
        """The work each cursor has passed (named as :meth:`carry_over` names it), for the
        cursors whose use case says."""
        self._take_saved()
        passed = {}
        for key, clients in self._cursors.items():
            entry = _DONE.get(key)
            for client, cursor in clients.items():
                if entry is not None:
                    passed[f"{key} cursor of {client}"] = list(entry[1](self, cursor))
        return passed

    def carry_over(self, old: Session) -> list[str]:
        """Take the cursors of ``old`` (the session of the graph before a rebuild or a change),
        each moved onto the same wire or operation here; says for each where it is now.

        A use case without a rebase keeps its cursors by index.
        """
        notes = []
        old._take_saved()
        for key, clients in old._saved.items():
            self._saved.setdefault(key, {}).update(clients)
        for key, clients in old._cursors.items():
            rebase = _REBASES.get(key)
            for client, cursor in clients.items():
                moved = copy.copy(cursor)
                if rebase is None:
                    note = "kept by index"
                else:
                    try:
                        note = rebase(old, self, moved)
                    except CadkgError as err:
                        moved, note = type(cursor)(), f"rewound: {err}"
                self._cursors.setdefault(key, {})[client] = moved
                notes.append(f"{key} cursor of {client}: {note}")
        return notes

    def load(self, data: dict[str, Any]) -> None:
        """Take cursors written by :meth:`dump`; malformed entries are ignored."""
        for key, clients in data.items():
            if isinstance(clients, dict):
                self._saved[key] = {c: v for c, v in clients.items() if isinstance(v, dict)}
