"""Sign-in (``POST/DELETE /api/session``), users, API tokens and the simulated keyswitch
(design.md §9.2). The levels each needs are in app/access/levels.py."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Body, Path, Request, Response
from fastapi.concurrency import run_in_threadpool
from pydantic import BaseModel, ConfigDict, Field, StrictBool, StrictInt, StrictStr

from app.access.deps import identity_of, needs
from app.access.errors import AccessDenied
from app.access.identity import TRAINER
from app.access.levels import describe_level, keyswitch_level
from app.access.middleware import is_local
from app.access.service import MIN_PASSWORD, SESSION_COOKIE, AccessError, AccessService, SignInRefused
from app.access.service import NAME as USER_NAME
from app.access.throttle import HTTP, Throttled
from app.errors import ConflictError, HmiError, InvalidInput, NotFoundError

router = APIRouter(tags=["access"])


class SignInBody(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [
        {"user": "anna", "password": "••••••••"}, {"panel": True}]})
    user: StrictStr | None = None
    password: StrictStr | None = None
    panel: StrictBool = Field(False, description="the operator panel (this computer only): no password, "
                                                 "the keyswitch's level")


class UserBody(BaseModel):
    model_config = ConfigDict(extra="forbid")
    # the schema states the service's rules (app/access/service.py), which keep their messages
    name: StrictStr = Field(json_schema_extra={"pattern": USER_NAME.pattern})
    password: StrictStr = Field(json_schema_extra={"minLength": MIN_PASSWORD},
                                description=f"at least {MIN_PASSWORD} characters")
    level: StrictInt = Field(description="1 manufacturer, 2 service, 3 user",
                             json_schema_extra={"minimum": 1, "maximum": 3})


class TokenBody(BaseModel):
    model_config = ConfigDict(extra="forbid")
    name: StrictStr
    level: StrictInt = Field(description="1..7")


class KeyswitchBody(BaseModel):
    model_config = ConfigDict(extra="forbid")
    position: StrictInt = Field(ge=0, le=3, description="0..3 = protection level 7..4")


def access_of(request: Request) -> AccessService:
    return request.app.state.access


def session_info(request: Request, identity=None) -> dict:
    access = access_of(request)
    identity = identity or identity_of(request)
    position = access.keyswitch()
    return {"signed_in": identity.kind not in (TRAINER,) and identity.authenticated,
            "kind": identity.kind, "name": identity.name, "who": identity.who if identity.authenticated else None,
            "level": identity.level,
            "level_text": describe_level(identity.level) if identity.level is not None else None,
            "expires": identity.expires, "signin_required": access.signin_on(),
            "trainer": identity.kind == TRAINER,
            "keyswitch": {"position": position, "level": keyswitch_level(position)}}


def set_session_cookie(request: Request, response: Response, secret: str, max_age: int) -> None:
    response.set_cookie(SESSION_COOKIE, secret, max_age=max_age, path=request.scope.get("root_path") or "/",
                        httponly=True, samesite="strict", secure=request.url.scheme == "https")


def clear_session_cookie(request: Request, response: Response) -> None:
    response.delete_cookie(SESSION_COOKIE, path=request.scope.get("root_path") or "/", httponly=True,
                           samesite="strict", secure=request.url.scheme == "https")


def _refused(exc: SignInRefused | Throttled) -> HmiError:
    error = HmiError(exc.message, code=exc.code)
    error.status = exc.status if isinstance(exc, SignInRefused) else 429
    if exc.retry_after_s is not None:
        error.headers["Retry-After"] = str(exc.retry_after_s)
    return error


def _source(request: Request) -> tuple[str, str]:
    client = request.scope.get("client")
    return HTTP, client[0] if client else ""


def refuse_at_once(request: Request) -> None:
    """429 before any work when this computer must wait or every password check is taken: on the
    event loop, so a flood of refused sign-ins takes no worker thread from the machine's calls."""
    gate = access_of(request).gate
    try:
        gate.check_source(_source(request))
        gate.check_room()
    except Throttled as exc:
        raise _refused(exc) from None


def sign_in(request: Request, user: str | None, password: str | None, panel: bool = False):
    """(session secret, identity); HmiError with the status to answer."""
    access = access_of(request)
    if panel:
        forwarded = "x-forwarded-for" in request.headers or "forwarded" in request.headers
        if not is_local(request.scope.get("client")) or forwarded:
            error = HmiError("the operator panel signs in only on the machine's own computer", code="panel_local_only")
            error.status = 403
            raise error
        return access.sign_in_panel()
    try:
        return access.sign_in(user or "", password or "", _source(request))
    except SignInRefused as exc:
        raise _refused(exc) from None


@router.post("/session", name="api_session_create", responses={429: {"description": "too many failed "
             "sign-ins from this computer, or every password check is taken: try again after Retry-After"}})
async def create_session(request: Request, response: Response, body: SignInBody) -> dict:
    """Sign in: sets the session cookie (HttpOnly, SameSite=Strict, for ``session_hours``); the answer
    holds the CSRF token a browser script sends as ``X-CSRFToken``. Password checks are bounded
    (docs/hardening.md): over the bound, 429 at once with ``Retry-After``."""
    if not body.panel and (body.user is None or body.password is None):
        raise InvalidInput("user and password are required (or panel: true)", field="user")
    if not body.panel:
        refuse_at_once(request)
    return await run_in_threadpool(_signed_in, request, response, body)


def _signed_in(request: Request, response: Response, body: SignInBody) -> dict:
    secret, identity = sign_in(request, body.user, body.password, body.panel)
    set_session_cookie(request, response, secret, access_of(request).session_seconds)
    token = request.scope.get("csrftoken")
    return {**session_info(request, identity), "csrf_token": token() if callable(token) else None}


@router.delete("/session", name="api_session_delete")
def delete_session(request: Request, response: Response) -> dict:
    """Sign out: the session ends on the server, the cookie is cleared."""
    access_of(request).sign_out(request.cookies.get(SESSION_COOKIE))
    clear_session_cookie(request, response)
    return {"signed_in": False}


@router.get("/session", name="api_session_get")
def get_session(request: Request) -> dict:
    """Who is acting (user, panel, token, trainer), with which level, and the keyswitch."""
    return session_info(request)


# --- administration ------------------------------------------------------------------------------

def _not_above_own(request: Request, level: int, what: str) -> None:
    identity = identity_of(request)
    if identity.level is not None and level < identity.level:
        raise AccessDenied("users", level, identity.level, f"a {what} of level {level} is above your level; you")


def _admin_error(exc: AccessError) -> HmiError:
    text = str(exc)
    if "exists already" in text:
        return ConflictError(text, code="exists")
    if text.startswith("no "):
        return NotFoundError(text)
    field = text.split(":", 1)[0] if ":" in text else None
    return InvalidInput(text, field=field)


@router.get("/users", name="api_users", dependencies=[needs("users")])
def list_users(request: Request) -> list[dict]:
    return access_of(request).list_users()


@router.post("/users", name="api_user_add", status_code=201, dependencies=[needs("users")])
def add_user(request: Request, body: UserBody) -> dict:
    """Creates a user (password hashed with argon2id); the first user switches sign-in on."""
    _not_above_own(request, body.level, "user")
    try:
        return access_of(request).add_user(body.name, body.level, body.password)
    except AccessError as exc:
        raise _admin_error(exc) from None


@router.delete("/users/{name}", name="api_user_delete", dependencies=[needs("users")])
def delete_user(request: Request, name: Annotated[str, Path(min_length=1, max_length=64)]) -> dict:
    try:
        return access_of(request).delete_user(name)
    except AccessError as exc:
        raise _admin_error(exc) from None


@router.get("/tokens", name="api_tokens", dependencies=[needs("users")])
def list_tokens(request: Request) -> list[dict]:
    return access_of(request).list_tokens()


@router.post("/tokens", name="api_token_add", status_code=201, dependencies=[needs("users")])
def add_token(request: Request, body: TokenBody) -> dict:
    """A new API token: ``token`` is shown in this answer only (the database keeps a hash)."""
    _not_above_own(request, body.level, "token")
    try:
        secret, record = access_of(request).add_token(body.name, body.level)
    except AccessError as exc:
        raise _admin_error(exc) from None
    return {**record, "token": secret}


@router.delete("/tokens/{name}", name="api_token_delete", dependencies=[needs("users")])
def delete_token(request: Request, name: Annotated[str, Path(min_length=1, max_length=64)]) -> dict:
    try:
        return access_of(request).delete_token(name)
    except AccessError as exc:
        raise _admin_error(exc) from None


@router.get("/keyswitch", name="api_keyswitch")
def keyswitch(request: Request) -> dict:
    position = access_of(request).keyswitch()
    return {"position": position, "level": keyswitch_level(position)}


@router.put("/keyswitch", name="api_keyswitch_put", dependencies=[needs("keyswitch")])
def turn_keyswitch(request: Request, body: Annotated[KeyswitchBody, Body()]) -> dict:
    """Turn the simulated keyswitch (position 0..3 = level 7..4): the operator panel's level."""
    return access_of(request).set_keyswitch(body.position)
