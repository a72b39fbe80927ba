"""Every use case's services by name, and :func:`call`, which runs one: what the CLI, the
HTTP endpoint and the ROS adapter call.

``call(session, "cad_service", {"label": "F1500.1"})`` runs one service; parameters that
arrive as text are converted to the service's types here, so every transport gets the same
checks and messages.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

import cadkg.registry as registry
from cadkg.errors import QueryError
from cadkg.services.service import CONVERT, Service
from cadkg.services.session import Session

__all__ = ["SERVICES", "call", "services_for"]


class _Services(Mapping[str, Service]):
    """The registry's services, read when first looked at (registering loads every use case)."""

    def __getitem__(self, name: str) -> Service:
        return registry.services()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(registry.services())

    def __len__(self) -> int:
        return len(registry.services())


SERVICES: Mapping[str, Service] = _Services()


def services_for(profile: str) -> list[Service]:
    """The services of one use case (``""``: the default profile)."""
    wanted = profile or registry.DEFAULT_PROFILE
    return [s for s in registry.services().values() if s.profile == wanted]


def call(session: Session, name: str, params: Mapping[str, str | Any], client: str = "default") -> Any:
    """Run service ``name``; text parameters are converted to the service's types.

    Raises
    ------
    QueryError
        On an unknown service, a missing, unknown or malformed parameter.
    """
    known = registry.services()
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
