"""Automation API of the measuring workflow (design.md §4): same semantics as the softkeys."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Body, Request
from fastapi.responses import JSONResponse
from pydantic import BaseModel, ConfigDict, Field, StrictBool, StrictInt

from app.access.deps import needs, require_measurement
from app.deps import WorkflowDep

router = APIRouter(prefix="/measure", tags=["measure"])


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
    task: str = Field(description="edge.set, edge.align, edge.distance, corner.right, corner.any, "
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
    point: StrictInt | None = Field(None, ge=1, le=12, description="measure this point; default: the lowest unstored")
    wait: StrictBool = Field(True, description="false: answer 202 at once; GET the session for "
                                               "``running``, ``progress`` and the ``answer``")


@router.post("", name="api_measure_create", dependencies=[needs("measure")])
def create_session(request: Request, body: CreateBody, workflow: WorkflowDep) -> dict:
    """Open the input screen of a task: a new session (replaces an idle one). Measuring into a zero
    offset, a probe calibration or tool measuring also needs that write's level."""
    params = dict(body.params)
    target = body.target or params.pop("target", None)
    require_measurement(request, body.task, target)
    return workflow.create(body.task, params, target).to_api()


@router.get("/current", name="api_measure_current")
def current_session(workflow: WorkflowDep) -> dict | None:
    session = workflow.session
    return None if session is None else session.to_api()


@router.get("/{session_id}", name="api_measure_session")
def get_session(session_id: str, workflow: WorkflowDep) -> dict:
    return workflow.get(session_id).to_api()


@router.get("/{session_id}/plan", name="api_measure_plan")
def plan(session_id: str, workflow: WorkflowDep, point: int | None = None) -> dict:
    """The planned path of a point from where the probe stands, with the start guard's verdict per
    segment (``clear``, ``collision``, ``limit``, ``unknown``; probing moves ``contact``/``no_switch``)."""
    return workflow.plan(session_id, point)


@router.post("/{session_id}/start", name="api_measure_start", dependencies=[needs("measure")])
def nc_start(request: Request, session_id: str, workflow: WorkflowDep,
             body: Annotated[StartBody | None, Body()] = None):
    """NC Start: probe the next unstored point (single-point tasks also compute and correct).

    With ``{"wait": false}``: 202 at once, the measurement runs on (design.md §9.1)."""
    body = body or StartBody()
    session = workflow.get(session_id)
    require_measurement(request, session.task, session.target)
    answer = workflow.start(session_id, body.point, wait=body.wait)
    return answer if body.wait else JSONResponse(answer, status_code=202)


@router.post("/{session_id}/points/{n}/invalidate", name="api_measure_invalidate", dependencies=[needs("measure")])
def invalidate(session_id: str, n: int, workflow: WorkflowDep) -> dict:
    return workflow.invalidate(session_id, n).to_api()


@router.post("/{session_id}/calculate", name="api_measure_calculate", dependencies=[needs("measure")])
def calculate(request: Request, session_id: str, workflow: WorkflowDep) -> dict:
    session = workflow.get(session_id)
    require_measurement(request, session.task, session.target)
    return workflow.calculate(session_id)


@router.delete("/{session_id}", name="api_measure_delete", dependencies=[needs("measure")])
def leave(session_id: str, workflow: WorkflowDep) -> dict:
    workflow.delete(session_id)
    return {"deleted": session_id}
