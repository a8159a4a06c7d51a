"""The request checks every request passes (pure ASGI, outermost first; design.md §9.2):

1. ``SecurityHeaders``: ``X-Frame-Options: DENY``, a Content-Security-Policy that allows only the
   product's own scripts (``script-src 'self'``, ``frame-ancestors 'none'``), ``nosniff``,
   ``Referrer-Policy: same-origin`` on every answer, errors included.
2. ``HostGuard``: Starlette's ``TrustedHostMiddleware`` (DNS rebinding): an unknown Host header is
   400 with the error envelope. Trusted: the loopback names and ``Settings.trusted_hosts``.
3. (``BodySizeLimit``, app/http_limits.py)
4. ``AccessGuard``: who is asking (``AccessService.resolve``), put into ``scope["state"]`` and the
   audit's context variable; the trainer serves only this computer; for every state-changing
   request the Origin rule, the JSON-only rule and whether a CSRF token is needed (below).
5. asgi-csrf (a maintained double-submit-cookie middleware): checks the token where 4. says one is
   needed: cookie ``csrftoken`` and the same value in the ``X-CSRFToken`` header (htmx: ``hx-headers``
   on ``<body>``) or the form field ``csrftoken`` (``ui.csrf_field()`` in native forms).

The CSRF rule for POST/PUT/PATCH/DELETE, the same with and without sign-in (trainer mode too):

- An ``Origin`` header must be this server's own origin (scheme://Host), else 403 ``cross_origin``;
  without Origin, a ``Referer`` must be of this origin, else 403. A browser sends Origin with every
  POST/PUT/DELETE, cross-site or not, so a foreign page's form (any enctype), fetch or htmx call is
  refused here and changes nothing.
- ``Authorization: Bearer`` requests need no CSRF token: a token is no ambient credential a browser
  attaches by itself.
- A request with neither Origin nor Referer needs no token either: it is no browser's. The Fetch
  standard has browsers add Origin to every request whose method is not GET/HEAD (as "null" where
  the origin is hidden), so a page can never make one without it; and a cross-origin JSON request
  would need a CORS preflight the HMI never grants. This keeps every non-browser client (httpx,
  curl, the test-suite's TestClient, a PLC gateway; JSON to the API, forms to the screens) working
  unchanged, in trainer mode and with a session cookie.
- Every other state-changing request, i.e. every one from a browser (it carries Origin or
  Referer), needs the CSRF token, else 403 ``csrf``: the HMI's own pages send it.
- ``/api/...`` accepts a body only as ``application/json`` (or ``+json``): 415
  ``unsupported_media_type`` otherwise, so an HTML form (urlencoded, multipart, text/plain) can never
  reach a JSON endpoint.
"""

from __future__ import annotations

import base64
import hashlib
import ipaddress
import json
import re
from urllib.parse import urlsplit

from starlette.middleware.trustedhost import TrustedHostMiddleware

from db import acting_as

from .identity import TRAINER
from .service import CSRF_COOKIE, AccessService

UNSAFE = frozenset({"POST", "PUT", "PATCH", "DELETE"})
LOOPBACK_NAMES = ("127.0.0.1", "localhost", "[::1]")
TEST_CLIENT = "testclient"           # Starlette's in-process TestClient (scope["client"]), Host "testserver"
DEFAULT_CSP = ("default-src 'self'; script-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data:; "
               "connect-src 'self'; font-src 'self' data:; object-src 'none'; base-uri 'none'; "
               "form-action 'self'; frame-ancestors 'none'")


def envelope_bytes(code: str, message: str, **extra) -> bytes:
    return json.dumps({"error": {"code": code, "message": message, **extra}}).encode()


async def send_error(send, status: int, code: str, message: str, headers: list | None = None) -> None:
    body = envelope_bytes(code, message)
    # HX-Reswap: an htmx page (which swaps 403 answers to show refusals) keeps its content
    await send({"type": "http.response.start", "status": status,
                "headers": [(b"content-type", b"application/json"), (b"content-length", str(len(body)).encode()),
                            (b"hx-reswap", b"none"), *(headers or [])]})
    await send({"type": "http.response.body", "body": body})


def csp_for_inline_scripts(html: str, extra: str = "") -> str:
    """The default policy plus the SHA-256 of each inline ``<script>`` of ``html`` (the docs pages
    FastAPI renders start Swagger UI with one): those scripts and the product's own files run,
    nothing else."""
    hashes = []
    for body in re.findall(r"<script(?![^>]*\bsrc=)[^>]*>(.*?)</script>", html, flags=re.S):
        digest = base64.b64encode(hashlib.sha256(body.encode()).digest()).decode()
        hashes.append(f"'sha256-{digest}'")
    policy = DEFAULT_CSP.replace("script-src 'self'", " ".join(["script-src 'self'", *hashes]))
    return policy + (f"; {extra}" if extra else "")


def is_local(client) -> bool:
    """The request comes from this computer (loopback), or from the in-process test client."""
    if not client:
        return True                      # no socket at all: in-process
    host = client[0]
    if host in (TEST_CLIENT, "localhost"):
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def is_loopback_host(host: str) -> bool:
    if host in ("localhost", "::1", "[::1]"):
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


class SecurityHeaders:
    HEADERS = ((b"x-frame-options", b"DENY"), (b"x-content-type-options", b"nosniff"),
               (b"referrer-policy", b"same-origin"), (b"cross-origin-opener-policy", b"same-origin"))

    def __init__(self, app):
        self.app = app

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)

        async def with_headers(message):
            if message["type"] == "http.response.start":
                headers = list(message.get("headers") or [])
                present = {k.lower() for k, _v in headers}
                headers += [(k, v) for k, v in self.HEADERS if k not in present]
                if b"content-security-policy" not in present:
                    headers.append((b"content-security-policy", DEFAULT_CSP.encode()))
                message = {**message, "headers": headers}
            await send(message)

        await self.app(scope, receive, with_headers)


class HostGuard:
    """Starlette's TrustedHostMiddleware, answering with the error envelope. The in-process test
    client's "testserver" is trusted only for requests that came through no socket."""

    def __init__(self, app, allowed_hosts: list[str]):
        self.app = app
        self.trusted = TrustedHostMiddleware(self._passed, allowed_hosts=allowed_hosts, www_redirect=False)

    async def _passed(self, scope, receive, send):
        scope["hmi.host_ok"] = True
        await self.app(scope, receive, send)

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        client = scope.get("client")
        if (client is None or client[0] == TEST_CLIENT) and _header(scope, b"host") in (b"testserver", None):
            return await self.app(scope, receive, send)

        async def guarded_send(message):
            if scope.get("hmi.host_ok"):
                await send(message)
            elif message["type"] == "http.response.start":      # Starlette's plain-text refusal
                await send_error(send, 400, "invalid_host",
                                 "unknown Host header: this HMI answers only to its trusted host names "
                                 "(--trusted-host, HMI_TRUSTED_HOSTS)")

        await self.trusted(scope, receive, guarded_send)


def _header(scope, name: bytes) -> bytes | None:
    for key, value in scope.get("headers") or ():
        if key == name:
            return value
    return None


def _origin_of(url: str) -> str | None:
    try:
        parts = urlsplit(url)
    except ValueError:
        return None
    if not parts.scheme or not parts.netloc:
        return None
    return _normal_origin(parts.scheme, parts.netloc)


def _normal_origin(scheme: str, netloc: str) -> str:
    scheme, netloc = scheme.lower(), netloc.lower()
    default = {"http": ":80", "https": ":443"}.get(scheme)
    if default and netloc.endswith(default):
        netloc = netloc[: -len(default)]
    return f"{scheme}://{netloc}"


def _content_type(scope) -> bytes:
    return (_header(scope, b"content-type") or b"").split(b";", 1)[0].strip().lower()


def _has_body(scope) -> bool:
    length = _header(scope, b"content-length")
    if length is not None:
        return length.strip() not in (b"", b"0")
    return _header(scope, b"transfer-encoding") is not None


def _is_json(content_type: bytes) -> bool:
    return content_type == b"application/json" or (content_type.startswith(b"application/")
                                                    and content_type.endswith(b"+json"))


def _has_cookie(scope, name: str) -> bool:
    cookie = _header(scope, b"cookie")
    return cookie is not None and re.search(rb"(?:^|;\s*)" + re.escape(name.encode()) + rb"=", cookie) is not None


class AccessGuard:
    def __init__(self, app, access: AccessService):
        self.app = app
        self.access = access

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            return await self.app(scope, receive, send)
        authorization = _header(scope, b"authorization")
        cookie = _header(scope, b"cookie")
        identity = self.access.resolve(authorization.decode("latin-1") if authorization else None,
                                       cookie.decode("latin-1") if cookie else None)
        scope.setdefault("state", {})["identity"] = identity
        if identity.kind == TRAINER and not is_local(scope.get("client")):
            return await send_error(send, 403, "trainer_local_only",
                                    "Trainer mode (no users) serves only this computer. Create a user "
                                    "(python -m app user add NAME --level L) to sign in from the network.")
        if scope["method"] in UNSAFE:
            refusal = self._check_write(scope, bearer=identity.kind == "token")
            if refusal is not None:
                return await send_error(send, *refusal)
        with acting_as(identity.actor):
            await self.app(scope, receive, send)

    def _check_write(self, scope, bearer: bool) -> tuple[int, str, str] | None:
        host = (_header(scope, b"host") or b"").decode("latin-1")
        served = _normal_origin(scope.get("scheme", "http"), host)
        origin = _header(scope, b"origin")
        referer = _header(scope, b"referer")
        if origin is not None:
            if _normal_origin_header(origin.decode("latin-1")) != served:
                return 403, "cross_origin", (f"cross-origin request refused: Origin {origin.decode('latin-1')} "
                                             f"is not {served}")
        elif referer is not None and _origin_of(referer.decode("latin-1")) != served:
            return 403, "cross_origin", "cross-origin request refused: the Referer is not this HMI"
        content_type = _content_type(scope)
        path = scope.get("path", "")
        root = scope.get("root_path", "")
        if root and path.startswith(root):
            path = path[len(root):]
        if (path == "/api" or path.startswith("/api/")) and _has_body(scope) and not _is_json(content_type):
            return 415, "unsupported_media_type", "the JSON API accepts only Content-Type: application/json"
        browser = origin is not None or referer is not None
        if bearer or not browser:
            scope["hmi.csrf_exempt"] = True
            return None
        if not _has_cookie(scope, CSRF_COOKIE):
            return 403, "csrf", "CSRF token missing: reload the page"
        return None


def _normal_origin_header(origin: str) -> str | None:
    if origin.strip().lower() == "null":
        return None
    return _origin_of(origin)


async def csrf_failed(scope, send, message_id) -> None:
    """asgi-csrf's refusal, as the error envelope."""
    await send_error(send, 403, "csrf", "CSRF token missing or wrong: reload the page")


def csrf_exempt(scope) -> bool:
    return bool(scope.get("hmi.csrf_exempt"))
