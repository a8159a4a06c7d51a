"""Answers to 401/403 of the access checks: the error envelope for the JSON API (with the level
needed), a redirect to the sign-in screen or the message line for the screens."""

from __future__ import annotations

from urllib.parse import quote

from fastapi import FastAPI, Request
from fastapi.responses import HTMLResponse, JSONResponse, RedirectResponse

from app.errors import envelope

from .errors import AccessDenied, Unauthenticated


def is_api(request: Request) -> bool:
    path = request.url.path[len(request.scope.get("root_path", "").rstrip("/")):]
    return path == "/api" or path.startswith("/api/")


def _htmx(request: Request) -> bool:
    return request.headers.get("HX-Request") == "true"


def signin_url(request: Request, next_path: str | None = None) -> str:
    from app.web.templating import url_path

    target = url_path(request, "signin_screen")
    return f"{target}?next={quote(next_path, safe='/')}" if next_path else target


def install_access_handlers(app: FastAPI) -> None:
    @app.exception_handler(Unauthenticated)
    async def _unauthenticated(request: Request, exc: Unauthenticated):
        if is_api(request):
            return JSONResponse(envelope(exc.code, exc.message), status_code=401,
                                headers={"WWW-Authenticate": "Bearer"})
        here = request.url.path + (f"?{request.url.query}" if request.url.query else "")
        if _htmx(request):
            current = request.headers.get("HX-Current-URL", "")
            return HTMLResponse("", status_code=401, headers={"HX-Redirect": signin_url(request, _path_of(current))})
        if request.method == "GET":
            return RedirectResponse(signin_url(request, here), status_code=303)
        return HTMLResponse("Sign in first.", status_code=401)

    @app.exception_handler(AccessDenied)
    async def _denied(request: Request, exc: AccessDenied):
        if is_api(request):
            body = envelope(exc.code, exc.message)
            body["error"].update({"required_level": exc.required, "function": exc.function})
            return JSONResponse(body, status_code=403)
        from app.web.templating import render_block

        response = render_block(request, "base.html", "message", {"message": exc.message, "level": "error"},
                                status_code=403, headers={"HX-Reswap": "none"})
        if not _htmx(request):
            return HTMLResponse(f"<!doctype html><title>Access level</title><p>{_escape(exc.message)}</p>",
                                status_code=403)
        return response


def _path_of(url: str) -> str | None:
    from urllib.parse import urlsplit

    parts = urlsplit(url)
    return parts.path + (f"?{parts.query}" if parts.query else "") if parts.path else None


def _escape(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
