"""Automation API of the measuring workflow (design.md §4): same semantics as the softkeys."""

from __future__ import annotations

from typing import Annotated, Any

from fastapi import APIRouter, Body
from pydantic import BaseModel, ConfigDict, Field

from app.deps import WorkflowDep

router = APIRouter(prefix="/measure", tags=["measure"])


class CreateBody(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [
        {"task": "hole.1", "params": {"diameter": 20, "probe_angle": 0, "setpoint": {"X": 0, "Y": 0},
                                      "target": "G54"}},
        {"task": "corner.right", "params": {"kind": "outside", "position": 1,
                                            "setpoint": {"X": 0, "Y": 0}}, "target": "G54"},
        {"task": "edge.set", "params": {"axis": "Z", "direction": "-", "setpoint": 0}},
    ]})
    task: str = Field(description="edge.set, edge.align, edge.distance, corner.right, corner.any, "
                                  "pocket.rect, hole.1..4, spigot.rect, spigot.1..4, plane.align, "
                                  "probe.length, probe.radius, toolprobe.calibrate, tool.length, tool.diameter")
    params: dict[str, Any] = Field(default_factory=dict)
    target: str | None = Field(None, description="measure_only, G54.., BASIC_REF, BASIC_n; "
                                                 "default: the WO active while measuring")


class StartBody(BaseModel):
    model_config = ConfigDict(extra="forbid")
    point: int | None = Field(None, ge=1, le=4, description="measure this point; default: the lowest unstored")


@router.post("")
def create_session(body: CreateBody, workflow: WorkflowDep) -> dict:
    """Open the input screen of a task: a new session (replaces an idle one)."""
    params = dict(body.params)
    target = body.target or params.pop("target", None)
    return workflow.create(body.task, params, target).to_api()


@router.get("/current")
def current_session(workflow: WorkflowDep) -> dict | None:
    session = workflow.session
    return None if session is None else session.to_api()


@router.get("/{session_id}")
def get_session(session_id: str, workflow: WorkflowDep) -> dict:
    return workflow.get(session_id).to_api()


@router.post("/{session_id}/start")
def nc_start(session_id: str, workflow: WorkflowDep,
             body: Annotated[StartBody | None, Body()] = None) -> dict:
    """NC Start: probe the next unstored point (single-point tasks also compute and correct)."""
    return workflow.start(session_id, body.point if body else None)


@router.post("/{session_id}/points/{n}/invalidate")
def invalidate(session_id: str, n: int, workflow: WorkflowDep) -> dict:
    return workflow.invalidate(session_id, n).to_api()


@router.post("/{session_id}/calculate")
def calculate(session_id: str, workflow: WorkflowDep) -> dict:
    return workflow.calculate(session_id)


@router.delete("/{session_id}")
def leave(session_id: str, workflow: WorkflowDep) -> dict:
    workflow.delete(session_id)
    return {"deleted": session_id}
