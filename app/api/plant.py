"""The plant view's JSON (design.md §10.5): what an MES dashboard polls."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Path, Query

from app.deps import PlantDep
from app.errors import NotFoundError

router = APIRouter(tags=["plant"])
MachineName = Annotated[str, Path(min_length=1, max_length=64)]


@router.get("/plant", name="api_plant")
def plant(plant: PlantDep) -> dict:
    """Every machine (HMI) on the shared database: ``{"machine" (this one), "time", "machines":
    [{"name", "last_seen", "online", "active_offset", "mode", "program_state", "last_measurement",
    "alarms", "calibrated_at", "calibration_age_h", "parts", "links"}]}``."""
    return plant.overview()


@router.get("/plant/series", name="api_plant_series")
def plant_series(plant: PlantDep, part_number: Annotated[str, Query(min_length=1, max_length=64)],
                 characteristic: Annotated[str, Query(min_length=1, max_length=80)]) -> dict:
    """One characteristic of a part number on every machine, in measuring order, by machine."""
    return plant.series(part_number, characteristic)


@router.get("/plant/{name}", name="api_plant_machine")
def plant_machine(plant: PlantDep, name: MachineName) -> dict:
    """One machine: its entry of ``GET /api/plant``, its newest parts with verdicts
    (``parts_list``) and measurements."""
    try:
        return plant.machine(name)
    except KeyError:
        raise NotFoundError(f"no machine {name!r} on this database", field="name") from None
