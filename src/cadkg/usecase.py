"""What one use case brings to cadkg, declared in one place.

A use case is a product and its robot cell (IEMA's switchgear cabinet, ELVEZ's harness
assembly ...). It lives in a folder of ``cadkg/usecases`` or in a package of its own, declares
one :class:`UseCase`, and names it in the ``cadkg.usecases`` entry-point group::

    [project.entry-points."cadkg.usecases"]
    mycell = "mycell:USE_CASE"

:mod:`cadkg.registry` finds it there; the five use cases cadkg ships are declared the same
way. Its ``mapping`` module registers the mappings of its records (``@map_record.register``);
the declaration names it (``mapping=``) and the build imports it before mapping a record, so
the declaration is all the core needs, and listing the use cases imports none of their readers.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any, Protocol

from cadkg.ingest.reader import Reader
from cadkg.services.display import Frame, MarkerSpec
from cadkg.services.service import Service
from cadkg.services.session import Session

__all__ = [
    "Answer",
    "Collector",
    "Derivation",
    "DerivedKind",
    "ExportOptions",
    "ExportView",
    "Planner",
    "Settings",
    "UseCase",
]


@dataclass(frozen=True)
class Answer:
    """The first fields of every service's result, which each transport shows as they are:
    whether the service could answer, and what it says (on ``success=False``, why not and what
    is known instead; a service answers an unknown name so rather than raising)."""

    success: bool
    message: str


class Collector(Protocol):
    """Sees a build's records as they are mapped, and gathers what the derivation needs."""

    complete: bool

    def add_edits(self, edits: Iterable[tuple[str, str]]) -> None: ...

    def source(self, rel: str) -> Callable[[object], None]: ...

    # Whether ``source``'s function needs ``record``: called where the file is read (a limited
    # child, on the collector as it was when the file's read began), only what it takes is
    # sent back.
    def wants(self, record: object) -> bool: ...

    def inputs(self) -> Any: ...


@dataclass(frozen=True)
class Settings:
    """The manifest's ``[derive]`` table, which the cell's derivation reads.

    A key not in ``keys`` is refused (naming them), so a misspelt setting cannot silently leave
    its default in force. ``read(table, fail)`` checks the values (``table`` is empty when the
    manifest has none) and gives the settings a collector finds in ``Manifest.derive``; on a bad
    value it raises ``fail(key, reason, found=..., expected=...)``, the manifest's error at that
    key's line. ``state(settings)`` gives the (ontology term, value) pairs the cell states, which
    an extraction reads back.
    """

    keys: frozenset[str]
    read: Callable[[Mapping[str, Any], Callable[..., Exception]], Any]
    state: Callable[[Any], Iterable[tuple[str, str | float]]] = lambda settings: ()


@dataclass(frozen=True)
class Derivation:
    """A model of the cell derived from its source graphs, written into a named graph of its own
    and kept as a file beside an on-disk store, so that reopening the store skips deriving.

    A build hands every record to ``collector(manifest)`` and derives from what it gathered
    while the store is still loading; after a change to the store the inputs are read back
    with ``extract(graph)``. Both must give the same inputs.
    """

    collector: Callable[[Any], Collector]
    extract: Callable[[Any], Any]
    derive: Callable[[Any], Any]
    graph: Callable[[Any], str]
    ntriples: Callable[[Any, str, Callable[[bytes], None] | None], bytes]
    dump: Callable[[Any], bytes]
    load: Callable[[bytes], Any]
    base: Callable[[Any], str] = lambda model: str(getattr(model, "base", ""))
    # ``adjust(inputs, settings)``: the inputs with some of the settings the manifest gave
    # replaced, as a served cell's parameters ask (the ROS node's ``approach_distance``).
    adjust: Callable[[Any, Mapping[str, Any]], Any] | None = None
    # The manifest's [derive] table; without, a manifest may not have one.
    settings: Settings | None = None
    # Also derives the cells of every use case that declares no derivation of its own; one
    # registered derivation may.
    default: bool = False
    # Kinds of things a revision diff compares that the model gives itself (below).
    things: Mapping[str, DerivedKind] = field(default_factory=dict)


@dataclass(frozen=True)
class DerivedKind:
    """A kind of thing a revision diff compares (:mod:`cadkg.changes.kinds`) that the derived
    model gives itself: ``read(model)`` is what the kind's first ``queries`` queries find in the
    graph written from it, read without querying it back (the placed pins and the wires' ends
    are most of a cabinet's rows); its other queries add their attributes as usual."""

    read: Callable[[Any], list[Any]]
    queries: int = 1


@dataclass(frozen=True)
class ExportOptions:
    """How ``cadkg export --view`` asks for a view: the modules of one variant, yEd graphics."""

    modules: tuple[str, ...] = ()
    yed: bool = False


ExportView = Callable[[Any, str, str | None, ExportOptions], Sequence[str]]
"""``view(graph, output, harness, options)``: writes one view of the graph (``cadkg export
--view``) and returns the warnings to show (an ambiguous name ...)."""


@dataclass(frozen=True)
class Planner:
    """How ``cadkg plan`` makes the robot's task list of a cell of this use case (docs/plan.md):
    ``tasks(graph, rules)`` gives a :class:`cadkg.plan.tasks.Problem`; ``rules`` is the default
    rules file."""

    rules: Traversable | Path
    tasks: Callable[[Any, Any], Any]
    # The ``[robot]`` settings ``tasks`` reads: any other key in a rules file is refused, so a
    # misspelt setting cannot silently leave its default in force.
    settings: frozenset[str] = frozenset()


@dataclass(frozen=True)
class UseCase:
    """A use case: the profile a manifest names (``[cell] profile``) and all it adds."""

    name: str
    title: str
    # The section of D3.1 that describes it ("4.1"); use cases are listed in this order.
    section: str = ""
    # The package it lives in (``package=__name__``): its ``queries`` and ``changes`` folders,
    # where it has them, are the folders of those fields unless they are given.
    package: str = ""
    readers: tuple[Reader, ...] = ()
    # Or the ``"module:attribute"`` naming them, imported when a command first needs the
    # services of this use case (the answers' modules are most of a command's start-up).
    services: tuple[Service, ...] | str = ()
    # A folder of named SPARQL queries (``.rq``, see cadkg.query.named).
    queries: Traversable | Path | None = None
    # Where the ROS node serves the services by default (``/gearbox_handler``).
    ros_namespace: str = ""
    derivation: Derivation | None = None
    # The use case's own static frames and markers, from a session on its graph.
    frames: Callable[[Session], Iterable[Frame]] | None = None
    markers: Callable[[Session, Path], Iterable[MarkerSpec]] | None = None
    # What it adds to the 3D workbench's scene: ``scene(graph, session, frames, out)`` appends
    # points of interest and routes to ``out["points"]`` and ``out["routes"]``, drawn in the
    # scene's ``frames`` (their names); a CadkgError leaves them out and is shown.
    scene: Callable[[Any, Session, set[str], dict[str, list[Any]]], None] | None = None
    views: Mapping[str, ExportView] = field(default_factory=dict)
    # Its own checks of a graph for ``cadkg validate``: ``checks(graph)`` gives
    # :class:`cadkg.query.validate.Finding` s (names one file gives and no other defines ...).
    checks: Callable[[Any], Iterable[Any]] | None = None
    # A folder of the kinds of things a revision diff compares (``.rq``, see cadkg.changes.kinds).
    changes: Traversable | Path | None = None
    # How the robot's task list is made (``cadkg plan``).
    planner: Planner | None = None
    # The module registering the mappings of its records (``"mycell.mapping"``), imported
    # before a build maps a record rather than with the declaration: it imports the record
    # classes, and so their readers. A use case may import it itself instead.
    mapping: str = ""

    def __post_init__(self) -> None:
        if not self.package:
            return
        root = resources.files(self.package)
        for name in ("queries", "changes"):
            folder = root.joinpath(name)
            if getattr(self, name) is None and folder.is_dir():
                object.__setattr__(self, name, folder)  # frozen: set once, while being made
