from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest

import cadkg
from tests.server.serving import serving


@pytest.fixture(scope="module")
def url(iema: cadkg.KnowledgeGraph) -> Iterator[str]:
    """The IEMA example served read-only with the default limits."""
    with serving(iema) as base:
        yield base


@pytest.fixture(scope="session")
def browser(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Any]:
    """Headless Chromium (see tests/server/browser.py); downloads go to ``browser.downloads``."""
    from tests.server.browser import chromium

    downloads = tmp_path_factory.mktemp("downloads")
    with chromium(downloads) as driver:
        driver.downloads = downloads
        yield driver


@pytest.fixture(scope="session")
def iema_site() -> Iterator[str]:
    """``cadkg serve`` on the IEMA example's manifest, in a process of its own."""
    from tests.conftest import IEMA
    from tests.server.serving import cadkg_serve

    with cadkg_serve(str(IEMA)) as base:
        yield base
