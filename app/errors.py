"""Error envelope ``{"error": {"code", "message", "field"?}}`` and the exception handlers (design.md §4).

Services raise :class:`HmiError` subclasses; routers never build error responses themselves.
"""

from __future__ import annotations

import logging
from collections.abc import Awaitable, Callable

from fastapi import FastAPI, Request
from fastapi.exceptions import RequestValidationError
from fastapi.responses import JSONResponse
from starlette.exceptions import HTTPException as StarletteHTTPException
from starlette.responses import Response

from app.machine.protocol import MachineAlarm, MachineBusy
from db import StorageUnavailable
from engine.types import MeasuringError

log = logging.getLogger(__name__)


class HmiError(Exception):
    """``extra``: machine-readable fields beside code/message/field in the envelope (e.g. the
    running ``program`` of a 409 ``mode``)."""

    status = 400
    code = "bad_request"

    def __init__(self, message: str, field: str | None = None, code: str | None = None,
                 extra: dict | None = None):
        super().__init__(message)
        self.message = message
        self.field = field
        self.extra = dict(extra or {})
        self.headers: dict[str, str] = {}      # e.g. Retry-After of a 429
        if code:
            self.code = code


class NotFoundError(HmiError):
    status = 404
    code = "not_found"


class InvalidInput(HmiError):
    status = 422
    code = "validation"


class ConflictError(HmiError):
    status = 409
    code = "conflict"


class BusyError(ConflictError):
    code = "busy"


class ModeError(ConflictError):
    """Refused by the channel's mode group (issue 24 §4): a program runs in MDA/AUTO, or a JOG
    measurement runs; ``extra`` names what runs (``mode``, ``program``)."""

    code = "mode"


class TooLarge(HmiError):
    status = 413
    code = "program_too_large"


class WorkflowError(HmiError):
    """A request the measuring workflow refuses; ``status`` is the HTTP status to answer with."""

    def __init__(self, status: int, code: str, message: str, field: str | None = None):
        super().__init__(message, field=field, code=code)
        self.status = status


class AlarmError(ConflictError):
    """A motion stopped by a machine alarm; the alarm stays in the machine status until Reset."""

    code = "alarm"

    def __init__(self, alarm_code: int, text: str):
        super().__init__(f"{alarm_code} {text}")
        self.alarm_code = alarm_code


def envelope(code: str, message: str, field: str | None = None) -> dict:
    body = {"code": code, "message": message}
    if field:
        body["field"] = field
    return {"error": body}


def error_response(status: int, code: str, message: str, field: str | None = None) -> JSONResponse:
    return JSONResponse(envelope(code, message, field), status_code=status)


def field_path(loc) -> str:
    """Pydantic location -> dotted field name without the ``body``/``query`` prefix."""
    parts = [str(p) for p in loc if p not in ("body", "query", "path", "form")]
    return ".".join(parts)


def _validation_message(err: dict) -> str:
    msg = err.get("msg", "invalid value")
    return msg.removeprefix("Value error, ")


def allowed_methods(request: Request) -> list[str]:
    """The methods of every route whose path matches the request's (FastAPI has one route per
    method; routers included lazily are flattened as fastapi.routing.iter_route_contexts does)."""
    import fastapi.routing

    flatten = getattr(fastapi.routing, "iter_route_contexts", None)
    routes = flatten(request.app.router.routes) if flatten else request.app.router.routes
    path = request.scope.get("path", "")
    literal: set[str] = set()          # routes of this very path (``/api/measure/current``)
    templated: set[str] = set()        # routes whose parameters match it (``/api/measure/{session_id}``)
    for route in routes:
        regex = getattr(route, "path_regex", None)
        if regex is not None and regex.match(path):
            (literal if getattr(route, "path", None) == path else templated).update(
                getattr(route, "methods", None) or ())
    methods = literal or templated       # the schema's path item: the literal one where there is one
    order = ("GET", "HEAD", "POST", "PUT", "PATCH", "DELETE", "OPTIONS")
    return sorted(methods, key=lambda m: (order.index(m) if m in order else len(order), m))


async def _hmi_error(_: Request, exc: HmiError):
    response = error_response(exc.status, exc.code, exc.message, exc.field)
    if exc.extra:
        body = envelope(exc.code, exc.message, exc.field)
        body["error"].update({k: v for k, v in exc.extra.items() if k not in body["error"]})
        response = JSONResponse(body, status_code=exc.status)
    response.headers.update(exc.headers)
    return response


async def _measuring_error(_: Request, exc: MeasuringError):
    return error_response(409, "alarm", f"{exc.alarm} {exc.message}")


async def _machine_alarm(_: Request, exc: MachineAlarm):
    return error_response(409, "alarm", f"{exc.alarm.code} {exc.alarm.text}")


async def _machine_busy(_: Request, exc: MachineBusy):
    return error_response(409, "busy", str(exc) or "a motion is running")


async def _request_validation(_: Request, exc: RequestValidationError):
    errors = exc.errors()
    first = errors[0] if errors else {}
    field = field_path(first.get("loc", ())) or None
    message = _validation_message(first) if first else "invalid request"
    if field:
        message = f"{field}: {message}"
    return error_response(422, "validation", message, field)


async def _http_error(request: Request, exc: StarletteHTTPException):
    code = {404: "not_found", 405: "method_not_allowed"}.get(exc.status_code, "http_error")
    response = error_response(exc.status_code, code, str(exc.detail))
    response.headers.update(exc.headers or {})
    if exc.status_code == 405:
        # every method the path has (RFC 9110 §15.5.6): Starlette names only the first route's,
        # FastAPI has one route per method
        allowed = allowed_methods(request)
        if allowed:
            response.headers["Allow"] = ", ".join(allowed)
    return response


async def _storage(_: Request, exc: StorageUnavailable):
    log.error("storage unavailable: %s", exc)
    return error_response(503, "storage_unavailable", f"Nothing was stored: {exc}")


async def _overflow(_: Request, exc: OverflowError):
    # the safety net of app.checks: a number too large for a float that a check missed
    log.warning("unchecked number overflow: %s", exc)
    return error_response(422, "validation", "a number is too large")


async def _value_error(_: Request, exc: ValueError):
    # A ValueError escaping a service is bad input the service did not name (e.g. numpy/engine).
    log.info("unclassified ValueError: %s", exc)
    return error_response(422, "validation", str(exc))


_HANDLERS: tuple[tuple[type[Exception], Callable[..., Awaitable[Response]]], ...] = (
    (HmiError, _hmi_error),
    (MeasuringError, _measuring_error),
    (MachineAlarm, _machine_alarm),
    (MachineBusy, _machine_busy),
    (RequestValidationError, _request_validation),
    (StarletteHTTPException, _http_error),
    (StorageUnavailable, _storage),
    (OverflowError, _overflow),
    (ValueError, _value_error),
)


def install_handlers(app: FastAPI) -> None:
    """The error envelope {"error": {"code", "message"}} (design.md §4) for the domain errors, bad input and HTTP errors."""
    for exc_type, handler in _HANDLERS:
        app.add_exception_handler(exc_type, handler)
