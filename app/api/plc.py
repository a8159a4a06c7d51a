"""PLC interface DB19.DBB43 (spec/jog-measuring.md §3.2) and the readiness checklist (jog-measuring §1.6 [I])."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Query
from pydantic import BaseModel, ConfigDict, Field, StrictBool, StrictInt

from app.access.deps import needs
from app.deps import ServicesDep
from app.services.plc import PlcSimulator
from app.services.readiness import ReadinessService
from app.workflow.tasks import TASKS

router = APIRouter(tags=["plc"])


class BitBody(BaseModel):
    model_config = ConfigDict(extra="forbid", json_schema_extra={"examples": [{"bit": 0, "value": True}]})
    # the schema states the range; the PLC simulator's own check keeps its message for the rest
    bit: StrictInt = Field(description="0..3: request 'point bit+1 invalid' (bits 4..7 belong to the HMI)",
                           json_schema_extra={"minimum": 0, "maximum": 3})
    value: StrictBool


class ModeBody(BaseModel):
    model_config = ConfigDict(extra="forbid")
    auto_release: StrictBool = Field(description="the PLC drops bit n-1 once the HMI cleared bit 4+n-1")


def plc_of(services) -> PlcSimulator:
    return services.plc


@router.get("/plc/db19", name="api_plc_db19")
def db19(services: ServicesDep) -> dict:
    """DB19.DBB43: the byte, bits 0..7 and the P1..P4 view."""
    return plc_of(services).snapshot()


@router.put("/plc/db19/dbb43", name="api_plc_dbb43_write", dependencies=[needs("measure")])
def write_bit(body: BitBody, services: ServicesDep) -> dict:
    """The PLC writes one of bits 0..3 (discard request for P1..P4); answers the byte after the HMI scan."""
    return plc_of(services).write(body.bit, body.value)


@router.put("/plc/db19/mode", name="api_plc_mode", dependencies=[needs("settings")])
def set_mode(body: ModeBody, services: ServicesDep) -> dict:
    return plc_of(services).set_auto_release(body.auto_release)


@router.get("/readiness", name="api_readiness")
def readiness(services: ServicesDep, task: Annotated[str | None, Query(
        json_schema_extra={"enum": sorted(TASKS)}, description="a measuring task's name")] = None) -> dict:
    """Prerequisites checklist; with ``?task=`` also whether that task is ready and what blocks it."""
    return ReadinessService(services).report(task)
