"""Set-up support after measuring (spec/jog-measuring.md §6.2): the activation screen's data,
NC Start (carry it out) and ``<<`` (leave without activating)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Path
from pydantic import BaseModel, ConfigDict, Field

from app.access.deps import needs
from app.deps import ServicesDep, WorkflowDep
from app.workflow import setup_support

router = APIRouter(prefix="/measure", tags=["measure"])


class CarryOutBody(BaseModel):
    model_config = ConfigDict(extra="forbid")
    activate: bool = Field(True, description="select the corrected WO in the channel")
    realign: bool = Field(True, description="swivel the probe parallel to the new infeed axis")
    retract: bool = Field(True, description="retract along the tool axis before swivelling")
    position_rotary: bool = Field(True, description="turn the rotary axis to align the workpiece")


@router.get("/{session_id}/setup-support", name="api_setup_support")
def setup_support_screen(session_id: Annotated[str, Path(min_length=1, max_length=64)], services: ServicesDep, workflow: WorkflowDep) -> dict:
    """The activation screen: results, corrected WO, toggle fields, texts."""
    return setup_support.screen_model(workflow, services.machine, session_id)


@router.post("/{session_id}/setup-support", name="api_setup_support_carry_out", dependencies=[needs("jog")])
def carry_out(session_id: Annotated[str, Path(min_length=1, max_length=64)], services: ServicesDep, workflow: WorkflowDep,
              body: CarryOutBody | None = None) -> dict:
    """NC Start on the activation screen."""
    choices = setup_support.Choices(**(body or CarryOutBody()).model_dump())
    return setup_support.carry_out(workflow, services.machine, session_id, choices, db=services.db)


@router.delete("/{session_id}/setup-support", name="api_setup_support_leave", dependencies=[needs("measure")])
def leave(session_id: Annotated[str, Path(min_length=1, max_length=64)], workflow: WorkflowDep) -> dict:
    """``<<``: leave without activating (the written correction stays)."""
    return setup_support.leave(workflow, session_id)
