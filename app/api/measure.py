"""Automation API of the measuring workflow (design.md §4): same semantics as the softkeys."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Body, Path, Query, Request
from fastapi.encoders import jsonable_encoder
from fastapi.responses import JSONResponse
from pydantic import BaseModel, ConfigDict, Field, StrictBool, StrictInt

from app.access.deps import needs, require_measurement
from app.deps import WorkflowDep
from app.errors import WorkflowError
from app.workflow.tasks import MAX_FIT_POINTS, TASKS

router = APIRouter(prefix="/measure", tags=["measure"])
# the schema names what the workflow takes (issue 25 item 7): the registry's task names, P1..P12
TASK_NAMES: list[Any] = sorted(TASKS)
SessionId = Annotated[str, Path(min_length=1, max_length=64, description="the session's id (``id`` of its answer)")]
PointNumber = Annotated[int, Path(ge=1, le=MAX_FIT_POINTS, description=f"point P1..P{MAX_FIT_POINTS} of the session's task")]


class CreateBody(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [
        {"task": "hole.1", "params": {"diameter": 20, "probe_angle": 0, "setpoint": {"X": 0, "Y": 0},
                                      "target": "G54"}},
        {"task": "corner.right", "params": {"kind": "outside", "position": 1,
                                            "setpoint": {"X": 0, "Y": 0}}, "target": "G54"},
        {"task": "edge.set", "params": {"axis": "Z", "direction": "-", "setpoint": 0}},
        {"task": "hole.1", "params": {"diameter": 132, "tolerance": {
            "setpoint": 132, "upper": 0.03, "lower": -0.03, "zero_range": 0.01, "mean_range": 0.02,
            "dim_difference": 0.06, "safe_area": 1, "k": 3, "evnum": 10, "keep_mean": True}},
         "target": {"tool": 20, "edge": 1, "correct": "radius", "mode": "wear"}},
    ]})
    # the enum is the schema's; an unknown name is the workflow's 400 naming "task", as before
    task: str = Field(json_schema_extra={"enum": TASK_NAMES}, description="edge.set, edge.align, edge.distance, corner.right, corner.any, "
                                  "pocket.rect, hole.1..4, spigot.rect, spigot.1..4, plane.align, "
                                  "probe.length, probe.radius, toolprobe.calibrate, tool.length, tool.diameter")
    params: dict[str, Any] = Field(default_factory=dict)
    # validated by the workflow, so that any wrong target is a 400 naming "target"
    target: Any = Field(
        None, json_schema_extra={"anyOf": [{"type": "string"}, {"type": "object"}, {"type": "null"}]},
        description="measure_only, G54.., BASIC_REF, BASIC_n (default: the WO active while measuring); "
                          'or a tool offset {"tool": T, "edge": 1, "correct": "radius"|"length", '
                          '"mode": "wear"|"geometry"} for hole.1, spigot.1, pocket.rect, spigot.rect, '
                          "edge.distance, edge.set (design.md §9.3)")


class StartBody(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [{}, {"point": 2},
                                                                              {"wait": False}]})
    point: StrictInt | None = Field(None, ge=1, le=MAX_FIT_POINTS, description="measure this point; default: the lowest unstored")
    wait: StrictBool = Field(True, description="false: answer 202 at once; GET the session for "
                                               "``running``, ``progress`` and the ``answer``")


@router.post("", name="api_measure_create", dependencies=[needs("measure")])
def create_session(request: Request, body: CreateBody, workflow: WorkflowDep) -> dict:
    """Open the input screen of a task: a new session (replaces an idle one). Measuring into a zero
    offset, a probe calibration or tool measuring also needs that write's level."""
    params = dict(body.params)
    if body.target is not None and not isinstance(body.target, str | dict):      # false, 0, a list
        raise WorkflowError(400, "invalid_target", "target: a zero offset's name or a tool offset object",
                            "target")
    target = body.target or params.pop("target", None)
    require_measurement(request, body.task, target)
    return workflow.create(body.task, params, target).to_api()


@router.get("/current", name="api_measure_current")
def current_session(workflow: WorkflowDep) -> dict | None:
    session = workflow.session
    return None if session is None else session.to_api()


@router.get("/{session_id}", name="api_measure_session")
def get_session(session_id: SessionId, workflow: WorkflowDep) -> dict:
    return workflow.get(session_id).to_api()


@router.get("/{session_id}/plan", name="api_measure_plan")
def plan(session_id: SessionId, workflow: WorkflowDep, point: Annotated[int | None, Query(
         ge=1, le=MAX_FIT_POINTS, description="the point (default: the next unstored)")] = None) -> dict:
    """The planned path of a point from where the probe stands, with the start guard's verdict per
    segment (``clear``, ``collision``, ``limit``, ``unknown``; probing moves ``contact``/``no_switch``)."""
    return workflow.plan(session_id, point)


@router.post("/{session_id}/start", name="api_measure_start", dependencies=[needs("measure")])
def nc_start(request: Request, session_id: SessionId, workflow: WorkflowDep,
             body: Annotated[StartBody | None, Body()] = None):
    """NC Start: probe the next unstored point (single-point tasks also compute and correct).

    With ``{"wait": false}``: 202 at once, the measurement runs on (design.md §9.1)."""
    body = body or StartBody()
    session = workflow.get(session_id)
    require_measurement(request, session.task, session.target)
    answer = workflow.start(session_id, body.point, wait=body.wait)
    return json_answer(answer, 200 if body.wait else 202)


def json_answer(answer: dict, status_code: int = 200) -> JSONResponse:
    """``answer`` as FastAPI would send it (``jsonable_encoder`` then ``JSONResponse``), rendered in
    one ``json.dumps`` when it holds only JSON's own types (the workflow's answers do: the same
    bytes without walking the answer twice, issue 30); anything else goes through the encoder."""
    try:
        return JSONResponse(answer, status_code=status_code)
    except TypeError:               # a value json.dumps does not know (a model, a date): FastAPI's way
        return JSONResponse(jsonable_encoder(answer), status_code=status_code)


@router.post("/{session_id}/points/{n}/invalidate", name="api_measure_invalidate", dependencies=[needs("measure")])
def invalidate(session_id: SessionId, n: PointNumber, workflow: WorkflowDep) -> dict:
    return workflow.invalidate(session_id, n).to_api()


@router.post("/{session_id}/calculate", name="api_measure_calculate", dependencies=[needs("measure")])
def calculate(request: Request, session_id: SessionId, workflow: WorkflowDep) -> dict:
    session = workflow.get(session_id)
    require_measurement(request, session.task, session.target)
    return workflow.calculate(session_id)


@router.delete("/{session_id}", name="api_measure_delete", dependencies=[needs("measure")])
def leave(session_id: SessionId, workflow: WorkflowDep) -> dict:
    workflow.delete(session_id)
    return {"deleted": session_id}
