"""The probe test and the repeatability check (design.md §10.4, app/services/probe_test.py,
app/services/probe_health.py)."""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter, Body, Path
from pydantic import BaseModel, ConfigDict, Field, StrictFloat

from app.access.deps import needs
from app.deps import ProbeHealthDep, ProbeTestDep
from app.records import MAX_PROBE
from app.services.probe_test import DEFAULT_TIMEOUT_S, MAX_TIMEOUT_S

router = APIRouter(tags=["probes"])
ProbeNumber = Annotated[int, Path(ge=1, le=MAX_PROBE, description=f"probe record number, 1..{MAX_PROBE}")]


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


@router.post("/probes/{n}/repeatability", name="api_probe_repeatability", dependencies=[needs("measure")])
def probe_repeatability(n: ProbeNumber, health: ProbeHealthDep, body: Annotated[dict | None, Body()] = None) -> dict:
    """Repeatability check (design.md §10.4, ISO 230-10 §7.1): from the current position the probe
    finds the face ahead (``direction`` "X+" … "Z-", default "Z-"; or ``directions``, e.g. the four
    of a ring gauge from its centre), then probes it ``touches`` times (default 10) from
    ``clearance`` mm before it at the measuring feed. Answers ``{"n", "two_sigma", "range", "at",
    "limit", "exceeded", "deviations", "calibration_id"}`` (mm); record ``n`` keeps it as
    ``repeatability``. 409 when the probe is not ready or finds no face; nothing is stored then."""
    return health.repeatability(n, body or {})


@router.get("/probes/{n}/history", name="api_probe_history")
def probe_history(n: ProbeNumber, health: ProbeHealthDep, probe: Literal["workpiece", "tool"] = "workpiece") -> list[dict]:
    """The record's calibrations, repeatability checks and invalidations, newest first."""
    return health.history(probe, n)
