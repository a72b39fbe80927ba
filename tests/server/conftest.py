from __future__ import annotations

from collections.abc import Iterator

import pytest

import cadkg
from tests.server.serving import serving


@pytest.fixture(scope="module")
def url(iema: cadkg.KnowledgeGraph) -> Iterator[str]:
    """The IEMA example served read-only with the default limits."""
    with serving(iema) as base:
        yield base


@pytest.fixture(scope="session")
def iema_site() -> Iterator[str]:
    """``cadkg serve`` on the IEMA example's manifest, in a process of its own."""
    from tests.conftest import IEMA
    from tests.server.serving import cadkg_serve

    with cadkg_serve(str(IEMA)) as base:
        yield base
