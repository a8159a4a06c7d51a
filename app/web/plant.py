"""The plant screens (design.md §10.5): every machine on the shared database, one machine's parts
and measurements."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Path, Request

from app.deps import PlantDep
from app.errors import NotFoundError
from app.i18n import _

from .templating import render_screen

router = APIRouter()


def _when(iso: str | None) -> str:
    return (iso or "")[:19].replace("T", " ")


def _calibration(age_h: float | None) -> str:
    if age_h is None:
        return _("never")
    hours = f"{age_h:.1f}"
    return _("%(h)s h ago", h=hours)


def _row(machine: dict) -> dict:
    return {**machine, "seen": _when(machine["last_seen"]), "calibration": _calibration(machine["calibration_age_h"])}


def _verdicts() -> dict[str, str]:
    return {"ok": _("OK"), "rework": _("Rework"), "scrap": _("Scrap"), "not_decidable": _("Not decidable")}


@router.get("/plant", name="plant_screen")
def plant_screen(request: Request, plant: PlantDep):
    machines = [_row(m) for m in plant.overview()["machines"]]
    return render_screen(request, "plant.html", {"screen": "plant", "machines": machines, "detail": None})


@router.get("/plant/{name}", name="plant_machine_screen")
def plant_machine_screen(request: Request, plant: PlantDep, name: Annotated[str, Path(min_length=1, max_length=64)]):
    try:
        detail = _row(plant.machine(name))
    except KeyError:
        raise NotFoundError(_("There is no machine %(name)s on this database", name=name), field="name") from None
    return render_screen(request, "plant.html", {"screen": "plant", "machines": [], "detail": detail,
                                                 "verdicts": _verdicts()})
