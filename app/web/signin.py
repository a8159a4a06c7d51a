"""Sign-in screen (design.md §9.2): user + password, or the operator panel (keyswitch level) on the
machine's own computer; sign-out. A plain HTML form with the CSRF field, so it works without htmx."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Request, Response
from fastapi.concurrency import run_in_threadpool
from fastapi.responses import RedirectResponse

from app.access.deps import identity_of
from app.access.levels import keyswitch_level
from app.access.middleware import is_local
from app.access.service import SESSION_COOKIE
from app.api.access import clear_session_cookie, refuse_at_once, set_session_cookie, sign_in
from app.errors import HmiError

from .templating import templates, url_path

router = APIRouter()


def _safe_next(request: Request, target: str | None) -> str:
    """Only a path of this HMI (never another site, never //host)."""
    if target and target.startswith("/") and not target.startswith("//") and "\\" not in target:
        return target
    return url_path(request, "jog_screen")


def _page(request: Request, next_path: str, error: str = "", user: str = "", status_code: int = 200,
          headers: dict | None = None):
    access = request.app.state.access
    panel_allowed = is_local(request.scope.get("client"))
    position = access.keyswitch() if panel_allowed else 0      # read only where the panel form shows
    return templates.TemplateResponse(request, "signin.html", {
        "next": next_path, "error": error, "user": user, "identity": identity_of(request),
        "signin_on": access.signin_on(), "panel_allowed": panel_allowed,
        "keyswitch": position, "keyswitch_level": keyswitch_level(position)},
        status_code=status_code, headers=headers)


@router.get("/signin", name="signin_screen")
def signin_screen(request: Request, next: str | None = None):
    return _page(request, _safe_next(request, next))


@router.post("/signin", name="signin_submit")
async def signin_submit(request: Request, user: Annotated[str, Form()] = "", password: Annotated[str, Form()] = "",
                        panel: Annotated[str, Form()] = "", next: Annotated[str, Form()] = ""):
    """As ``POST /api/session``: while this computer must wait or every password check is taken,
    429 at once on the event loop, before any password work and without a worker thread
    (docs/hardening.md); else the check runs in the bounded pool."""
    target = _safe_next(request, next)
    if panel != "1":
        try:
            refuse_at_once(request)
        except HmiError as exc:
            return _page(request, target, exc.message, user, status_code=exc.status, headers=exc.headers)
    return await run_in_threadpool(_signin_submit, request, target, user, password, panel)


def _signin_submit(request: Request, target: str, user: str, password: str, panel: str):
    try:
        secret, _identity = sign_in(request, user, password, panel == "1")
    except HmiError as exc:
        return _page(request, target, exc.message, user, status_code=exc.status, headers=exc.headers)
    response = RedirectResponse(target, status_code=303)
    set_session_cookie(request, response, secret, request.app.state.access.session_seconds)
    return response


@router.post("/signout", name="signout_submit")
def signout_submit(request: Request):

    request.app.state.access.sign_out(request.cookies.get(SESSION_COOKIE))
    if request.headers.get("HX-Request") == "true":        # htmx follows a 303 itself: tell it instead
        response = Response(status_code=200, headers={"HX-Redirect": url_path(request, "signin_screen")})
    else:
        response = RedirectResponse(url_path(request, "signin_screen"), status_code=303)
    clear_session_cookie(request, response)
    return response
