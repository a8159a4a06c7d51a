"""PLC test page ``/plc``: DB19.DBB43 as LEDs with toggles for bits 0..3 (jog-measuring §3.2) and the
readiness checklist (jog-measuring §1.6 [I]). Both parts refresh by htmx polling."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Request

from app.access.deps import needs
from app.deps import PlcDep, ServicesDep
from app.errors import HmiError
from app.i18n import gettext
from app.services.commissioning import CommissioningService
from app.services.plc import MEANINGS
from app.services.readiness import ReadinessService

from . import plc_texts  # noqa: F401  (registers the PLC screen's texts)
from .templating import render_block, render_screen

router = APIRouter()


def _byte_ctx(services, message: str = "", level: str = "info") -> dict:
    return {"plc": services.plc.snapshot(), "meanings": MEANINGS, "plc_message": message, "plc_level": level}


def _readiness_ctx(services) -> dict:
    return {"readiness": ReadinessService(services).report()}


def _commissioning_ctx(services) -> dict:
    """The start-up checks of manual ch. 9–10 with their rules in the operator's language."""
    return {"commissioning": [(c, c.rule_text(gettext)) for c in CommissioningService(services).checks()]}


@router.get("/plc", name="plc_screen")
def plc_screen(request: Request, services: ServicesDep):
    return render_screen(request, "plc.html", {"screen": "plc", **_byte_ctx(services), **_readiness_ctx(services),
                                               **_commissioning_ctx(services)})


@router.get("/plc/db19", name="plc_db19")
def plc_byte(request: Request, services: ServicesDep):
    return render_block(request, "plc.html", "plc_byte", _byte_ctx(services))


@router.post("/plc/db19/bit", name="plc_db19_bit", dependencies=[needs("measure")])
def plc_toggle(request: Request, services: ServicesDep, plc: PlcDep, bit: Annotated[str, Form()],
               value: Annotated[str, Form()]):
    try:
        number = int(bit) if bit.strip().lstrip("-").isdigit() else bit
        plc.write(number, value == "1")
    except HmiError as exc:
        return render_block(request, "plc.html", "plc_byte", _byte_ctx(services, exc.message, "error"))
    return render_block(request, "plc.html", "plc_byte", _byte_ctx(services))


@router.post("/plc/db19/mode", name="plc_db19_mode", dependencies=[needs("settings")])
def plc_mode(request: Request, services: ServicesDep, plc: PlcDep,
             auto_release: Annotated[str | None, Form()] = None):
    plc.set_auto_release(auto_release in ("on", "true", "1"))
    return render_block(request, "plc.html", "plc_byte", _byte_ctx(services))


@router.get("/plc/readiness", name="plc_readiness")
def readiness_block(request: Request, services: ServicesDep):
    return render_block(request, "plc.html", "readiness", _readiness_ctx(services))
