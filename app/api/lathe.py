"""The lathe's own data and commands (turning.md §10.2, a product extension): reference grooves
``_KB`` and SPOS of the main spindle. Everything else of the lathe goes through the common
routes (``/api/machine``, ``/api/tools``, ``/api/tool-probes``, ``/api/probes``, ``/api/measure``)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Path
from pydantic import BaseModel, ConfigDict, StrictFloat

from app.access.deps import needs
from app.deps import MachineDep, ServicesDep
from app.services.lathe_data import GROOVE_RECORDS, GrooveService

router = APIRouter(prefix="/lathe", tags=["lathe"])
GrooveNumber = Annotated[int, Path(ge=1, le=GROOVE_RECORDS)]


class SposBody(BaseModel):
    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    angle: StrictFloat


class GrooveBody(BaseModel):
    """The _KB values as entered (machine-related radius values; 0 or absent = not entered)."""

    model_config = ConfigDict(extra="forbid", allow_inf_nan=False)
    x_minus: StrictFloat | None = None
    x_plus: StrictFloat | None = None
    bottom_z: StrictFloat | None = None
    z_minus: StrictFloat | None = None
    z_plus: StrictFloat | None = None
    top_x: StrictFloat | None = None
    bottom_x: StrictFloat | None = None


@router.get("/grooves", name="api_lathe_grooves")
def list_grooves(services: ServicesDep) -> list[dict]:
    return GrooveService(services.db).list()


@router.get("/grooves/{n}", name="api_lathe_groove_get")
def get_groove(n: GrooveNumber, services: ServicesDep) -> dict:
    return GrooveService(services.db).get(n)


@router.put("/grooves/{n}", name="api_lathe_groove_put", dependencies=[needs("probe_data")])
def put_groove(n: GrooveNumber, body: GrooveBody, services: ServicesDep) -> dict:
    return GrooveService(services.db).put(n, body.model_dump(exclude_none=True))


@router.post("/spos", name="api_lathe_spos", dependencies=[needs("jog")])
def spos(body: SposBody, machine: MachineDep) -> dict:
    """SPOS of the main spindle: the clamped workpiece turns (its eccentricity with it)."""
    return machine.spindle_position(body.angle)
