"""The kinematics screen (design.md §10.6, docs/kinematics.md): measure a rotary axis on a calibration
sphere (CYCLE996-like), see the positions, the results and the deviations, and optimise the control's
kinematic data after confirming. The measurement runs through the same workflow as the API task
``kinematics.measure`` (one NC Start per position, then Calculate)."""

from __future__ import annotations

import math

from fastapi import APIRouter, Request

from app import checks
from app.access.deps import needs
from app.deps import ServicesDep, WorkflowDep
from app.errors import HmiError, InvalidInput
from app.i18n import _
from app.services.kinematics import KinematicsService

from .templating import render_screen

router = APIRouter()
TASK = "kinematics.measure"
DEFAULTS = {"x": "", "y": "", "z": "", "diameter": "25", "axis": "", "positions": "-60 -30 0 30 60", "mode": "check"}


def _number(text: str, label: str) -> float:
    """A typed number (app.checks.parse_number: ASCII digits, a point or a comma); the screen's
    own words when it is none."""
    try:
        return checks.parse_number(text, label)
    except InvalidInput:
        raise HmiError(_("%(field)s: enter a number", field=label), field=label) from None


def _params(form: dict) -> dict:
    positions = [_number(t, _("Positions")) for t in str(form.get("positions", "")).replace(";", " ").split()]
    return {"sphere": {"center": [_number(form.get(k, ""), _("Sphere centre") + " " + k.upper()) for k in "xyz"],
                       "diameter": _number(form.get("diameter", ""), _("Sphere diameter"))},
            "axis": form.get("axis"), "positions": positions, "mode": form.get("mode", "check")}


def _picture(result: dict | None) -> dict | None:
    """Positions on the circle of sphere centres, as SVG coordinates (unit circle scaled to 80)."""
    if not result:
        return None
    spheres = result["spheres"]
    axis = next(iter(result["axes"]))
    sense = -1.0 if result.get("unit") == "table" else 1.0
    dots = [{"angle": s["angle"], "x": 100 + 80 * math.cos(math.radians(sense * s["angle"] - 90)),
             "y": 100 + 80 * math.sin(math.radians(sense * s["angle"] - 90))} for s in spheres]
    return {"axis": axis, "dots": dots}


def _screen(request: Request, services, form: dict, result: dict | None = None, message: str = "",
            status: int = 200):
    lines = KinematicsService(services.db, services.machine).get()
    form = {**DEFAULTS, **{k: v for k, v in form.items() if v is not None}}
    if not form["axis"] and lines:
        form["axis"] = sorted(lines)[0]
    return render_screen(request, "kinematics.html", {
        "screen": "kinematics", "form": form, "lines": lines, "result": result, "message": message,
        "picture": _picture(result)}, status_code=status)


@router.get("/kinematics", name="kinematics_screen")
def kinematics_screen(request: Request, services: ServicesDep):
    return _screen(request, services, {})


@router.post("/kinematics/form", name="kinematics_form", dependencies=[needs("measure")])
async def redraw(request: Request, services: ServicesDep):
    """The mode changed: draw again (optimise asks before it measures)."""
    form = {k: str(v) for k, v in (await request.form()).items() if k != "csrf_token"}
    return _screen(request, services, form)


@router.post("/kinematics/measure", name="kinematics_measure", dependencies=[needs("measure")])
async def measure(request: Request, services: ServicesDep, workflow: WorkflowDep):
    """All positions one after the other, then Calculate (in ``optimise`` the screen asked first)."""
    form = {k: str(v) for k, v in (await request.form()).items() if k != "csrf_token"}
    try:
        params = _params(form)
        session = workflow.create(TASK, params)
        try:
            for _slot in session.slots:
                workflow.start(session.id)
            answer = workflow.calculate(session.id)
        finally:
            if workflow.session is not None and workflow.session.id == session.id:
                workflow.delete(session.id)
    except HmiError as exc:
        return _screen(request, services, form, message=exc.message, status=200)
    written = answer["result"].get("written")
    message = _("Measured kinematics written into the machine data") if written else _("Measured: nothing written")
    return _screen(request, services, form, result=answer["result"], message=message)
