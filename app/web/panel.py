"""Shared chrome: status header, live position display, machine control panel (MCP) and its actions.

Actions answer with the ``message`` block (swapped out of band into the message line), so a
refused jog shows its reason without leaving the screen.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Annotated

from fastapi import APIRouter, Form, Request
from fastapi.responses import HTMLResponse

from app.access.deps import needs
from app.deps import MachineDep
from app.errors import HmiError
from app.services.machine_service import MAX_FEED

from .panel_state import PanelState
from .templating import render_block

router = APIRouter()
DIRECTIONS = {"+": 1, "-": -1}


def message(request: Request, text: str = "", level: str = "info", headers: dict | None = None):
    return render_block(request, "base.html", "message", {"message": text, "level": level}, headers=headers)


@router.get("/ui/header", name="panel_header")
def header(request: Request):
    return render_block(request, "base.html", "header_status")


@router.get("/ui/position", name="panel_position")
async def position(request: Request):
    """The live position values, rendered once per state version and what else they show (the
    tab's panel, the settings, the language): a poll at rest costs no template (issue 30 item 2;
    app/web/fast_reads.py answers a repeated poll before FastAPI's routing).
    On the event loop like ``GET /api/machine``: a hit waits for nothing, a worker-thread hop would
    cost more than the answer."""
    snapshot, gud, made, key = _position_cache(request)
    body = made.get(key)
    if body is None:
        body = render_block(request, "base.html", "position_values", {"status": snapshot.body, "gud": gud}).body
        made[key] = body
    return HTMLResponse(body)


def _position_cache(request: Request) -> tuple:
    """(snapshot, settings, the blocks made for them, this request's key): the blocks are kept
    while the machine's snapshot and the settings stay the same (at most 64 panels and languages)."""
    services = request.app.state.services
    machine = services.machine
    snapshot = machine.snapshot()
    gud = services.settings.get()
    key = (PanelState.of(request, machine.axes), getattr(request.state, "language", None),
           request.scope.get("root_path", ""))
    cache = getattr(request.app.state, "position_cache", None)
    if cache is None or cache[0] is not snapshot or not (cache[1] is gud or cache[1] == gud) or len(cache[2]) > 64:
        cache = (snapshot, gud, dict[tuple, bytes]())
        request.app.state.position_cache = cache
    return snapshot, gud, cache[2], key


def cached_position(request: Request) -> bytes | None:
    """The position block's bytes for this request if made already for the current state, else None."""
    _snapshot, _gud, made, key = _position_cache(request)
    return made.get(key)


def _panel(request: Request, machine, **chosen) -> PanelState:
    """The tab's panel (headers), with the value a selection key just chose."""
    panel = PanelState.of(request, machine.axes)
    return replace(panel, **{k: v for k, v in chosen.items() if v is not None})


@router.post("/ui/panel/coords", name="panel_coords", dependencies=[needs("view")])
def set_coords(request: Request, machine: MachineDep, coords: Annotated[str, Form()]):
    panel = _panel(request, machine, coords=coords if coords in ("WCS", "MCS") else None)
    return render_block(request, "base.html", "position", {"panel": panel})


@router.post("/ui/panel/axis", name="panel_axis", dependencies=[needs("jog")])
def set_axis(request: Request, machine: MachineDep, axis: Annotated[str, Form()]):
    panel = _panel(request, machine, axis=axis if axis in machine.axes else None)
    return render_block(request, "base.html", "mcp", {"panel": panel})


@router.post("/ui/panel/increment", name="panel_increment", dependencies=[needs("jog")])
def set_increment(request: Request, machine: MachineDep, increment: Annotated[str, Form()]):
    panel = _panel(request, machine, increment=increment if increment in PanelState.INCREMENTS else None)
    return render_block(request, "base.html", "mcp", {"panel": panel})


def _jog_feed(request: Request, machine, rapid: str | None = None) -> float | None:
    """The tab's jog feed (mm/min): its feed choice, or RAPID times the rapid override; None:
    the machine's own jog feed."""
    panel = PanelState.of(request, machine.axes)
    traverse = machine.rapid_feed
    feed = panel.jog_feed(traverse, None if rapid is None else rapid == "on")
    return None if feed is None else min(feed, MAX_FEED)


def _jog_axis(request: Request, machine, axis: str | None) -> str:
    """The axis the command names (the tab's selection), never another tab's."""
    return axis if axis is not None and axis in machine.axes else PanelState.of(request, machine.axes).axis


@router.post("/ui/jog", name="panel_jog", dependencies=[needs("jog")])
def jog(request: Request, machine: MachineDep, direction: Annotated[str, Form()],
        axis: Annotated[str | None, Form()] = None, increment: Annotated[str | None, Form()] = None):
    """One increment of the tab's axis (blocks until the move ends, like the API)."""
    step = PanelState.INCREMENTS.get(increment or PanelState.of(request, machine.axes).increment)
    if direction not in DIRECTIONS or step is None:
        return message(request, "Select an increment (INC) for a single jog step", "error")
    try:
        machine.jog(_jog_axis(request, machine, axis), DIRECTIONS[direction] * step, _jog_feed(request, machine))
    except HmiError as exc:
        return message(request, exc.message, "error")
    return message(request)


@router.post("/ui/panel/jogfeed", name="panel_jog_feed", dependencies=[needs("jog")])
def set_jog_feed(request: Request, machine: MachineDep, feed: Annotated[str | None, Form()] = None,
                 rapid: Annotated[str | None, Form()] = None, rov: Annotated[str | None, Form()] = None):
    """The tab's jog feed, RAPID key and rapid override (kept by the tab, like axis and increment)."""
    panel = _panel(request, machine, feed=feed if feed in PanelState.FEEDS else None,
                   rov=rov if rov in PanelState.RAPID_OVERRIDES else None,
                   rapid=None if rapid not in ("on", "off") else rapid == "on")
    return render_block(request, "base.html", "mcp", {"panel": panel})


HANDWHEEL_MAX_DETENTS = 1000      # one request: at most 10 turns of a 100-detent wheel


@router.post("/ui/handwheel", name="panel_handwheel", dependencies=[needs("jog")])
def handwheel(request: Request, machine: MachineDep, detents: Annotated[str, Form()],
              axis: Annotated[str | None, Form()] = None, increment: Annotated[str | None, Form()] = None):
    """The virtual handwheel: ``detents`` (signed) times the tab's increment on its axis, at the jog feed."""
    step = PanelState.INCREMENTS.get(increment or PanelState.of(request, machine.axes).increment)
    try:
        count = int(detents)
    except ValueError:
        return message(request, "Handwheel: the number of detents must be a whole number", "error")
    if step is None:
        return message(request, "Handwheel: select an increment (INC 1 … 1000) for the distance per detent", "error")
    if count == 0 or abs(count) > HANDWHEEL_MAX_DETENTS:
        return message(request, f"Handwheel: 1 to {HANDWHEEL_MAX_DETENTS} detents at a time", "error")
    try:
        machine.jog(_jog_axis(request, machine, axis), count * step, _jog_feed(request, machine))
    except HmiError as exc:
        return message(request, exc.message, "error")
    return message(request)


@router.post("/ui/jog/start", name="panel_jog_start", dependencies=[needs("jog")])
def jog_start(request: Request, machine: MachineDep, direction: Annotated[str, Form()],
              axis: Annotated[str | None, Form()] = None, rapid: Annotated[str | None, Form()] = None,
              tab: Annotated[str | None, Form()] = None, press: Annotated[str | None, Form()] = None):
    """Press-and-hold: starts or renews the continuous jog (hold-to-run: the tab renews it while
    the key is held; without a renewal the axis stops after 0.5 s, design.md §9.1)."""
    if direction not in DIRECTIONS:
        return message(request, "direction must be + or -", "error")
    try:
        machine.jog_continuous(_jog_axis(request, machine, axis), DIRECTIONS[direction],
                               _jog_feed(request, machine, rapid), *_held_by(tab, press))
    except HmiError as exc:
        return message(request, exc.message, "error")
    return message(request)


def _held_by(tab: str | None, press: str | None) -> tuple[str | None, int | None]:
    """The tab and key press of a hold-to-run request (issue 24 §6); malformed: none (the old way)."""
    if not tab or len(tab) > 64 or not tab.replace("-", "").replace("_", "").isalnum():
        return None, None
    try:
        number = int(press) if press else None
    except ValueError:
        number = None
    return tab, (number if number is not None and 0 < number < 2**31 else None)


@router.post("/ui/jog/stop", name="panel_jog_stop", dependencies=[needs("view")])
def jog_stop(request: Request, machine: MachineDep, tab: Annotated[str | None, Form()] = None,
             press: Annotated[str | None, Form()] = None):
    machine.stop_jog(*_held_by(tab, press))
    return message(request)


@router.post("/ui/override", name="panel_override", dependencies=[needs("jog")])
def override(request: Request, machine: MachineDep, feed: Annotated[str, Form()]):
    try:
        machine.set_override(float(feed))
    except (ValueError, HmiError):
        return message(request, "Feed override must be 0..120 %", "error")
    return message(request)


@router.post("/ui/reset", name="panel_reset", dependencies=[needs("view")])
def reset(request: Request, machine: MachineDep):
    machine.reset()
    # screens listen with hx-trigger="hmi-reset from:body" (jog-measuring §1.4: Reset aborts measuring)
    return message(request, headers={"HX-Trigger": "hmi-reset"})


@router.post("/ui/ncstart", name="panel_nc_start", dependencies=[needs("measure")])
def nc_start(request: Request):
    """NC Start outside a measuring input screen: no function (the JOG basic screen)."""
    return message(request, "NC Start: no measuring function selected", "info")
