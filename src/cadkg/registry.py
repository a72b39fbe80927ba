"""The one registry: every format cadkg reads and every use case it serves.

The formats no use case owns come from :mod:`cadkg.ingest.formats`; use cases, with their own
readers, services, named queries, ROS names and derivation, from the ``cadkg.usecases``
entry-point group (see :mod:`cadkg.usecase`). The five use cases cadkg ships are found there
like any other package's, so adding a use case is adding a folder (or a package) and one
entry-point line. Everything is loaded on first use, once.
"""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Iterable
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import TYPE_CHECKING

from cadkg.errors import IngestError, RegistryError
from cadkg.ingest.formats import READERS
from cadkg.ingest.reader import Reader
from cadkg.services.service import Effect, Service
from cadkg.usecase import Derivation, Settings, UseCase

if TYPE_CHECKING:
    from importlib.metadata import EntryPoint

__all__ = [
    "DEFAULT_PROFILE",
    "ENTRY_POINT_GROUP",
    "add_use_case",
    "derivation",
    "derive_settings",
    "kinds",
    "load_mappings",
    "query_folders",
    "reader_for",
    "register",
    "services",
    "services_of",
    "sniff_kind",
    "use_case",
    "use_cases",
]

ENTRY_POINT_GROUP = "cadkg.usecases"
# The profile of a cell whose manifest names none: the cabinet of D3.1's first use case.
DEFAULT_PROFILE = "iema"


class _Table:
    def __init__(self) -> None:
        self.readers: dict[str, Reader] = {}
        self.use_cases: dict[str, UseCase] = {}
        self.services: dict[str, Service] = {}
        # The services of each use case not yet in ``services``, in the order the use cases were
        # added (a name clash names the later one): the tuple, or the ``"module:attribute"``
        # naming it, imported when first needed.
        self.unread: dict[str, tuple[Service, ...] | str] = {}
        # Moves with every use case added: what a cache made from the table is keyed on.
        self.changes = 0
        self.derivations: dict[str, Derivation] = {}
        # The derivation of the cells whose use case declares none (Derivation.default).
        self.default: tuple[str, Derivation] | None = None


_TABLE: _Table | None = None


def _table() -> _Table:
    global _TABLE
    if _TABLE is None:
        # Reading the installed packages' metadata takes a few hundredths of a second: on first use.
        from importlib.metadata import entry_points

        table = _Table()
        for reader in READERS:
            _add_reader(table, reader)
        for entry in sorted(entry_points(group=ENTRY_POINT_GROUP), key=lambda e: e.name):
            _add(table, _load(entry))
        _TABLE = table
    return _TABLE


def _load(entry: EntryPoint) -> UseCase:
    try:
        found = entry.load()
    except Exception as err:  # a third party's package: say which one failed, and how
        raise RegistryError(f"use case {entry.name!r} ({entry.value}) cannot be loaded: {err}") from err
    if not isinstance(found, UseCase):
        raise RegistryError(f"use case {entry.name!r} ({entry.value}) is not a cadkg.usecase.UseCase")
    return found


def _add_reader(table: _Table, reader: Reader) -> None:
    if reader.kind in table.readers:
        raise RegistryError(f"reader kind {reader.kind!r} is already registered")
    table.readers[reader.kind] = reader


def _add(table: _Table, case: UseCase) -> None:
    if case.name in table.use_cases:
        raise RegistryError(f"use case {case.name!r} is already registered")
    for reader in case.readers:
        _add_reader(table, reader)
    table.unread[case.name] = case.services
    if case.derivation is not None and case.derivation.default:
        if table.default is not None:
            raise RegistryError(
                f"use cases {table.default[0]} and {case.name} both derive the cell model of every "
                "other cell; one may"
            )
        table.default = (case.name, case.derivation)
    if case.derivation is not None:
        table.derivations[case.name] = case.derivation
    table.use_cases[case.name] = case
    table.changes += 1


def _add_services(table: _Table, name: str, declared: Iterable[Service]) -> None:
    for service in declared:
        if not isinstance(service.effect, Effect):
            raise RegistryError(
                f"service {service.name!r} of {name} declares no Effect (what a call changes)"
            )
        if service.name in table.services:
            owner = table.services[service.name].profile
            raise RegistryError(f"service {service.name!r} of {name} is already one of {owner}'s")
        table.services[service.name] = dataclasses.replace(service, profile=name)


def _read_services(table: _Table, name: str) -> None:
    """Add the services of use case ``name`` to the table, importing them when they are named."""
    spec = table.unread.pop(name, None)
    if spec is None:
        return
    from cadkg.ingest.reader import resolve

    declared = resolve(spec) if isinstance(spec, str) else spec
    if not isinstance(declared, tuple) or not all(isinstance(s, Service) for s in declared):
        raise RegistryError(f"services {spec!r} of {name} are not a tuple of cadkg.services.service.Service")
    _add_services(table, name, declared)
    table.changes += 1


def add_use_case(case: UseCase) -> None:
    """Register a use case that no entry point names (a notebook's, a test's)."""
    _add(_table(), case)


def register(reader: Reader) -> Reader:
    """Add a reader of a format outside any use case; a kind may be registered once."""
    _add_reader(_table(), reader)
    return reader


def use_cases() -> list[UseCase]:
    """Every registered use case: those of D3.1 in the order of its sections, then the others by name."""
    return sorted(_table().use_cases.values(), key=lambda c: (not c.section, c.section, c.name))


def use_case(profile: str) -> UseCase:
    """The use case of a cell's profile (``""``: :data:`DEFAULT_PROFILE`).

    Raises
    ------
    KeyError
        With the known profiles.
    """
    cases = _table().use_cases
    try:
        return cases[profile or DEFAULT_PROFILE]
    except KeyError:
        raise KeyError(f"unknown profile {profile!r}; known: {', '.join(sorted(cases))}") from None


def loaded() -> object:
    """The registry's table as loaded now: what a cache of something made from it is keyed on
    (a test may load the registry afresh, a notebook add a use case)."""
    table = _table()
    return (table, table.changes)


def services() -> dict[str, Service]:
    """Every service of every use case, by name (importing every use case's services)."""
    table = _table()
    for name in list(table.unread):
        _read_services(table, name)
    return dict(table.services)


def services_of(profile: str) -> dict[str, Service]:
    """The services of one use case (``""``: :data:`DEFAULT_PROFILE`), by name, importing only
    that use case's: a command on one cell does not import every use case's answers. An
    unknown profile has none."""
    table = _table()
    wanted = profile or DEFAULT_PROFILE
    _read_services(table, wanted)
    return {name: s for name, s in table.services.items() if s.profile == wanted}


def derivation(profile: str) -> Derivation | None:
    """The derivation of the cell model of a cell of ``profile`` (``""``: :data:`DEFAULT_PROFILE`):
    its use case's own, else the one declared the default (the cabinet geometry places any
    cell's components at their items), else None. An unknown profile gets the default."""
    table = _table()
    own = table.derivations.get(profile or DEFAULT_PROFILE)
    if own is not None:
        return own
    return table.default[1] if table.default is not None else None


def derive_settings(profile: str) -> Settings | None:
    """The settings (the manifest's ``[derive]`` table) of the derivation of a cell of ``profile``."""
    found = derivation(profile)
    return found.settings if found is not None else None


def load_mappings() -> None:
    """Import every use case's mapping module (see :attr:`cadkg.usecase.UseCase.mapping`),
    so that each record a reader gives has its mapping registered."""
    for case in use_cases():
        if case.mapping:
            importlib.import_module(case.mapping)


def query_folders() -> list[Traversable | Path]:
    """The folders of the use cases' named queries."""
    return [c.queries for c in use_cases() if c.queries is not None]


def kinds() -> list[Reader]:
    """Every registered reader, sorted by kind."""
    return sorted(_table().readers.values(), key=lambda r: r.kind)


def reader_for(kind: str) -> Reader:
    """The reader registered for ``kind``; raises KeyError with the known kinds."""
    readers = _table().readers
    try:
        return readers[kind]
    except KeyError:
        raise KeyError(f"unknown kind {kind!r}; known kinds: {', '.join(sorted(readers))}") from None


def sniff_kind(path: str | Path, head: bytes | None = None, profile: str = "") -> str:
    """The kind of a file from its suffix, or from its first bytes when the suffix is shared.

    A reader of the cell's use case (``profile``) that claims a shared suffix without a sniffer
    takes it in that use case's cells (an ELVEZ cell reads its ``.x3d`` and ``.wri`` files as
    platform files). Otherwise, when no reader's sniffer claims a file whose suffix several
    readers share, the reader of that suffix without a sniffer decides: the one of the cell's
    use case before the core one.

    Raises
    ------
    IngestError
        When no reader claims the file.
    """
    table = _table()
    readers: Iterable[Reader] = table.readers.values()
    suffix = Path(path).suffix.lower()
    candidates = [r for r in readers if suffix in r.suffixes]
    if len(candidates) == 1:
        return candidates[0].kind
    # A use case that reads a shared suffix without asking the content (ELVEZ's .wri and .x3d)
    # takes that suffix in its own cells, whatever a core reader's sniffer would say.
    case = table.use_cases.get(profile) if profile else None
    own = [r for r in candidates if not r.sniffs() and case is not None and r in case.readers]
    if len(own) == 1:
        return own[0].kind
    if head is None:
        try:
            with Path(path).open("rb") as handle:
                head = handle.read(16384)
        except OSError as err:
            raise IngestError(path, f"cannot read the file: {err.strerror}") from err
        except ValueError:  # a NUL byte in a path given by a service caller
            raise IngestError(repr(str(path)), "cannot read the file: a NUL byte in its name") from None
    # The workbook and text sniffing (lxml, the XLS container) only when content must decide.
    from cadkg.ingest.sheet import sniff_head
    from cadkg.ingest.text import sniffable_head

    head = sniff_head(path, sniffable_head(head))
    sniffed = [r for r in candidates or readers if r.sniff is not None and r.sniff(head)]
    if len(sniffed) == 1:
        return sniffed[0].kind
    if not sniffed:
        fallback = _fallback(table, [r for r in candidates if not r.sniffs()], profile)
        if fallback is not None:
            return fallback.kind
    names = ", ".join(r.kind for r in kinds())
    raise IngestError(
        path,
        "cannot tell the kind of this file from its suffix or content",
        found=suffix or "no suffix",
        expected=f"a 'kind' in the manifest, one of: {names}",
    )


def _fallback(table: _Table, unsniffed: list[Reader], profile: str) -> Reader | None:
    case = table.use_cases.get(profile or DEFAULT_PROFILE)
    own = {r.kind for r in case.readers} if case is not None else set()
    others = {r.kind for c in table.use_cases.values() for r in c.readers}
    for chosen in ([r for r in unsniffed if r.kind in own], [r for r in unsniffed if r.kind not in others]):
        if len(chosen) == 1:
            return chosen[0]
    return None
