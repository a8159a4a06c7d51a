"""Health, machine state and motion, scenario loading. Motion calls block until the move ends."""

from __future__ import annotations

from typing import Annotated, Literal

from fastapi import APIRouter, Body, Query, Request, Response
from pydantic import BaseModel, ConfigDict, Field, StrictBool, StrictFloat, StrictInt, StrictStr

from app.access.deps import needs
from app.deps import MachineDep
from app.errors import InvalidInput
from app.machine.scenario import load_scenario
from app.records import MAX_TOOL
from app.services import trainer
from app.services.scenarios import with_time_scale

router = APIRouter(tags=["machine"])


class _Body(BaseModel):
    # JSON booleans are never numbers (design.md §9.1): every number is a StrictFloat/StrictInt
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)


class JogBody(_Body):
    axis: str
    distance: StrictFloat
    feed: StrictFloat | None = None


class ContinuousJogBody(_Body):
    axis: str
    direction: Literal[-1, 1]
    feed: StrictFloat | None = None
    # issue 24 §6: the tab (its live feed's ``tab``) and its key press; a renewal of a released
    # press is ignored, and the jog stops when that tab's live feed drops
    tab: str | None = Field(None, min_length=1, max_length=64, pattern=r"^[A-Za-z0-9_-]+$")
    press: StrictInt | None = Field(None, ge=1, le=2**31)
    seq: StrictInt | None = Field(None, ge=0, le=2**31, description="renewal number within the press")


class GotoBody(_Body):
    X: StrictFloat | None = None
    Y: StrictFloat | None = None
    Z: StrictFloat | None = None
    A: StrictFloat | None = None
    B: StrictFloat | None = None
    C: StrictFloat | None = None
    coords: Literal["WCS", "MCS"] = "WCS"
    feed: StrictFloat | None = None


class OverrideBody(_Body):
    feed: StrictFloat = Field(ge=0, le=120)


class ToolBody(_Body):
    tool: Annotated[StrictInt, Field(ge=0, le=MAX_TOOL)] | StrictStr | None


class ActivateBody(_Body):
    offset: str


class ProbeBody(_Body):
    direction: list[StrictFloat] = Field(min_length=3, max_length=3)
    distance: StrictFloat
    feed: StrictFloat
    coords: Literal["WCS", "MCS"] = "MCS"


@router.get("/health", name="api_health")
def health() -> dict:
    return {"status": "ok"}


@router.get("/machine", name="api_machine", response_model=dict)
async def machine_state(request: Request) -> Response:
    # the snapshot's bytes, encoded once per state version (issue 30 item 2); on the event loop: a
    # snapshot waits for nothing (the machines' status locks are held for a read, the write count
    # is a WAL read), and a worker-thread hop would cost more than the answer; the service read
    # directly (a dependency costs more than the answer too)
    return Response(request.app.state.services.machine.snapshot().json, media_type="application/json")


@router.post("/machine/jog", name="api_machine_jog", dependencies=[needs("jog")])
def jog(body: JogBody, machine: MachineDep) -> dict:
    return machine.jog(body.axis, body.distance, body.feed)


@router.post("/machine/jog/continuous", name="api_machine_jog_continuous", dependencies=[needs("jog")])
def jog_continuous(body: ContinuousJogBody, machine: MachineDep) -> dict:
    """Starts a continuous jog that runs until ``/machine/stop``, Reset or a limit/alarm."""
    return machine.jog_continuous(body.axis, body.direction, body.feed, body.tab, body.press)


@router.post("/machine/stop", name="api_machine_stop", dependencies=[needs("view")])   # stopping is never locked
def stop(machine: MachineDep) -> dict:
    return machine.stop()


@router.post("/machine/goto", name="api_machine_goto", dependencies=[needs("jog")])
def goto(body: GotoBody, machine: MachineDep) -> dict:
    target = body.model_dump(include={"X", "Y", "Z", "A", "B", "C"}, exclude_none=True)
    return machine.goto(target, body.coords, body.feed)


@router.post("/machine/reset", name="api_machine_reset", dependencies=[needs("view")])  # Reset is never locked
def reset(machine: MachineDep) -> dict:
    return machine.reset()


@router.put("/machine/override", name="api_machine_override", dependencies=[needs("jog")])
def override(body: OverrideBody, machine: MachineDep) -> dict:
    return machine.set_override(body.feed)


@router.post("/machine/tool", name="api_machine_tool", dependencies=[needs("jog")])
def tool_change(body: ToolBody, machine: MachineDep) -> dict:
    return machine.change_tool(body.tool)


@router.post("/machine/activate", name="api_machine_activate", dependencies=[needs("jog")])
def activate(body: ActivateBody, machine: MachineDep) -> dict:
    return machine.activate(body.offset)


@router.post("/machine/probe", name="api_machine_probe", dependencies=[needs("jog")])
def probe(body: ProbeBody, machine: MachineDep) -> dict:
    return machine.probe(body.direction, body.distance, body.feed, body.coords)


@router.get("/machine/scene", name="api_machine_scene")
def scene(request: Request) -> dict:
    """The true scene (MCS) for the machine view: block, circles, rects, probe. With the setting
    ``trainer_hide_part`` only the fixtures and the probe where the NC puts it (``"hidden": true``)."""
    return trainer.visible_scene(request.app.state.services)


@router.get("/sim/setup-error", name="api_sim_setup_error")
def setup_error(request: Request, offset: Annotated[str | None, Query(max_length=16)] = None) -> dict:
    """The trainer's answer: the stored zero offset (default: the active one) against the hidden
    part, computed by the simulator. ``error`` = stored entries − those of the right set-up (the
    part's nearest reference point at the WCS zero, ``reference``), mm and degrees."""
    return trainer.setup_error(request.app.state.services, offset)


class MachinePartBody(_Body):
    scatter_sigma: StrictFloat = Field(0.0, ge=0.0, le=1.0, description="scatter of the cut sizes, mm (1σ)")


@router.post("/sim/machine-part", name="api_sim_machine_part", dependencies=[needs("scenario")])
def machine_part(machine: MachineDep, body: Annotated[MachinePartBody | None, Body()] = None) -> dict:
    """The next part of the machined-part series replaces the workpiece (design.md §9.3): its
    features made by ``machined_by`` tools are cut with the tools' true size against the tool
    data the control holds now; then the tools wear by ``wear_per_part``."""
    return machine.machine_part((body or MachinePartBody()).scatter_sigma)


class SimProbeBody(_Body):
    probe: Literal["workpiece", "tool"] = "workpiece"
    deflect: StrictBool | None = Field(None, description="true: deflect the stylus by hand, false: let go")
    battery: StrictFloat | None = Field(None, ge=0.0, le=1.0, description="a radio probe's charge 0..1")
    armed: StrictBool | None = Field(None, description="switch a radio probe on (true) or off (false)")


@router.post("/sim/probe", name="api_sim_probe", dependencies=[needs("jog")])
def sim_probe(body: SimProbeBody, machine: MachineDep) -> dict:
    """The operator's hand on a probe of the simulator (design.md §10.4): deflect or release it,
    change a radio probe's battery, switch it on or off. Answers the ``GET /api/machine`` body."""
    return machine.set_probe(body.probe, body.deflect, body.battery, body.armed)


@router.post("/sim/scenario", name="api_sim_scenario", dependencies=[needs("scenario")])
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
    answer = machine.load_scenario(scenario, reset_data=reset_data)
    with request.app.state.services.db.unit() as unit:       # who loaded it (and wiped the data)
        unit.add_audit("scenario", "scenario", None, {"reset_data": reset_data, "seed": data.get("seed")}, "api")
    return answer
