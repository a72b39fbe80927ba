"""The HTTP side of cadkg: a SPARQL 1.1 Protocol endpoint, the services as JSON, and a web page.

Start it with ``cadkg serve STORE_OR_MANIFEST`` or build the ASGI app with :func:`create_app`.
"""

from __future__ import annotations

from cadkg.server.app import create_app, serve
from cadkg.server.context import Settings
from cadkg.server.limits import Limits

__all__ = ["Limits", "Settings", "create_app", "serve"]
