"""Shared chrome: status header, live position display, machine control panel (MCP) and its actions.

Actions answer with the ``message`` block (swapped out of band into the message line), so a
refused jog shows its reason without leaving the screen.
"""

from __future__ import annotations

from typing import Annotated

from fastapi import APIRouter, Form, Request

from app.deps import MachineDep
from app.errors import HmiError
from app.services.machine_service import PanelState

from .templating import render_block

router = APIRouter()
DIRECTIONS = {"+": 1, "-": -1}


def message(request: Request, text: str = "", level: str = "info", headers: dict | None = None):
    return render_block(request, "base.html", "message", {"message": text, "level": level}, headers=headers)


@router.get("/ui/header")
def header(request: Request):
    return render_block(request, "base.html", "header_status")


@router.get("/ui/position")
def position(request: Request):
    return render_block(request, "base.html", "position_values")


@router.post("/ui/panel/coords")
def set_coords(request: Request, machine: MachineDep, coords: Annotated[str, Form()]):
    if coords in ("WCS", "MCS"):
        machine.panel.coords = coords
    return render_block(request, "base.html", "position")


@router.post("/ui/panel/axis")
def set_axis(request: Request, machine: MachineDep, axis: Annotated[str, Form()]):
    if axis in machine.axes:
        machine.panel.axis = axis
    return render_block(request, "base.html", "mcp")


@router.post("/ui/panel/increment")
def set_increment(request: Request, machine: MachineDep, increment: Annotated[str, Form()]):
    if increment in PanelState.INCREMENTS:
        machine.panel.increment = increment
    return render_block(request, "base.html", "mcp")


@router.post("/ui/jog")
def jog(request: Request, machine: MachineDep, direction: Annotated[str, Form()]):
    """One increment of the selected axis (blocks until the move ends, like the API)."""
    step = PanelState.INCREMENTS.get(machine.panel.increment)
    if direction not in DIRECTIONS or step is None:
        return message(request, "Select an increment (INC) for a single jog step", "error")
    try:
        machine.jog(machine.panel.axis, DIRECTIONS[direction] * step)
    except HmiError as exc:
        return message(request, exc.message, "error")
    return message(request)


@router.post("/ui/jog/start")
def jog_start(request: Request, machine: MachineDep, direction: Annotated[str, Form()]):
    """Press-and-hold: continuous jog until ``/ui/jog/stop`` (key released)."""
    if direction not in DIRECTIONS:
        return message(request, "direction must be + or -", "error")
    try:
        machine.jog_continuous(machine.panel.axis, DIRECTIONS[direction])
    except HmiError as exc:
        return message(request, exc.message, "error")
    return message(request)


@router.post("/ui/jog/stop")
def jog_stop(request: Request, machine: MachineDep):
    machine.stop()
    return message(request)


@router.post("/ui/override")
def override(request: Request, machine: MachineDep, feed: Annotated[str, Form()]):
    try:
        machine.set_override(float(feed))
    except (ValueError, HmiError):
        return message(request, "Feed override must be 0..120 %", "error")
    return message(request)


@router.post("/ui/reset")
def reset(request: Request, machine: MachineDep):
    machine.reset()
    # screens listen with hx-trigger="hmi-reset from:body" (spec §1.4: Reset aborts measuring)
    return message(request, headers={"HX-Trigger": "hmi-reset"})


@router.post("/ui/ncstart")
def nc_start(request: Request):
    """NC Start outside a measuring input screen: no function (the JOG basic screen)."""
    return message(request, "NC Start: no measuring function selected", "info")
