"""JSON API routers (design.md §4). Thin: parse, call a service, return its data.

Every route has a ``name`` for ``url_path_for`` (``api_...``). The published OpenAPI schema keeps
the operation ids and summaries FastAPI made from the endpoint functions' names before the routes
were named, so that named routes change nothing a client generator sees.
"""

import re
from typing import Any

from fastapi import APIRouter, Depends
from fastapi.routing import APIRoute
from pydantic import BaseModel, Field

from app.access.deps import guard

from . import (
    access,
    commissioning,
    cycles,
    data,
    events,
    kinematics,
    lathe,
    machine,
    measure,
    nc,
    plant,
    plc,
    probe_test,
    programs,
    results,
    setup_support,
)


def operation_id(route: APIRoute) -> str:
    """FastAPI's default operation id, made from the endpoint's function name, not the route name."""
    text = re.sub(r"\W", "_", f"{route.endpoint.__name__}{route.path_format}")
    return f"{text}_{list(route.methods or ())[0].lower()}"


class ErrorBody(BaseModel):
    code: str = Field(description="a slug: validation, not_found, unauthenticated, access_level, csrf, ...")
    message: str
    field: str | None = Field(None, description="the input at fault (validation errors)")
    required_level: int | None = Field(None, description="access_level: the protection level needed")
    function: str | None = Field(None, description="access_level: the function of the level table")


class ErrorEnvelope(BaseModel):
    """Every error of the API (design.md §4): 4xx with this body, never a bare 500 for bad input."""

    error: ErrorBody


# Every route: the access guard (401 without credentials while sign-in is on, ``view`` for reads,
# app/access/deps.py), and the real error envelope in the schema (in place of FastAPI's 422 model).
ERRORS: dict[int | str, dict[str, Any]] = {"4XX": {"model": ErrorEnvelope, "description": "Error: 401 no or bad credentials, 403 access_level "
                                                         "(the level needed) or cross_origin/csrf, 404, 409, "
                                                         "415 non-JSON body, 422 validation"}}
api_router = APIRouter(prefix="/api", generate_unique_id_function=operation_id, dependencies=[Depends(guard)],
                       responses=ERRORS)
for module in (machine, data, measure, setup_support, plc, access, nc, programs, cycles, lathe, events, results, probe_test, plant,
               kinematics, commissioning):
    for route in module.router.routes:
        if isinstance(route, APIRoute) and route.summary is None:
            route.summary = route.endpoint.__name__.replace("_", " ").title()    # FastAPI's default
    api_router.include_router(module.router)

__all__ = ["api_router"]
