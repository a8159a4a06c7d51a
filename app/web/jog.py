"""The JOG basic screen, with the probe lamps and the probe test (design.md §10.4)."""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Request
from fastapi.responses import RedirectResponse

from app.access.deps import needs
from app.deps import ProbeTestDep
from app.errors import HmiError

from .templating import render_block, render_screen, url_path

router = APIRouter()


@router.get("/", name="root")
def root(request: Request):
    return RedirectResponse(url_path(request, "jog_screen"), status_code=303)


@router.get("/jog", name="jog_screen")
def jog_screen(request: Request, probe_test: ProbeTestDep):
    return render_screen(request, "jog.html", {"screen": "jog", "probe_test": probe_test.state()})


@router.get("/jog/alarms", name="jog_alarms", dependencies=[needs("view")])
def jog_alarms(request: Request):
    """The alarm pane, fetched when the live feed reports a new machine state (as the header is)."""
    return render_block(request, "jog.html", "alarm_pane")


@router.get("/jog/probe-test", name="jog_probe_test_state", dependencies=[needs("view")])
def probe_test_state(request: Request, probe_test: ProbeTestDep):
    """The probe pane (lamps and test), fetched when the live feed reports a new machine state."""
    return render_block(request, "jog.html", "probe_pane", {"probe_test": probe_test.state()})


@router.post("/jog/probe-test", name="jog_probe_test", dependencies=[needs("jog")])
def start_probe_test(request: Request, probe_test: ProbeTestDep, probe: Annotated[str, Form()] = "workpiece"):
    """The softkey: start the probe test; a probe that cannot show a switch says why."""
    try:
        state = probe_test.start(probe)
    except HmiError as exc:
        return render_block(request, "jog.html", "probe_pane", {"probe_test": probe_test.state(),
                                                                "probe_test_error": exc.message})
    return render_block(request, "jog.html", "probe_pane", {"probe_test": state})
