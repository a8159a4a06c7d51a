"""The help picture and the equipment of a measuring task screen (issue 17 item 5): drawn with the
screen and again when the operator changes a field that moves the points (axis, direction,
corner position, inside/outside)."""

from __future__ import annotations

from fastapi import APIRouter, HTTPException, Request

from app.access.deps import needs
from app.workflow.tasks import TASKS

from . import help_pictures
from .templating import render_block

router = APIRouter()

TEMPLATE = "measure_task.html"


def context(services, task: str, values: dict | None) -> dict:
    """``help_picture`` (SVG figure or None) and ``equipment`` rows for the task's screen."""
    spec = TASKS.get(task)
    if spec is not None and spec.lathe:                   # the lathe screens draw their own set-up
        return {"help_picture": None, "equipment": []}
    return {"help_picture": help_pictures.draw(task, values, services.machine.plane()),
            "equipment": help_pictures.equipment_rows(services, task)}


@router.post("/measure/task/{task}/help", name="measure_task_help", dependencies=[needs("view")])
async def help_block(request: Request, task: str):
    if task not in TASKS:
        raise HTTPException(404, f"no measuring screen for {task!r}")
    form = dict(await request.form())
    return render_block(request, TEMPLATE, "help", {"task": task, **context(request.app.state.services, task, form)})
