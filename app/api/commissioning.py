"""The commissioning checks of the measuring cycles (manual ch. 9–10, app.services.commissioning)."""

from __future__ import annotations

from fastapi import APIRouter

from app.deps import ServicesDep
from app.services.commissioning import CommissioningService

router = APIRouter()


@router.get("/commissioning/checks", name="api_commissioning_checks")
def commissioning_checks(services: ServicesDep) -> dict:
    """Each start-up check of the measuring cycles: the manual's section, the machine datum or cycle
    data it reads, the value the NC holds, the manual's rule and ``ok`` (None: not checked, the
    control gives no machine data); ``ok`` of all, ``failed`` how many fail."""
    return CommissioningService(services).report()
