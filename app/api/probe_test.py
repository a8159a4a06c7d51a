"""The probe test (design.md §10.4, app/services/probe_test.py): start it, read it, cancel it."""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter, Body
from pydantic import BaseModel, ConfigDict, Field, StrictFloat

from app.access.deps import needs
from app.deps import ProbeTestDep
from app.services.probe_test import DEFAULT_TIMEOUT_S, MAX_TIMEOUT_S

router = APIRouter(tags=["probes"])


class ProbeTestBody(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    probe: Literal["workpiece", "tool"] = "workpiece"
    timeout_s: StrictFloat = Field(DEFAULT_TIMEOUT_S, gt=0, le=MAX_TIMEOUT_S,
                                   description="how long the test waits for the probe to switch, s")


@router.post("/probe/test", name="api_probe_test", dependencies=[needs("jog")])
def start_probe_test(probe_test: ProbeTestDep, body: Annotated[ProbeTestBody | None, Body()] = None) -> dict:
    """Start the probe test: deflect the probe by hand within ``timeout_s``. ``state`` goes
    ``waiting`` → ``switched`` (the probe signal came on) → ``passed`` (it went off again), or
    ``not_switched``. 409 when the probe cannot show a switch (not in the spindle, not armed,
    already deflected, no tool probe)."""
    body = body or ProbeTestBody()
    return probe_test.start(body.probe, body.timeout_s)


@router.get("/probe/test", name="api_probe_test_state")
def probe_test_state(probe_test: ProbeTestDep) -> dict:
    """The running or last probe test: ``{"probe", "state", "started", "switched_at", "released_at", "after_s"}``."""
    return probe_test.state()


@router.delete("/probe/test", name="api_probe_test_cancel", dependencies=[needs("jog")])
def cancel_probe_test(probe_test: ProbeTestDep) -> dict:
    return probe_test.cancel()
