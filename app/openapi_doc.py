"""The OpenAPI document as the API really answers (issue [operator-ux] item 11, design.md §3):
the error envelope ``{"error": {"code", "message", "field"}}`` (app.api.ErrorEnvelope) for
every status an operation can give, not only the routers' catch-all "4XX", with an example of
each, and an example answer of the main operations.

FastAPI builds the document from the routes; this only rewrites its responses once, cached
like FastAPI's own ``app.openapi``."""

from __future__ import annotations

from fastapi import FastAPI
from fastapi.openapi.utils import get_openapi

ENVELOPE = "#/components/schemas/ErrorEnvelope"      # app.api.ErrorEnvelope (the routers' "4XX")

# status -> (description, example error)
ERRORS = {
    400: ("Bad request: the input is refused (nothing changed)",
          {"code": "invalid_target", "message": "unknown zero offset 'G99'", "field": "target"}),
    401: ("Not signed in (POST /api/session) and no Bearer token",
          {"code": "unauthenticated", "message": "sign in first (POST /api/session) or send Authorization: Bearer <token>",
           "field": None}),
    403: ("The access level is too low for this function, or a cross-site request",
          {"code": "access_level", "message": "needs level 3 (offsets); you have level 7", "field": None}),
    404: ("No such record",
          {"code": "not_found", "message": "no log entry 12345", "field": "log_id"}),
    409: ("Refused by the machine state: an alarm, a running motion, a locked point",
          {"code": "alarm", "message": "61301 Probe not switched", "field": None}),
    415: ("The body is not JSON (Content-Type application/json)",
          {"code": "unsupported_media_type", "message": "the JSON API accepts only Content-Type: application/json",
           "field": None}),
    413: ("The request body is too large", {"code": "body_too_large", "message": "request body larger than 1048576 bytes", "field": None}),
    422: ("Validation: a value out of range or of the wrong type (nothing changed)",
          {"code": "validation", "message": "trans.X: 'abc' is not a number", "field": "trans.X"}),
    503: ("Storage fault (disk full, database locked): nothing was written",
          {"code": "storage_unavailable", "message": "Nothing was stored: database or disk is full",
           "field": None}),
}
WRITES = {"post", "put", "patch", "delete"}

# hand-written success examples of the operations an integrator starts with
SUCCESS_EXAMPLES = {
    ("get", "/api/machine"): {"controller": "sim", "kind": "mill", "active_offset": "G54", "tool": 9,
                              "mcs": {"X": 250.0, "Y": 150.0, "Z": -20.0}, "wcs": {"X": 0.0, "Y": 0.0, "Z": 100.0},
                              "alarms": []},
    ("get", "/api/offsets/{name}"): {"name": "G54", "trans": {"X": 250.0, "Y": 150.0, "Z": -120.0},
                                     "fine": {"X": 0.0, "Y": 0.0, "Z": 0.0}, "rot": {"X": 0.0, "Y": 0.0, "Z": 12.5}},
    ("post", "/api/measure"): {"id": "3f2c...", "task": "edge.set", "target": "G54", "points": 1},
}


def _error_response(status: int) -> dict:
    description, example = ERRORS[status]
    return {"description": description,
            "content": {"application/json": {"schema": {"$ref": ENVELOPE},
                                             "example": {"error": example}}}}


def _statuses(method: str, path: str, public: bool) -> list[int]:
    out = [422]
    if not public:
        out += [401, 403]
    if "{" in path:
        out.append(404)
    if method in WRITES:
        out += [400, 409, 413, 415, 503]
    return sorted(set(out))


def _example_for(method: str, path: str, operation: dict) -> None:
    ok = next((code for code in ("200", "201", "204") if code in operation.get("responses", {})), None)
    if ok is None or ok == "204":
        return
    content = operation["responses"][ok].setdefault("content", {})
    body = content.setdefault("application/json", {"schema": {}})
    if (method, path) in SUCCESS_EXAMPLES:
        body["example"] = SUCCESS_EXAMPLES[(method, path)]


def rewrite(document: dict, public_paths: set[str]) -> dict:
    """The document with the error envelope, every 4xx and examples (pure: dict in, dict out)."""
    schemas = document.setdefault("components", {}).setdefault("schemas", {})
    if "ErrorEnvelope" not in schemas:          # no API route at all (nothing refers to it)
        return document
    schemas.pop("HTTPValidationError", None)
    schemas.pop("ValidationError", None)
    for path, item in document.get("paths", {}).items():
        for method, operation in item.items():
            if method not in {"get", "put", "post", "delete", "patch"}:
                continue
            responses = operation.setdefault("responses", {})
            if path in public_paths:
                operation["security"] = []          # anyone may call it, signed in or not
            for status in _statuses(method, path, path in public_paths):
                responses[str(status)] = _error_response(status)
            _example_for(method, path, operation)
    return document


def install(app: FastAPI, public_paths: set[str] | None = None) -> None:
    """``app.openapi`` answering the rewritten document (built once, then cached)."""
    public = set(public_paths or ())

    def openapi() -> dict:
        if app.openapi_schema is None:
            document = get_openapi(title=app.title, version=app.version, description=app.description,
                                   routes=app.routes)
            app.openapi_schema = rewrite(document, public)
        return app.openapi_schema

    app.openapi = openapi  # type: ignore[method-assign]
