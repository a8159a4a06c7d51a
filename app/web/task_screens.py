"""Input screens of every measuring task (spec/jog-measuring.md §2, §3; design.md §7).

One template for all tasks. The form posts on NC Start (the MCP triggers ``ncstart`` on the
element marked ``data-ncstart``); the session is created on the first NC Start and re-created
while no point is stored, so the fields always rule. While a point is stored, the fields that
decide the probing are locked; setpoints and the target stay editable until Calculate.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from fastapi import APIRouter, HTTPException, Request
from starlette.concurrency import run_in_threadpool

from app.services.measuring import MeasuringEnv
from app.workflow import planning
from app.workflow.executor import StepExecutor
from app.workflow.service import WorkflowError

from . import measure
from .task_forms import (
    FieldSpec,
    FormEnv,
    field_of_error,
    fields_for,
    form_data,
    friendly,
    is_workpiece,
    values_from_params,
)
from .task_svg import draw
from .templating import ANGLE_KEYS, fmt_result, is_htmx, render_block, render_blocks, render_screen

router = APIRouter()
TEMPLATE = "measure_task.html"


@dataclass(frozen=True)
class TaskPage:
    task: str
    label: str
    path: tuple[str, ...]
    url: str
    back: tuple[str, str]       # (softkey text, parent menu url)


def _pages() -> dict[str, TaskPage]:
    pages = {}

    def walk(menu, base, path, back):
        for item in menu.items:
            if isinstance(item, measure.Menu):
                walk(item, f"{base}/{item.slug}", (*path, item.label), f"{base}/{item.slug}")
            else:
                pages[item.task] = TaskPage(item.task, item.label, (*path, item.label), f"{base}/{item.slug}",
                                            ("<< Back" if base.startswith("/measure/tool") else "Back", back))

    walk(measure.WORKPIECE_MENU, "/measure/workpiece", (measure.WORKPIECE_MENU.label,), "/measure/workpiece")
    walk(measure.TOOL_MENU, "/measure/tool", (measure.TOOL_MENU.label,), "/measure/tool")
    return pages


PAGES = _pages()


def _page(task: str) -> TaskPage:
    page = PAGES.get(task)
    if page is None:
        raise HTTPException(404, f"no measuring screen for {task!r}")
    return page


# --- context -------------------------------------------------------------------------------

class _Env:
    """The services one screen request needs."""

    def __init__(self, request: Request):
        services = request.app.state.services
        self.services = services
        self.workflow = services.workflow
        self.machine = services.machine
        self.gud = services.settings.get()
        self.form_env = FormEnv(plane=self.machine.plane(), offsets=tuple(services.offsets.names()),
                                active_offset=self.machine.active_offset,
                                rotary_axes=tuple(self.machine.rotary_axes), gud=self.gud)

    def session_of(self, task: str):
        session = self.workflow.session
        return session if session is not None and session.task == task else None

    def measuring_context(self):
        services = self.services
        return MeasuringEnv(services.db, services.machine, services.settings).measuring_context()


def _stored_any(session) -> bool:
    return session is not None and any(s.stored for s in session.slots)


def _locked_values(fields: list[FieldSpec], session) -> dict[str, str]:
    locked = [f for f in fields if f.locks]
    return values_from_params(locked, session.params) if _stored_any(session) else {}


def _typed(env: _Env, task: str, form: dict | None):
    """(fields, the task's session, FormData): the typed text, the locked fields from the session."""
    fields = fields_for(task, env.form_env)
    session = env.session_of(task)
    typed = {**(form or {}), **_locked_values(fields, session)}
    return fields, session, form_data(task, fields, typed, env.gud)


def _visible_answer(session):
    """The last answer while no new point is stored (the result stays on the screen)."""
    if session is not None and session.last and not _stored_any(session):
        return session.last
    return None


# --- rendering -----------------------------------------------------------------------------

RESULT_LABELS = [
    ("position", "Edge position"), ("corner", "Corner P0"), ("center", "Centre P0"), ("p1", "P1"),
    ("p2", "P2"), ("distance", "Distance L"), ("diameter", "Diameter"), ("pitch_diameter", "Pitch diameter"),
    ("length", "Length L"), ("width", "Width W"), ("radius", "Radius R"), ("angle", "Angle α"),
    ("angle_2", "Angle of 2nd edge"), ("corner_angle", "Corner angle"), ("alpha", "Alpha α"), ("beta", "Beta β"),
]
TOOL_LABELS = {"length": "Length L1", "radius": "Radius R"}


def result_rows(task: str, result: dict | None) -> list[tuple[str, str, str]]:
    """(label, value text, unit) of the task's result keys (design.md §4)."""
    if not result:
        return []
    rows = []
    tool_task = task.startswith("tool.")
    for key, label in RESULT_LABELS:
        if key not in result:
            continue
        value = result[key]
        label = TOOL_LABELS.get(key, label) if tool_task else label
        unit = "°" if key in ANGLE_KEYS else "mm"
        if key == "center" and task.startswith(("hole.3", "hole.4", "spigot.3", "spigot.4")):
            label = "P0 (circle centre)" if task.endswith("3") else "P0 (diagonals)"
        if isinstance(value, dict):
            rows += [(f"{label} {axis}", fmt_result(key, v), unit) for axis, v in value.items()]
        elif isinstance(value, int | float):
            rows.append((label, fmt_result(key, value), unit))
    for key in ("probe", "tool_probe", "tool"):
        data = result.get(key)
        if isinstance(data, dict):
            rows += _flat(key.replace("_", " ").capitalize(), data)
    return rows


def _flat(prefix: str, data: dict) -> list[tuple[str, str, str]]:
    rows = []
    for key, value in data.items():
        if isinstance(value, dict):
            rows += _flat(f"{prefix} {key}", value)
        elif isinstance(value, list | tuple) and all(isinstance(v, int | float) for v in value):
            rows.append((f"{prefix} {key}", " / ".join(fmt_result(key, v) for v in value), ""))
        elif isinstance(value, int | float | bool):
            rows.append((f"{prefix} {key}", fmt_result(key, value), ""))
    return rows


def correction_rows(correction: dict | None) -> list[dict]:
    """Before/after of each frame component of the target WO (translation mm, rotation °)."""
    if not correction or not correction.get("after"):
        return []
    before, after = correction.get("before") or {}, correction["after"]
    rows = []
    for part, label in (("trans", "Offset"), ("fine", "Fine"), ("rot", "Rotation")):
        for axis, new in (after.get(part) or {}).items():
            old = (before.get(part) or {}).get(axis, 0.0)
            if part == "fine" and not old and not new:
                continue
            key = "angle" if part == "rot" else "trans"
            rows.append({"label": f"{label} {axis}", "field": f"{part}.{axis}",
                         "before": fmt_result(key, old), "after": fmt_result(key, new),
                         "changed": abs(float(new) - float(old)) > 1e-9})
    return rows


def _svgs(env: _Env, task: str, params: dict | None, session, answer: dict | None) -> list:
    """Top (and side) view: planned path of the next point from the current ball centre."""
    try:
        ctx = env.measuring_context()
        coords = "WCS" if is_workpiece(task) or task.startswith("probe.") else "MCS"
        start = StepExecutor(env.machine.machine, ctx.chain().wcs2bcs, ctx.tool_length,
                             ctx.plane.infeed_unit).current(coords)
    except Exception:       # the preview must never break the screen
        return []
    steps = []
    result = (answer or {}).get("result")
    if params is not None and not result:
        n = (session.next_point() if session is not None else None) or 1
        try:
            normalised = planning.validate_params(task, params, ctx.plane)
            steps = planning.planned_path(task, normalised, n, np.asarray(start), planning.context_from(ctx))
        except Exception:
            steps = []
    points = session.to_api()["points"] if session is not None else []
    radius = ctx.probe.ball_diameter / 2.0 if ctx.probe else float((ctx.tool or {}).get("radius") or 1.0)
    return draw(task, ctx.plane, params=params, start=start, steps=steps, points=points, result=result,
                ball_radius=radius)


def _screen_context(env: _Env, page: TaskPage, form: dict | None, *, answer=None, alarm=None, errors=None,
                    notice: str = "") -> dict:
    task = page.task
    fields, session, data = _typed(env, task, form)
    stored_any = _stored_any(session)
    n_points = planning.TASK_POINTS[task]
    if answer is None:
        answer = _visible_answer(session)
    if answer is not None and "result" not in answer:
        answer = None
    setup = (answer or {}).get("setup_support")
    points = session.to_api()["points"] if session is not None else \
        [{"n": n, "stored": False} for n in range(1, n_points + 1)]
    errors = errors or {}
    tool = None
    if task.startswith(("tool.", "toolprobe.")):
        st = env.machine.status()
        tool = {"t": st["tool"], "length": st["tool_length"], "mode": env.gud.tool_offset_mode,
                "probe_number": env.gud.tool_probe_number}
        if st["tool"] is not None:
            try:
                row = env.services.tools.get(st["tool"])
                tool["radius"] = float(row.get("radius") or 0.0) + float((row.get("wear") or {}).get("radius") or 0.0)
            except Exception:
                tool["radius"] = None
    warnings = list((answer or {}).get("warnings") or (session.warnings if session is not None else []))
    return {
        "screen": "measure_tool" if task.startswith(("tool.", "toolprobe.")) else "measure_workpiece",
        "page": page, "task": task,
        "fields": [{"spec": f, "value": data.values.get(f.name, ""), "error": errors.get(f.name),
                    "locked": f.locks and stored_any, "id": f.name.replace(".", "-")} for f in fields],
        "form_error": errors.get("_form"),
        "points": points, "n_points": n_points, "single": n_points == 1,
        "can_calculate": session is not None and session.can_calculate,
        "next_point": (session.next_point() if session is not None else 1) or None,
        "answer": answer, "setup": setup, "session_id": session.id if session is not None else None,
        "result_rows": result_rows(task, (answer or {}).get("result")),
        "correction": (answer or {}).get("correction"),
        "correction_rows": correction_rows((answer or {}).get("correction")),
        "warnings": warnings, "alarm": alarm, "notice": notice, "tool": tool,
        "svgs": _svgs(env, task, data.params, session, answer),
        "vkeys_task": True,
    }


def _render(request: Request, ctx: dict, message: str = "", level: str = "info", status_code: int = 200):
    """Full page on a normal GET; on htmx the screen + softkeys + message line."""
    if not is_htmx(request):
        return render_screen(request, TEMPLATE, ctx, status_code=status_code)
    return render_blocks(request, TEMPLATE, ["screen", "vsoftkeys", "hsoftkeys", "message"],
                         {**ctx, "message": message, "level": level}, status_code)


def input_screen(task: str):
    """The GET handler registered in ``measure.INPUT_SCREENS``: a fresh screen, old points discarded."""

    def handler(request: Request):
        env = _Env(request)
        session = env.workflow.session
        if session is not None and not session.running:
            env.workflow.delete(session.id)       # entering a screen starts a new measurement (spec §3.1)
        return _render(request, _screen_context(env, _page(task), None))

    return handler


for _task in PAGES:
    measure.INPUT_SCREENS[_task] = input_screen(_task)


# --- actions -------------------------------------------------------------------------------

def _error_view(env: _Env, page: TaskPage, form: dict, exc: WorkflowError):
    fields = fields_for(page.task, env.form_env)
    errors, alarm, notice = {}, None, ""
    if exc.field:
        name = field_of_error(fields, exc.field)
        errors[name] = friendly(fields, name, exc.message)
    elif exc.code == "alarm":
        alarm = exc.message
    else:
        notice = exc.message
    return _screen_context(env, page, form, alarm=alarm, errors=errors, notice=notice), exc.message


def _apply_form(env: _Env, page: TaskPage, form: dict):
    """The session for the typed params: recreated while no point is stored, else updated."""
    _fields, session, data = _typed(env, page.task, form)
    if _stored_any(session) and not session.running:
        return env.workflow.update_params(session.id, data.params, data.target)
    return env.workflow.create(page.task, data.params, data.target)


def _nc_start(env: _Env, page: TaskPage, form: dict):
    session = _apply_form(env, page, form)
    answer = env.workflow.start(session.id)
    n = answer["point"]["n"]
    if "result" in answer:
        return {"answer": answer}, "Measurement done" + (": WO activated" if answer.get("activated") else "")
    return {}, f"P{n} stored" + ("; press Calculate" if session.can_calculate else "")


def _calculate(env: _Env, page: TaskPage, form: dict):
    session = env.session_of(page.task)
    if session is None:
        raise WorkflowError(409, "points_missing", "Calculate needs all points stored")
    _apply_form(env, page, form)
    answer = env.workflow.calculate(session.id)
    return {"answer": answer}, "Calculated" + (": WO activated" if answer.get("activated") else "")


def _invalidate(n: int):
    def action(env: _Env, page: TaskPage, form: dict):
        session = env.session_of(page.task)
        if session is None:
            return {}, ""
        env.workflow.invalidate(session.id, n)
        return {}, f"P{n} invalid: measure it again with NC Start"
    return action


async def _act(request: Request, task: str, action):
    page = _page(task)
    form = dict(await request.form())

    def run():
        env = _Env(request)
        try:
            extra, message = action(env, page, form)
            return _render(request, _screen_context(env, page, form, **extra), message)
        except WorkflowError as exc:
            ctx, message = _error_view(env, page, form, exc)
            return _render(request, ctx, message, "error")

    return await run_in_threadpool(run)


@router.post("/measure/task/{task}/start")
async def nc_start(request: Request, task: str):
    return await _act(request, task, _nc_start)


@router.post("/measure/task/{task}/calculate")
async def calculate(request: Request, task: str):
    return await _act(request, task, _calculate)


@router.post("/measure/task/{task}/invalidate/{n}")
async def invalidate(request: Request, task: str, n: int):
    return await _act(request, task, _invalidate(n))


@router.post("/measure/task/{task}/refresh")
async def refresh(request: Request, task: str):
    """Re-draw from the typed values (after Reset, and the Select softkey of tool-probe calibration)."""
    def action(env, page, form):
        if form.get("_select") == "mode":
            form["mode"] = "length_diameter" if form.get("mode", "length") == "length" else "length"
        return {}, ""
    return await _act(request, task, action)


@router.post("/measure/task/{task}/check/{name}")
async def check_field(request: Request, task: str, name: str):
    """A field changed: its error next to it, the live SVG redrawn; setpoints go into the session."""
    _page(task)
    form = dict(await request.form())

    def run():
        env = _Env(request)
        fields, session, data = _typed(env, task, form)
        error = None
        try:
            planning.validate_params(task, data.params, env.form_env.plane)
            if _stored_any(session):
                env.workflow.update_params(session.id, data.params, data.target)
        except (ValueError, WorkflowError) as exc:
            field = field_of_error(fields, getattr(exc, "field", None))
            if field == name:
                error = friendly(fields, field, getattr(exc, "message", str(exc)))
        return render_blocks(request, TEMPLATE, ["field_error", "svg"], {
            "field_id": name.replace(".", "-"), "field_error": error, "task": task, "oob": True,
            "svgs": _svgs(env, task, data.params, session, _visible_answer(session))})

    return await run_in_threadpool(run)


@router.post("/measure/task/{task}/svg")
async def svg(request: Request, task: str):
    """The live SVG, polled while the screen is open (probe position, planned path)."""
    _page(task)
    form = dict(await request.form())

    def run():
        env = _Env(request)
        _fields, session, data = _typed(env, task, form)
        return render_block(request, TEMPLATE, "svg", {
            "task": task, "svgs": _svgs(env, task, data.params, session, _visible_answer(session))})

    return await run_in_threadpool(run)


@router.post("/measure/task/{task}/leave")
def leave(request: Request, task: str):
    """Back: leaving the input screen aborts the measurement and discards stored points (spec §3.1)."""
    page = _page(task)
    workflow = request.app.state.services.workflow
    session = workflow.session
    if session is not None and session.task == task:
        workflow.delete(session.id)
    parent = page.back[1]
    parts = parent.strip("/").split("/")
    if parts == ["measure", "workpiece"]:
        response = measure.workpiece_menu(request)
    elif parts == ["measure", "tool"]:
        response = measure.tool_menu(request)
    else:
        response = measure.workpiece_group(request, parts[-1])
    response.headers["HX-Push-Url"] = parent
    return response
