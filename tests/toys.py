"""Plug-ins made in tests: a derivation that derives nothing, whose other parts a test sets."""

from __future__ import annotations

from typing import Any

from cadkg.usecase import Derivation

__all__ = ["toy_derivation"]


def _nothing(*_: object) -> None:
    return None


def toy_derivation(**fields: Any) -> Derivation:
    """A :class:`Derivation` whose every hook gives None, with ``fields`` (``default``, ``settings`` ...)."""
    return Derivation(_nothing, _nothing, _nothing, _nothing, _nothing, _nothing, _nothing, **fields)
