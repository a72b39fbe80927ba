"""What a command or a transport names as its cell: a store directory, a manifest, or the URL
of a remote SPARQL endpoint. Every transport opens it here, so all three take the same
targets and refuse a wrong one with the same message."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cadkg.errors import CadkgError

if TYPE_CHECKING:
    from cadkg.graph import KnowledgeGraph
    from cadkg.remote import Auth

__all__ = ["TargetError", "model_with", "open_target"]


class TargetError(CadkgError):
    """A target that is neither a store directory, a manifest nor an http(s) URL."""


def open_target(
    target: str | Path,
    *,
    writable: bool = False,
    local: bool = False,
    auth: Auth | None = None,
    timeout: float | None = None,
    warn: Callable[[str], None] | None = None,
) -> KnowledgeGraph:
    """Open ``target``: a store directory (read-only unless ``writable``: then changes such as
    an assignment are kept in it as new generations), a manifest built in memory (its readers'
    warnings handed to ``warn``), or a remote endpoint asked with ``auth`` (else the
    credentials of ``CADKG_STORE_AUTH[_DIGEST]``) and ``timeout`` when given; ``local``
    refuses a URL (a command that works on local files).

    Raises
    ------
    TargetError
        When ``target`` is none of these.
    CadkgError
        When the store, the manifest or the endpoint cannot be read.
    """
    from cadkg.graph import KnowledgeGraph
    from cadkg.remote import DEFAULT_TIMEOUT, RemoteGraph, auth_from_env, is_url

    neither = TargetError(f"{str(target)!r} is neither a store directory nor a manifest file")
    if is_url(target) and local:
        raise neither
    if is_url(target):
        credentials = auth if auth is not None else auth_from_env()
        seconds = DEFAULT_TIMEOUT if timeout is None else timeout
        return RemoteGraph(str(target), auth=credentials, timeout=seconds)
    path = Path(target)
    if path.is_dir():
        return KnowledgeGraph.open(path, read_only=not writable)
    if path.is_file():
        kg = KnowledgeGraph.build(path)
        if warn is not None:
            for report in kg.reports:
                for warning in report.warnings:
                    warn(str(warning))
        return kg
    raise neither


def model_with(settings: Mapping[str, float]) -> Callable[[KnowledgeGraph], Any]:
    """The cell model of a graph derived with ``settings`` instead of the manifest's (the ROS
    node's ``approach_distance``): what a holder takes as its ``model``.

    The model it gives raises :class:`CadkgError` for a cell whose derivation takes no settings.
    """

    def derive(kg: KnowledgeGraph) -> Any:
        import cadkg.registry as registry
        from cadkg.store import cell_profile

        profile = cell_profile(kg)
        derivation = registry.derivation(profile)
        if derivation is None:
            return kg.cell_model()
        if derivation.adjust is None:
            raise CadkgError(
                f"the cell model of a {profile or 'default'} cell takes no {', '.join(settings)}"
            )
        return derivation.derive(derivation.adjust(derivation.extract(kg), dict(settings)))

    return derive
