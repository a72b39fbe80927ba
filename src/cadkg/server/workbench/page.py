"""The web page: the bundle built from ``web/`` into ``static/dist``, and the favicon.

The bundle is built when cadkg is set up (``scripts/setup.sh`` runs ``npm ci`` and Vite), not
at run time and not from the internet; it holds the third-party editor and 3D code, so it is
not part of the source tree. Without it ``/`` answers 503 with a page saying how to build it,
and ``cadkg serve`` says so when it starts, while the SPARQL endpoint and the JSON API work
as before.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any

from starlette.responses import FileResponse, HTMLResponse, Response

__all__ = ["DIST", "STATIC", "bundle_missing", "favicon", "page"]

STATIC = Path(__file__).resolve().parents[1] / "static"
DIST = STATIC / "dist"
_BUILD = (
    "build it from a cadkg source checkout with <code>bash scripts/setup.sh</code> "
    "(needs Node.js 20 or later and npm; or <code>cd web &amp;&amp; npm ci &amp;&amp; npm run build</code>), "
    "then install cadkg again if it was installed from that checkout without <code>-e</code>"
)


def bundle_missing() -> str | None:
    """Why the page cannot be served (one line), or None when its bundle is there."""
    if (DIST / "index.html").is_file():
        return None
    return f"the web page is not built ({DIST / 'index.html'} is missing); run: bash scripts/setup.sh"


async def page(request: Any) -> Response:
    """``GET /``: the built page, or a short page saying how to build it."""
    if bundle_missing() is None:
        return FileResponse(DIST / "index.html", media_type="text/html; charset=utf-8")
    body = (
        "<!doctype html><html lang=en><meta charset=utf-8><title>cadkg: page not built</title>"
        "<h1>The web page of this cadkg is not built</h1>"
        f"<p>{html.escape(str(DIST))} holds no <code>index.html</code>: {_BUILD}.</p>"
        "<p>The SPARQL endpoint (<a href=/sparql>/sparql</a>) and the JSON API "
        "(<a href=/api>/api</a>) work without it.</p></html>"
    )
    return HTMLResponse(body, 503)


async def favicon(request: Any) -> Response:
    """``GET /favicon.ico``."""
    return FileResponse(STATIC / "favicon.ico", media_type="image/x-icon")
