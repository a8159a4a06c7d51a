"""The activation screen of the set-up support (spec/jog-measuring.md §6.2, manual §4.3.9).

Left: the measuring function just executed and its result (in the WCS active while measuring);
right: the measuring-WO values and the corrected WO (before/after), the toggle fields, the top
text line (changes with the answers), the dialog line. NC Start carries it out, ``<<`` leaves
without activating. Afterwards the measuring function's input screen is shown again.
"""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import Response

from app.access.deps import needs
from app.errors import WorkflowError
from app.workflow import setup_support as support

from . import task_screens
from .task_screens import PAGES
from .templating import is_htmx, render_screen, softkey, url_path, vkeys

router = APIRouter()
TOGGLE_NAMES = ("activate", "realign", "retract", "position_rotary")


def task_href(request: Request, task: str) -> tuple[str, str]:
    """(label, URL) of the input screen of ``task`` in the softkey tree."""
    page = PAGES.get(task)
    if page is None:
        return task, url_path(request, "measure_workpiece_menu")
    return page.label, page.href(request)


def choices_from(form) -> support.Choices:
    return support.Choices(**{n: str(form.get(n, "yes")).lower() in ("yes", "1", "true", "on")
                              for n in TOGGLE_NAMES})


def _render(request: Request, session_id: str, choices: support.Choices | None = None,
            notice: str = ""):
    services = request.app.state.services
    model = support.screen_model(services.workflow, services.machine, session_id)
    if choices is not None:
        for t in model["toggles"]:
            t["value"] = bool(getattr(choices, t["name"])) and t.get("enabled", True)
        model["top_line"] = support.top_line({"reasons": model["reasons"]}, choices, model["swivel"])
    return render_screen(request, "setup_support.html", {
        "screen": "measure_workpiece", "m": model, "task_label": task_href(request, model["task"])[0],
        "session_id": session_id, "notice": notice,
        "vkeys": vkeys([], softkey(request, "<<", "setup_support_leave", post=True, session_id=session_id)),
        "message": notice or model["message"]})


@router.get("/measure/setup-support/{session_id}", name="setup_support_screen")
def screen(request: Request, session_id: str):
    return _render(request, session_id)


@router.post("/measure/setup-support/{session_id}/toggle", name="setup_support_toggle", dependencies=[needs("measure")])
async def toggle(request: Request, session_id: str):
    """A toggle field changed: the top line follows the answers."""
    return _render(request, session_id, choices_from(await request.form()))


@router.post("/measure/setup-support/{session_id}/start", name="setup_support_start", dependencies=[needs("jog")])
async def nc_start(request: Request, session_id: str):
    """NC Start: carry out, then back to the measuring function's input screen."""
    services = request.app.state.services
    choices = choices_from(await request.form())
    try:
        outcome = support.carry_out(services.workflow, services.machine, session_id, choices, db=services.db)
    except WorkflowError as exc:
        return _render(request, session_id, choices, notice=exc.message)
    return _back(request, session_id, outcome)


@router.post("/measure/setup-support/{session_id}/leave", name="setup_support_leave", dependencies=[needs("measure")])
def leave(request: Request, session_id: str):
    """``<<``: leave without activating; the correction stays written."""
    services = request.app.state.services
    try:
        support.leave(services.workflow, session_id)
    except WorkflowError:
        pass
    return _back(request, session_id, {"messages": ["Left without activating: the compensation stays "
                                                    "written in the WO"]})


def _back(request: Request, session_id: str, outcome: dict) -> Response:
    """Back to the measuring function's input screen, saying what was done ("G54 activated"). An
    htmx request gets the input screen's blocks (the header, position display and control panel
    stay; the URL is pushed, so a reload shows the same screen), a plain form a redirect."""
    services = request.app.state.services
    try:
        task = services.workflow.get(session_id).task
    except WorkflowError:
        task = ""
    _label, href = task_href(request, task)
    if not is_htmx(request):
        return Response(status_code=303, headers={"Location": href})
    if task not in PAGES:           # the session is gone: a full page of the menu
        return Response(status_code=204, headers={"HX-Redirect": href})
    text = " · ".join(outcome.get("messages", []))
    response = task_screens.input_screen_with(request, task, message=text, notice=text)
    response.headers["HX-Push-Url"] = href
    return response
