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
