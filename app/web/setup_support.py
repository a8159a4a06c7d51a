"""The activation screen of the set-up support (spec/jog-measuring.md §6.2, manual §4.3.9).

Left: the measuring function just executed and its result (in the WCS active while measuring);
right: the measuring-WO values and the corrected WO (before/after), the toggle fields, the top
text line (changes with the answers), the dialog line. NC Start carries it out, ``<<`` leaves
without activating. Afterwards the measuring function's input screen is shown again.
"""

from __future__ import annotations

from fastapi import APIRouter, Request
from fastapi.responses import Response

from app.workflow import setup_support as support
from app.workflow.service import WorkflowError

from .task_screens import PAGES
from .templating import is_htmx, render_screen, vkeys

router = APIRouter()
TOGGLE_NAMES = ("activate", "realign", "retract", "position_rotary")


def task_href(task: str) -> tuple[str, str]:
    """(label, URL) of the input screen of ``task`` in the softkey tree."""
    page = PAGES.get(task)
    return (page.label, page.url) if page is not None else (task, "/measure/workpiece")


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
        "screen": "measure_workpiece", "m": model, "task_label": task_href(model["task"])[0],
        "session_id": session_id, "notice": notice,
        "vkeys": vkeys([], {"label": "<<", "post": f"/measure/setup-support/{session_id}/leave"}),
        "message": notice or model["message"]})


@router.get("/measure/setup-support/{session_id}")
def screen(request: Request, session_id: str):
    return _render(request, session_id)


@router.post("/measure/setup-support/{session_id}/toggle")
async def toggle(request: Request, session_id: str):
    """A toggle field changed: the top line follows the answers."""
    return _render(request, session_id, choices_from(await request.form()))


@router.post("/measure/setup-support/{session_id}/start")
async def nc_start(request: Request, session_id: str):
    """NC Start: carry out, then back to the measuring function's input screen."""
    services = request.app.state.services
    choices = choices_from(await request.form())
    try:
        outcome = support.carry_out(services.workflow, services.machine, session_id, choices, db=services.db)
    except WorkflowError as exc:
        return _render(request, session_id, choices, notice=exc.message)
    return _back(request, session_id, outcome)


@router.post("/measure/setup-support/{session_id}/leave")
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
    services = request.app.state.services
    try:
        task = services.workflow.get(session_id).task
    except WorkflowError:
        task = ""
    _label, href = task_href(task)
    text = " | ".join(outcome.get("messages", [])).encode("ascii", "replace").decode("ascii")
    if is_htmx(request):
        return Response(status_code=204, headers={"HX-Location": href, "X-HMI-Message": text[:300]})
    return Response(status_code=303, headers={"Location": href})
