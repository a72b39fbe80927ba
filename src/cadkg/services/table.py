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

__all__ = ["SERVICES", "call", "served_for", "services_for"]


_MERGED: tuple[object, dict[str, Service]] | None = None


def _table() -> dict[str, Service]:
    """The operations and the registry's services (registering loads every use case), merged
    once per loaded registry.

    Raises
    ------
    RegistryError
        When a use case names a service as one of the operations every cell offers.
    """
    global _MERGED
    source = registry.loaded()
    if _MERGED is not None and _MERGED[0] is source:
        return _MERGED[1]
    from cadkg.services.operations import OPERATIONS

    declared = registry.services()
    taken = sorted(set(OPERATIONS) & set(declared))
    if taken:
        raise RegistryError(f"services {', '.join(taken)} are operations every cell offers")
    merged = {**OPERATIONS, **declared}
    _MERGED = (source, merged)
    return merged


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
    wanted = profile or registry.DEFAULT_PROFILE
    return [s for s in registry.services().values() if s.profile == wanted]


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
    known = _table()
    service = known.get(name)
    if service is None:
        raise QueryError(f"unknown service {name!r}; known: {', '.join(sorted(known))}")
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
