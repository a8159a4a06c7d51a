"""Health, machine state and motion, scenario loading. Motion calls block until the move ends."""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter, Body, Request
from pydantic import BaseModel, ConfigDict, Field, StrictInt, StrictStr

from app.deps import MachineDep
from app.errors import InvalidInput
from app.machine.scenario import load_scenario
from app.services.scenarios import with_time_scale

router = APIRouter(tags=["machine"])


class _Body(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class JogBody(_Body):
    axis: str
    distance: float
    feed: float | None = None


class ContinuousJogBody(_Body):
    axis: str
    direction: Literal[-1, 1]
    feed: float | None = None


class GotoBody(_Body):
    X: float | None = None
    Y: float | None = None
    Z: float | None = None
    A: float | None = None
    B: float | None = None
    C: float | None = None
    coords: Literal["WCS", "MCS"] = "WCS"
    feed: float | None = None


class OverrideBody(_Body):
    feed: float = Field(ge=0, le=120)


class ToolBody(_Body):
    tool: StrictInt | StrictStr | None


class ActivateBody(_Body):
    offset: str


class ProbeBody(_Body):
    direction: list[float] = Field(min_length=3, max_length=3)
    distance: float
    feed: float
    coords: Literal["WCS", "MCS"] = "MCS"


@router.get("/health")
def health() -> dict:
    return {"status": "ok"}


@router.get("/machine")
def machine_state(machine: MachineDep) -> dict:
    return machine.status()


@router.post("/machine/jog")
def jog(body: JogBody, machine: MachineDep) -> dict:
    return machine.jog(body.axis, body.distance, body.feed)


@router.post("/machine/jog/continuous")
def jog_continuous(body: ContinuousJogBody, machine: MachineDep) -> dict:
    """Starts a continuous jog that runs until ``/machine/stop``, Reset or a limit/alarm."""
    return machine.jog_continuous(body.axis, body.direction, body.feed)


@router.post("/machine/stop")
def stop(machine: MachineDep) -> dict:
    return machine.stop()


@router.post("/machine/goto")
def goto(body: GotoBody, machine: MachineDep) -> dict:
    target = body.model_dump(include={"X", "Y", "Z", "A", "B", "C"}, exclude_none=True)
    return machine.goto(target, body.coords, body.feed)


@router.post("/machine/reset")
def reset(machine: MachineDep) -> dict:
    return machine.reset()


@router.put("/machine/override")
def override(body: OverrideBody, machine: MachineDep) -> dict:
    return machine.set_override(body.feed)


@router.post("/machine/tool")
def tool_change(body: ToolBody, machine: MachineDep) -> dict:
    return machine.change_tool(body.tool)


@router.post("/machine/activate")
def activate(body: ActivateBody, machine: MachineDep) -> dict:
    return machine.activate(body.offset)


@router.post("/machine/probe")
def probe(body: ProbeBody, machine: MachineDep) -> dict:
    return machine.probe(body.direction, body.distance, body.feed, body.coords)


@router.get("/machine/scene")
def scene(machine: MachineDep) -> dict:
    """The true scene (MCS) for the machine view: block, circles, rects, probe."""
    return machine.scene_geometry()


@router.post("/sim/scenario")
def load(request: Request, machine: MachineDep, body: Annotated[dict, Body()]) -> dict:
    data = dict(body)
    reset_data = data.pop("reset_data", False)
    if not isinstance(reset_data, bool):
        raise InvalidInput("reset_data: must be true or false", field="reset_data")
    try:
        scenario = load_scenario(data)
    except ValueError as exc:
        raise InvalidInput(str(exc), code="invalid_scenario") from None
    scenario = with_time_scale(scenario, request.app.state.settings.time_scale)
    return machine.load_scenario(scenario, reset_data=reset_data)
