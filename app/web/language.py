"""Which language a screen request is answered in (design.md §9.9), and the middleware that makes
it current (``app.i18n``) for the request.

Order: ``?lang=en|de|zh`` (remembered for this browser in the cookie ``hmi_lang``), then that
cookie, then the setting ``language`` (General; ``auto`` = ask the browser), then the browser's
``Accept-Language``, else English. The JSON API (``/api/...``) always answers in English: its
messages are a contract for programs, which translate by the error ``code``.
"""

from __future__ import annotations

from http.cookies import CookieError, SimpleCookie
from urllib.parse import parse_qs

from app.i18n import DEFAULT_LANGUAGE, LANGUAGES, reset_language, set_language
from db.database import StorageUnavailable

COOKIE = "hmi_lang"
COOKIE_MAX_AGE = 365 * 24 * 3600
ENGLISH_ONLY = ("api", "static")      # first path segments answered in English


def from_accept_language(header: str) -> str | None:
    """The first supported language of an ``Accept-Language`` header by its q values
    (``zh-CN,zh;q=0.9,en;q=0.8`` -> zh), or None."""
    ranked = []
    for position, part in enumerate(header.split(",")):
        tag, _, params = part.strip().partition(";")
        quality = 1.0
        if params.strip().startswith("q="):
            try:
                quality = float(params.strip()[2:])
            except ValueError:
                quality = 0.0
        primary = tag.strip().lower().split("-")[0]
        if quality > 0 and primary in LANGUAGES:
            ranked.append((-quality, position, primary))
    return min(ranked)[2] if ranked else None


def choose(query_lang: str | None, cookie_lang: str | None, setting: str | None,
           accept_language: str | None) -> str:
    """The language by the rule of this module's docstring."""
    for candidate in (query_lang, cookie_lang):
        if candidate in LANGUAGES:
            return candidate
    if setting in LANGUAGES:
        return setting
    return from_accept_language(accept_language or "") or DEFAULT_LANGUAGE


def _header(scope, name: bytes) -> str:
    for key, value in scope.get("headers") or ():
        if key == name:
            return value.decode("latin-1")
    return ""


def _setting(scope) -> str | None:
    app = scope.get("app")
    try:
        return app.state.services.settings.get().language
    except (AttributeError, StorageUnavailable):   # no app state (the middleware alone), or no storage
        return None


class LanguageMiddleware:
    """Pure ASGI: sets the request's language (``scope["state"]["language"]`` and ``app.i18n``);
    a valid ``?lang`` is remembered with a ``Set-Cookie`` on the answer."""

    def __init__(self, app):
        self.app = app

    async def __call__(self, scope, receive, send):
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return
        chosen = None
        if scope.get("path", "").lstrip("/").partition("/")[0] in ENGLISH_ONLY:
            lang = DEFAULT_LANGUAGE
        else:
            query = parse_qs(scope.get("query_string", b"").decode("latin-1"))
            chosen = (query.get("lang") or [None])[0]
            chosen = chosen if chosen in LANGUAGES else None
            cookies = SimpleCookie()
            try:
                cookies.load(_header(scope, b"cookie"))
            except CookieError:         # a malformed Cookie header: no cookie language
                pass
            cookie_lang = cookies[COOKIE].value if COOKIE in cookies else None
            lang = choose(chosen, cookie_lang, _setting(scope), _header(scope, b"accept-language"))
            if chosen == cookie_lang:
                chosen = None               # already remembered
        scope.setdefault("state", {})["language"] = lang
        token = set_language(lang)

        async def send_with_cookie(message):
            if chosen and message["type"] == "http.response.start":
                cookie = f"{COOKIE}={chosen}; Path=/; Max-Age={COOKIE_MAX_AGE}; SameSite=Strict"
                message = {**message, "headers": [*message.get("headers", []),
                                                  (b"set-cookie", cookie.encode("latin-1"))]}
            await send(message)

        try:
            await self.app(scope, receive, send_with_cookie)
        finally:
            reset_language(token)
