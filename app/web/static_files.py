"""The vendored and own static files, named by their content's version.

A page names a static file as ``/static/hmi.js?v=<version>`` (``url_path``): the browser keeps that
file for a year and asks for it again only when a new release changes its content, and with it the
name. A file asked for without its current version (a link inside a vendored bundle, an older page)
is revalidated each time, as before. Changing screens then loads the page and its live data only,
not eight files again (each through every request check)."""

from __future__ import annotations

import hashlib
from functools import lru_cache
from pathlib import Path

from starlette.responses import Response
from starlette.staticfiles import StaticFiles
from starlette.types import Scope

STATIC_DIR = Path(__file__).resolve().parents[2] / "static"
KEPT = "public, max-age=31536000, immutable"
ASK_AGAIN = "no-cache"


@lru_cache(maxsize=512)
def static_version(path: str) -> str:
    """The first 12 hex digits of the SHA-256 of ``static/<path>``; "" for a file that is not there
    (the link then answers 404 as before). Files change only with a release: read once."""
    file = (STATIC_DIR / path).resolve()
    if not file.is_relative_to(STATIC_DIR) or not file.is_file():
        return ""
    return hashlib.sha256(file.read_bytes()).hexdigest()[:12]


def versioned(path: str) -> str:
    """``path`` with its version as the query (``hmi.js`` → ``hmi.js?v=…``)."""
    version = static_version(path)
    return f"?v={version}" if version else ""


class VersionedStaticFiles(StaticFiles):
    """StaticFiles whose answers say how long the browser may keep them (see the module)."""

    async def get_response(self, path: str, scope: Scope) -> Response:
        response = await super().get_response(path, scope)
        if response.status_code in (200, 304):
            asked = scope.get("query_string", b"").decode("latin-1")
            current = static_version(path)
            response.headers["Cache-Control"] = KEPT if current and asked == f"v={current}" else ASK_AGAIN
        return response
