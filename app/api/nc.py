"""The NC channel (design.md §9.4): run an MDA text or a stored program, NC Start/Stop/Reset,
the channel's state and its variables (R parameters, GUD such as ``_OVR``, system data)."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Body, Path, Query, Request
from fastapi.responses import JSONResponse
from pydantic import BaseModel, ConfigDict, Field, StrictBool, StrictStr

from app.access.deps import measuring_function, needs, require
from app.deps import NcDep
from app.services.nc import NcSyntaxInput, protected_function

router = APIRouter(prefix="/nc", tags=["nc"])


class RunBody(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [
        {"mda": "N10 G54 G0 X10 Y10\nN20 M30"}, {"program": "BORE1", "wait": False},
        {"mda": "G500 G90\n_MVAR=101 _SETVAL=20 _KNUM=1 _FA=5\nCYCLE977\nM30", "single_block": True}]})
    program: StrictStr | None = Field(None, description="the name of a stored program (AUTOMATIC)")
    mda: StrictStr | None = Field(None, description="the text of an MDA program (at most 1 MiB: 413 above)")
    wait: StrictBool = Field(True, description="true: answer when the program has ended or stopped; "
                                               "false: 202 at once, GET /api/nc for the state")
    single_block: StrictBool = Field(False, description="single block: stop after every block "
                                                        "(NC Start: POST /api/nc/start)")


class StartBody(BaseModel):
    model_config = ConfigDict(extra="forbid")
    wait: StrictBool = True
    single_block: StrictBool | None = None


class VariableBody(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [{"value": 0.004}]})
    value: Any = Field(description="a number, or a text for STRING variables")


def _syntax(exc: NcSyntaxInput) -> JSONResponse:
    """422 with the line and column of the error (and the catalogue entry): nothing moved."""
    detail = exc.detail
    return JSONResponse({"error": {"code": exc.code, "message": exc.message, "field": exc.field,
                                   "line": detail.get("line"), "column": detail.get("column"),
                                   "alarm": detail}}, status_code=422)


def authorizer(request: Request):
    """The check a program makes before it writes: the level of who started it must allow what a
    cycle's measurement writes (a zero offset, tool data, a calibration), as in JOG, and the
    stored data a program assigns (``function``: the EV/MV memories), as the JSON API does."""
    def authorize(category, target, function: str | None = None) -> None:
        function = function or measuring_function(category, target)
        if function:
            require(request, function)
    return authorize


def _answer(answer: dict, wait: bool):
    return answer if wait else JSONResponse(answer, status_code=202)


@router.post("/run", name="api_nc_run", dependencies=[needs("measure")])
def run(body: RunBody, nc: NcDep, request: Request):
    """Load the MDA text or the stored program and run it from its first block: ``{"state":
    "done"|"alarm"|"stopped", "block", "alarm"}``. A syntax error is a 422 naming line and
    column; nothing moves."""
    try:
        # a run through the API is single block only when it says so (the screen's toggle is its own)
        answer = nc.run(program=body.program, mda=body.mda, wait=body.wait, single_block=body.single_block,
                        authorize=authorizer(request))
    except NcSyntaxInput as exc:
        return _syntax(exc)
    return _answer(answer, body.wait)


@router.post("/start", name="api_nc_start", dependencies=[needs("measure")])
def start(nc: NcDep, request: Request, body: Annotated[StartBody | None, Body()] = None):
    """NC Start: continue the loaded program (after M0, single block or NC Stop), or run it
    again when it has ended."""
    body = body or StartBody()
    return _answer(nc.start(wait=body.wait, single_block=body.single_block, authorize=authorizer(request)),
                   body.wait)


@router.post("/stop", name="api_nc_stop", dependencies=[needs("jog")])
def stop(nc: NcDep) -> dict:
    """NC Stop: the program stops at the end of the block being executed."""
    return nc.stop()


@router.post("/reset", name="api_nc_reset", dependencies=[needs("jog")])
def reset(nc: NcDep) -> dict:
    """NC Reset: abort, modal state to the defaults, measuring offsets cleared, mode JOG."""
    return nc.reset()


@router.get("", name="api_nc")
def state(nc: NcDep) -> dict:
    """mode (JOG/MDA/AUTO), program, block, state (idle, ready, running, stopped, done, alarm), alarm."""
    return nc.status()


class SelectBody(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [{"program": "BORE1"}]})
    program: StrictStr


@router.post("/select", name="api_nc_select", dependencies=[needs("measure")])
def select(body: SelectBody, nc: NcDep):
    """Select a stored program for AUTOMATIC (mode AUTO; ``POST /api/nc/start`` runs it)."""
    try:
        return nc.select(body.program)
    except NcSyntaxInput as exc:
        return _syntax(exc)


@router.get("/variables", name="api_nc_variables")
def variables(nc: NcDep, names: Annotated[str, Query(description="comma-separated: _OVR,R1,$AA_MM[X]")]) -> dict:
    """The values: a whole variable (``_OVR``: a list, ``$AA_MM``: by axis) or one element."""
    wanted = [n.strip() for n in _split(names) if n.strip()]
    return nc.read_variables(wanted)


@router.put("/variables/{name}", name="api_nc_variable_put", dependencies=[needs("measure")])
def put_variable(name: Annotated[str, Path(min_length=1, max_length=64, description="R1, _EV[9], _TUL")], body: VariableBody, nc: NcDep, request: Request) -> dict:
    """Write one variable element (``R1``, ``_EV[9]``, ``_TUL``) as a program would; the EV/MV
    memories need the level of ``/api/memories`` (``app.services.nc.PROTECTED``)."""
    function = protected_function(name)
    if function:
        require(request, function)
    return nc.write_variable(name, body.value)


def _split(names: str) -> list[str]:
    """Split at the commas outside brackets (``_WP[0,1]`` stays one name)."""
    out, depth, current = [], 0, ""
    for ch in names:
        depth += ch == "["
        depth -= ch == "]"
        if ch == "," and depth == 0:
            out.append(current)
            current = ""
        else:
            current += ch
    out.append(current)
    return out
