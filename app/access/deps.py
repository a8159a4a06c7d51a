"""FastAPI side of the access levels: the router-wide ``guard``, ``needs(function)`` per route, and
``require(request, function)`` where the function depends on the request's data.

- ``guard`` (on every router): public routes (health, sign-in, docs) pass; otherwise no
  credentials are 401 while sign-in is on, reads need ``view``, and a write route that names no
  function needs ``UNDECLARED_WRITE``.
- ``needs("offsets")`` in a route's ``dependencies=[...]``: 403 ``access_level`` below the level the
  settings ask for that function.
"""

from __future__ import annotations

from fastapi import Depends, Request, Security
from fastapi.security import APIKeyCookie, HTTPBearer

from app.errors import WorkflowError
from app.workflow.context import MEASURE_ONLY
from app.workflow.tasks import Category

from .errors import AccessDenied, Unauthenticated
from .identity import INVALID, NOBODY, Identity
from .levels import FUNCTIONS, UNDECLARED_WRITE, required_level
from .service import SESSION_COOKIE

UNSAFE = frozenset({"POST", "PUT", "PATCH", "DELETE"})
# route names anyone may call, signed in or not
PUBLIC_ROUTES = frozenset({"api_health", "api_session_create", "api_session_delete", "api_session_get",
                           "signin_screen", "signin_submit", "signout_submit", "swagger_ui_html",
                           "swagger_ui_redirect", "redoc_html", "openapi", "static"})

_bearer = HTTPBearer(auto_error=False, description="An API token: python -m app token add NAME --level L")
_cookie = APIKeyCookie(name=SESSION_COOKIE, auto_error=False,
                       description="The session cookie of POST /api/session (a browser sends it by itself)")


def identity_of(request: Request) -> Identity:
    return getattr(request.state, "identity", NOBODY)


def _gud(request: Request):
    return request.app.state.services.settings.get()


def require(request: Request, function: str) -> Identity:
    """The request's identity, if it may do ``function``; else 401 / 403 ``access_level``."""
    identity = identity_of(request)
    if identity.kind == INVALID:
        raise Unauthenticated(identity.reason, code="invalid_token")
    if not identity.authenticated:
        raise Unauthenticated("sign in first (POST /api/session) or send Authorization: Bearer <token>")
    needed = required_level(_gud(request), function)
    if not identity.may(needed):
        raise AccessDenied(function, needed, identity.level)
    return identity


def may_view(request: Request) -> bool:
    """``guard``'s read rule as a yes/no, raising nothing: the request may ``view``
    (app/web/fast_reads.py answers a poll only then; otherwise the route's guard refuses)."""
    identity = identity_of(request)
    return (identity.kind != INVALID and identity.authenticated
            and identity.may(required_level(_gud(request), "view")))


def denied(request: Request, function: str) -> str:
    """'' when the request may do ``function``, else the reason (for disabled softkeys); remembered
    for the request (a table asks once per cell)."""
    cache = request.scope.setdefault("hmi.denied", {})
    if function not in cache:
        try:
            require(request, function)
            cache[function] = ""
        except AccessDenied as exc:
            cache[function] = exc.short()
        except Unauthenticated:
            cache[function] = "sign in first"
    return cache[function]


class Needs:
    """``Depends(Needs("offsets"))``: the route's function in the level table."""

    def __init__(self, function: str):
        if function not in FUNCTIONS:
            raise ValueError(f"unknown access function {function!r}")
        self.function = function

    async def __call__(self, request: Request) -> None:
        require(request, self.function)

    def __repr__(self) -> str:
        return f"Needs({self.function!r})"


def needs(function: str):
    return Depends(Needs(function))


def declared_function(route) -> str | None:
    for dependency in getattr(route, "dependencies", ()) or ():
        if isinstance(getattr(dependency, "dependency", None), Needs):
            return dependency.dependency.function
    return None


async def guard(request: Request, _token: str | None = Security(_bearer),
                _session: str | None = Security(_cookie)) -> None:
    route = request.scope.get("route")
    if getattr(route, "name", None) in PUBLIC_ROUTES:
        return
    if request.method not in UNSAFE:
        require(request, "view")
    elif declared_function(route) is None:
        require(request, UNDECLARED_WRITE)
    else:
        _authenticated(request)          # the route's own ``needs`` checks the level


def _authenticated(request: Request) -> None:
    identity = identity_of(request)
    if identity.kind == INVALID:
        raise Unauthenticated(identity.reason, code="invalid_token")
    if not identity.authenticated:
        raise Unauthenticated("sign in first (POST /api/session) or send Authorization: Bearer <token>")


# --- measuring: what a session writes decides the level (design.md §9.2) --------------------

def measuring_function(category: str, target) -> str | None:
    """The function a measurement's write needs besides ``measure``: a zero offset (``offsets``),
    tool data (``tools``), probe calibration (``calibration``); None for measure only."""
    if isinstance(target, dict):                  # a tool offset as target (design.md §9.3)
        return "tools"
    if category in (Category.PROBE_CALIBRATION, Category.TOOL_PROBE_CALIBRATION):
        return "calibration"
    if category == Category.TOOL_MEASURING:
        return "tools"
    return None if target in (None, MEASURE_ONLY, "G500") else "offsets"


def require_measurement(request: Request, task: str, target) -> None:
    """Before a measuring session is opened or run: ``measure``, and the level of what it writes.
    ``target`` None is the default the workflow takes (the WO active while measuring)."""
    require(request, "measure")
    services = request.app.state.services
    try:
        spec = services.workflow.spec(task)
    except WorkflowError:      # an unknown task: the workflow names the error
        return
    if target is None and spec.corrects_zero_offset:
        target = services.machine.active_offset
    function = measuring_function(spec.category, target)
    if function:
        require(request, function)
