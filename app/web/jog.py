"""The JOG basic screen."""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import RedirectResponse

from app.access.deps import needs

from .templating import render_block, render_screen, url_path

router = APIRouter()


@router.get("/", name="root")
def root(request: Request):
    return RedirectResponse(url_path(request, "jog_screen"), status_code=303)


@router.get("/jog", name="jog_screen")
def jog_screen(request: Request):
    return render_screen(request, "jog.html", {"screen": "jog"})


@router.get("/jog/alarms", name="jog_alarms", dependencies=[needs("view")])
def jog_alarms(request: Request):
    """The alarm pane, fetched when the live feed reports a new machine state (as the header is)."""
    return render_block(request, "jog.html", "alarm_pane")
