"""Every service by name (the operations every cell offers, :mod:`cadkg.services.operations`,
and every use case's), and :func:`call`, which runs one: what the CLI, the HTTP endpoint and
the ROS adapter call.

``call(session, "cad_service", {"label": "F1500.1"})`` runs one service; parameters that
arrive as text are converted to the service's types here, so every transport gets the same
checks and messages.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

import cadkg.registry as registry
from cadkg.errors import QueryError, RegistryError
from cadkg.services.service import CONVERT, Service
from cadkg.services.session import Session

__all__ = ["SERVICES", "call", "find", "served_for", "services_for"]


_MERGED: tuple[object, dict[str, Service]] | None = None


def _without_operations(declared: Mapping[str, Service]) -> None:
    """Raises RegistryError when a use case names a service as one of the operations."""
    from cadkg.services.operations import OPERATIONS

    taken = sorted(set(OPERATIONS) & set(declared))
    if taken:
        raise RegistryError(f"services {', '.join(taken)} are operations every cell offers")


def _table() -> dict[str, Service]:
    """The operations and the registry's services (importing every use case's), merged once
    per state of the registry.

    Raises
    ------
    RegistryError
        When a use case names a service as one of the operations every cell offers.
    """
    global _MERGED
    if _MERGED is not None and _MERGED[0] == registry.loaded():
        return _MERGED[1]
    from cadkg.services.operations import OPERATIONS

    declared = registry.services()
    _without_operations(declared)
    merged = {**OPERATIONS, **declared}
    _MERGED = (registry.loaded(), merged)
    return merged


def find(name: str, profile: str = "") -> Service | None:
    """Service ``name`` as a cell of ``profile`` finds it: one of the operations, or of its use
    case's services (importing only those), else of any use case's; None when there is none.

    Raises
    ------
    RegistryError
        When a use case names a service as one of the operations every cell offers.
    """
    from cadkg.services.operations import OPERATIONS

    return OPERATIONS.get(name) or _own(profile).get(name) or _table().get(name)


_OWN: dict[str, tuple[object, dict[str, Service]]] = {}


def _own(profile: str) -> dict[str, Service]:
    """The services of ``profile``'s use case, checked against the operations once per state of
    the registry: every call of every transport looks its service up here."""
    own = _OWN.get(profile)
    if own is not None and own[0] == registry.loaded():
        return own[1]
    services = registry.services_of(profile)
    _without_operations(services)
    # Keyed after the read: reading a use case's services is itself a change of the registry.
    _OWN[profile] = (registry.loaded(), services)
    return services


class _Services(Mapping[str, Service]):
    """Every service by name, read when first looked at."""

    def __getitem__(self, name: str) -> Service:
        return _table()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(_table())

    def __len__(self) -> int:
        return len(_table())


SERVICES: Mapping[str, Service] = _Services()


def services_for(profile: str) -> list[Service]:
    """The services of one use case (``""``: the default profile)."""
    return list(registry.services_of(profile).values())


def served_for(profile: str) -> list[Service]:
    """What a transport serves a cell of ``profile``: the operations every cell offers, then
    the use case's own services."""
    from cadkg.services.operations import OPERATIONS

    return [*OPERATIONS.values(), *services_for(profile)]


def call(session: Session, name: str, params: Mapping[str, str | Any], client: str = "default") -> Any:
    """Run service ``name``; text parameters are converted to the service's types.

    Raises
    ------
    QueryError
        On an unknown service, a missing, unknown or malformed parameter.
    """
    service = find(name, session.profile)
    if service is None:
        raise QueryError(f"unknown service {name!r}; known: {', '.join(sorted(_table()))}")
    unknown = set(params) - set(service.params)
    if unknown:
        raise QueryError(
            f"{name}: unknown parameter {', '.join(sorted(unknown))}; "
            f"parameters: {', '.join(service.params) or 'none'}"
        )
    missing = [p for p in service.params if p not in params and p not in service.optional]
    if missing:
        raise QueryError(f"{name}: missing parameter {', '.join(missing)}")
    values = {
        key: CONVERT[service.params[key]](value) if isinstance(value, str) else value
        for key, value in params.items()
    }
    if service.effect.changes:
        return service.run(session, client=client, **values)
    with session.reading(name):
        return service.run(session, client=client, **values)
