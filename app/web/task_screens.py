"""Input screens of every measuring task (spec/jog-measuring.md §2, jog-measuring §3; design.md §7).

One template for all tasks. The form posts on NC Start (the MCP triggers ``ncstart`` on the
element marked ``data-ncstart``); the session is created on the first NC Start and re-created
while no point is stored, so the fields always rule. While a point is stored, the fields that
decide the probing are locked; setpoints and the target stay editable until Calculate.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal, TypedDict

import numpy as np
from fastapi import APIRouter, HTTPException, Request
from starlette.concurrency import run_in_threadpool

from app.access.deps import denied, measuring_function, needs, require_measurement
from app.errors import WorkflowError
from app.i18n import N_, _, language
from app.services.measuring import MeasuringEnv
from app.workflow import guard, planning
from app.workflow.executor import StepExecutor
from app.workflow.forms import TOOL_TARGET, FieldSpec, FormEnv
from app.workflow.tasks import Category, task_spec
from engine.plan import ideal_path
from engine.tasks import Family

from . import measure, task_help, units
from .failsafe import EXPECTED, PictureFailed, drawn
from .lathe_screens import lathe_correction_rows, lathe_result_rows, lathe_svgs, lathe_tool_info
from .task_forms import (
    FormData,
    field_of_error,
    form_data,
    friendly,
    known_values,
    lathe_values_from_params,
    values_from_params,
)
from .task_svg import draw
from .templating import (
    ANGLE_KEYS,
    fmt_result,
    is_htmx,
    render_block,
    render_blocks,
    render_screen,
    templates,
    url_path,
)
from .texts import field_name

router = APIRouter()
TEMPLATE = "measure_task.html"


@dataclass(frozen=True)
class TaskPage:
    task: str
    label: str
    path: tuple[str, ...]
    slugs: tuple[str, ...]                  # its place in the menu tree (``measure.menu_route``)
    back: tuple[str, tuple[str, ...]]       # (softkey text, slugs of the parent menu)

    def href(self, request: Request) -> str:
        """The URL of the input screen."""
        route, params = measure.menu_route(self.slugs)
        return url_path(request, route, **params)

    @property
    def url(self) -> str:
        """The URL without a request: the route's path in the screens' router (mounted at the root)."""
        route, params = measure.menu_route(self.slugs)
        return str(measure.router.url_path_for(route, **params))


def _pages() -> dict[str, TaskPage]:
    pages = {}

    def walk(menu, slugs, path):
        for item in menu.items:
            if isinstance(item, measure.Menu):
                walk(item, (*slugs, item.slug), (*path, item.label))
            else:
                back = "<< Back" if slugs[0] == measure.TOOL_MENU.slug else "Back"
                pages[item.task] = TaskPage(item.task, item.label, (*path, item.label), (*slugs, item.slug),
                                            (back, slugs))

    walk(measure.WORKPIECE_MENU, (measure.WORKPIECE_MENU.slug,), (measure.WORKPIECE_MENU.label,))
    walk(measure.TOOL_MENU, (measure.TOOL_MENU.slug,), (measure.TOOL_MENU.label,))
    lathe = measure.LATHE_MENU
    for item in lathe.items:
        pages[item.task] = TaskPage(item.task, item.label, (lathe.label, item.label), (lathe.slug, item.slug),
                                    ("<< Back", (lathe.slug,)))
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
        self.request = request
        self.services = services
        self.workflow = services.workflow
        self.machine = services.machine
        self.gud = services.settings.get()
        self.form_env = FormEnv(plane=self.machine.plane(), offsets=tuple(services.offsets.names()),
                                active_offset=self.machine.active_offset,
                                rotary_axes=tuple(self.machine.rotary_axes), gud=self.gud,
                                diameter_programming=self.machine.diameter_programming)

    def session_of(self, task: str):
        session = self.workflow.session
        return session if session is not None and session.task == task else None

    def measuring_context(self):
        services = self.services
        return MeasuringEnv(services.db, services.machine, services.settings).measuring_context()


def _stored_any(session) -> bool:
    return session is not None and any(s.stored for s in session.slots)


def _locked_values(fields: list[FieldSpec], session, gud=None) -> dict[str, str]:
    locked = [f for f in fields if f.locks]
    return values_from_params(locked, session.params, gud=gud) if _stored_any(session) else {}


def _typed(env: _Env, task: str, form: dict | None):
    """(fields, the task's session, FormData): the typed text, the locked fields from the session.

    Without a form (a GET: the screen opened again, a refresh, another tab) the session's own
    params are shown: the server's session is the truth (design.md §9.1)."""
    spec = task_spec(task)
    fields = spec.form(env.form_env)
    session = env.session_of(task)
    if form is None and session is not None and spec.lathe:
        form = lathe_values_from_params(fields, session.params, env.gud)
    elif form is None and session is not None:
        form = values_from_params(fields, session.params, setpoints=True, gud=env.gud)
        if isinstance(session.target, str):
            form["target"] = session.target
        else:                                   # a tool offset: its fields from the session
            form["target"] = TOOL_TARGET
            form.update({f"tool_target.{k}": str(v) for k, v in session.target.items()})
            for key, value in (session.params.get("tolerance") or {}).items():
                form[f"tolerance.{key}"] = _tolerance_text(fields, key, value, env.gud)
    typed = {**(form or {}), **_locked_values(fields, session, env.gud)}
    known = known_values(fields, session.params) if session is not None else None
    return fields, session, form_data(spec, fields, typed, env.gud, known)


def _tolerance_text(fields: list[FieldSpec], key: str, value, gud) -> str:
    """A session's tolerance value as its field shows it (a length in the screen's unit)."""
    if isinstance(value, bool):
        return "yes" if value else "no"
    spec = next((f for f in fields if f.name == f"tolerance.{key}"), None)
    if spec is not None and spec.unit == "mm" and isinstance(value, int | float):
        return units.field_text(float(value), gud)
    return str(value)


def _visible_answer(session):
    """The last answer while no new point is stored (the result stays on the screen)."""
    if session is not None and session.last and not _stored_any(session):
        return session.last
    return None


# --- rendering -----------------------------------------------------------------------------

DECISIONS = {   # the strategy's decision (measuring-math §3.5) in the operator's words
    "none": N_("Within the zero offset range: no correction, the mean value is kept"),
    "mean": N_("Corrected by the mean value"), "full": N_("Corrected by 100 % of the deviation"),
    "oversize": N_("Oversize: corrected by 100 %, check the part"), "undersize": N_("Undersize: corrected by 100 %, check the part"),
    "dimension_difference": N_("Dimension difference exceeded: no correction, check the tool"),
    "safe_area": N_("Safe area exceeded: no correction"),
}

RESULT_LABELS = [
    ("actual", N_("Actual value")), ("deviation", N_("Deviation D")), ("mean_value", N_("Mean value Mv")),
    ("compensation", N_("Compensation")),
    ("position", N_("Edge position")), ("corner", N_("Corner P0")), ("center", N_("Centre P0")), ("p1", N_("P1")),
    ("p2", N_("P2")), ("distance", N_("Distance L")), ("diameter", N_("Diameter")), ("pitch_diameter", N_("Pitch diameter")),
    ("length", N_("Length L")), ("width", N_("Width W")), ("radius", N_("Radius R")), ("angle", N_("Angle α")),
    ("angle_2", N_("Angle of 2nd edge")), ("corner_angle", N_("Corner angle")), ("alpha", N_("Alpha α")), ("beta", N_("Beta β")),
]


def task_name(task: str) -> str:
    """A measuring task id (``edge.set``) as its softkey text in the screen's language."""
    page = PAGES.get(task)
    return _(page.label) if page is not None else task


def result_label(key: str) -> str:
    """A result key of the set-up support's tables: the key in English (as before), the measuring
    screen's label in another language."""
    if language() == "en":
        return key
    return _(dict(RESULT_LABELS).get(key, key))


# here rather than in templating.py, which this module imports (texts.py had to import back)
templates.env.globals["task_name"] = task_name
templates.env.globals["result_label"] = result_label
TOOL_LABELS = {"length": N_("Length L1"), "radius": N_("Radius R")}


def result_rows(task: str, result: dict | None, gud=None) -> list[tuple[str, str, str]]:
    """(label, value text, unit) of the task's result keys (design.md §4), in the screen's language
    and unit."""
    if not result:
        return []
    rows = []
    spec = task_spec(task)
    if spec.lathe:
        return lathe_result_rows(result)
    tool_task = spec.category == Category.TOOL_MEASURING
    for key, label in RESULT_LABELS:
        if key not in result:
            continue
        value = result[key]
        label = TOOL_LABELS.get(key, label) if tool_task else label
        unit = "°" if key in ANGLE_KEYS else units.unit(gud)
        if key == "center" and spec.points >= 3 and spec.family in (Family.HOLE, Family.SPIGOT):
            label = N_("P0 (circle centre)") if spec.points == 3 else N_("P0 (diagonals)")
        if isinstance(value, dict):
            rows += [(f"{_(label)} {axis}", fmt_result(key, v, gud), unit) for axis, v in value.items()]
        elif isinstance(value, int | float):
            rows.append((_(label), fmt_result(key, value, gud), unit))
    for key in ("probe", "tool_probe", "tool"):
        data = result.get(key)
        if isinstance(data, dict):
            rows += _flat(_(RECORD_LABELS[key]), data, gud)
    return rows


RECORD_LABELS = {"probe": N_("Probe"), "tool_probe": N_("Tool probe"), "tool": N_("Tool")}
NOT_LENGTHS = frozenset({"number", "tool", "t", "type", "axes", "points"})


def _flat(prefix: str, data: dict, gud=None) -> list[tuple[str, str, str]]:
    """A record of the result (probe, tool probe, tool) as rows named in the operator's words."""
    rows = []
    for key, value in data.items():
        name = f"{prefix} {field_name(key)}"
        if isinstance(value, dict):
            rows += _flat(name, value, gud)
        elif isinstance(value, list | tuple) and all(isinstance(v, int | float) for v in value):
            rows.append((name, " / ".join(_record_value(key, v, gud) for v in value), ""))
        elif isinstance(value, int | float | bool):
            rows.append((name, _record_value(key, value, gud), ""))
    return rows


def _record_value(key: str, value, gud) -> str:
    if isinstance(value, bool) or key in NOT_LENGTHS:
        return fmt_result(key, value)
    return fmt_result(key, value, gud)


def correction_rows(correction: dict | None, gud=None) -> list[dict]:
    """Before/after of each frame component of the target WO (translation mm, rotation °), or of
    the tool data of a tool offset (length, radius and their wear, mm)."""
    if not correction or not correction.get("after"):
        return []
    if correction.get("lathe"):
        return lathe_correction_rows(correction)
    before, after = correction.get("before") or {}, correction["after"]
    if "tool" in correction:
        return [row for part in (None, "wear") for row in _tool_part_rows(part, before, after, gud)]
    return _frame_correction_rows(before, after, gud)


def _tool_part_rows(part: str | None, before: dict, after: dict, gud) -> list[dict]:
    """Length and radius of the tool (``part`` None) or of its wear, as they were and are."""
    new_part = (after.get(part) if part else after) or {}
    old_part = (before.get(part) if part else before) or {}
    rows = []
    for key in ("length", "radius"):
        if key not in new_part:
            continue
        old, new = float(old_part.get(key, 0.0)), float(new_part[key])
        rows.append({"label": field_name(f"{part}.{key}" if part else key).capitalize(),
                     "field": f"{part}.{key}" if part else key, "before": fmt_result("length", old, gud),
                     "after": fmt_result("length", new, gud), "changed": abs(new - old) > 1e-9})
    return rows


def _frame_correction_rows(before: dict, after: dict, gud) -> list[dict]:
    """Offset, fine offset and rotation per axis of the frame, as they were and are."""
    rows = []
    for part, label in (("trans", N_("Offset")), ("fine", N_("Fine")), ("rot", N_("Rotation"))):
        for axis, new in (after.get(part) or {}).items():
            old = (before.get(part) or {}).get(axis, 0.0)
            if part == "fine" and not old and not new:
                continue
            key = "angle" if part == "rot" else "trans"
            rows.append({"label": f"{_(label)} {axis}", "field": f"{part}.{axis}",
                         "before": fmt_result(key, old, gud), "after": fmt_result(key, new, gud),
                         "changed": abs(float(new) - float(old)) > 1e-9})
    return rows


def _svgs(env: _Env, task: str, params: dict | None, session, answer: dict | None) -> list:
    """Top (and side) view: planned path of the next point from the current ball centre."""
    spec = task_spec(task)
    if spec.lathe:
        return lathe_svgs(env, spec, params, answer)
    try:
        return _mill_svgs(env, task, params, session, answer)
    except PictureFailed as failed:     # a bug, logged: its error line stands in the picture's place
        return [failed.line]


def _mill_svgs(env: _Env, task: str, params: dict | None, session, answer: dict | None) -> list:
    spec = task_spec(task)

    def at_start():
        ctx = env.measuring_context()
        return ctx, StepExecutor(env.machine.machine, ctx.chain().wcs2bcs, ctx.tool_length,
                                 ctx.plane.infeed_unit).current(spec.coords)

    here = drawn("the measuring preview", at_start, None)
    if here is None:        # no probe position or no data: the screen says why
        return []
    ctx, start = here
    steps: list = []
    refused = None
    result = (answer or {}).get("result")
    if params is not None and not result:
        n = (session.next_point() if session is not None else None) or 1
        steps, refused = _next_path(env, spec, params, session, ctx, start, n)
    points = session.to_api()["points"] if session is not None else []
    radius = ctx.probe.ball_diameter / 2.0 if ctx.probe else float((ctx.tool or {}).get("radius") or 1.0)
    return draw(task, ctx.plane, params=params, start=start, steps=steps, points=points, result=result,
                ball_radius=radius, refused=refused)


def _next_path(env: _Env, spec, params: dict, session, ctx, start, n: int) -> tuple[list, object]:
    """The planned path of point ``n`` (ideal latches; none for parameters the form marks as
    wrong) and the step the start guard would refuse."""

    def plan():
        normalised = spec.validate(params, ctx.plane)
        return normalised, ideal_path(spec.program(normalised, n, np.asarray(start), planning.context_from(ctx)),
                                      start)

    planned = drawn("the planned path", plan, None)
    if planned is None:
        return [], None
    normalised, steps = planned
    refused = None
    if steps and guard.guarded(spec) and spec.coords == "WCS" and (session is None or session.guard):
        # the start guard's verdict: the segment NC Start would refuse is marked
        refused = drawn("the start guard's check",
                        lambda: guard.check_point(env.machine.machine, spec, normalised, n, ctx)[0].refusal, None)
    return steps, refused


class FieldRow(TypedDict):
    """One input field as the template draws it."""
    spec: FieldSpec
    value: str
    error: str | None
    locked: bool
    id: str


class ToolInfo(TypedDict, total=False):
    """The tool in the spindle on a tool-measuring screen (``radius`` only with a tool in it)."""
    t: int | None
    length: float | None
    mode: str
    probe_number: int
    radius: float | None


class TaskScreenContext(TypedDict):
    """What every measuring task's screen gives ``measure_task.html`` (the keys all three share)."""
    lathe: bool
    diamon: bool
    page: TaskPage
    task: str
    fields: list[FieldRow]
    form_error: str | None
    points: list[dict]
    n_points: int
    single: bool
    positions_tool: bool
    can_calculate: bool
    next_point: int | None
    answer: dict | None
    setup: dict | None
    session_id: str | None
    result_rows: list[tuple[str, str, str]]
    correction: dict | None
    correction_rows: list[dict]
    warnings: list
    alarm: str | None
    alarm_remedy: str
    notice: str
    svgs: list
    vkeys_task: bool
    tool_mode: bool
    decision: str | None
    decision_alarm: object
    running: bool
    progress: dict
    start_denied: str
    help_picture: str | None
    equipment: list


class WorkpieceScreenContext(TaskScreenContext):
    """A workpiece task's screen (``measure_workpiece``): no tool box."""
    screen: Literal["measure_workpiece"]
    tool: None


class ToolScreenContext(TaskScreenContext):
    """A tool-measuring task's screen (``measure_tool``): the tool in the spindle."""
    screen: Literal["measure_tool"]
    tool: ToolInfo


class LatheScreenContext(TaskScreenContext):
    """A lathe task's screen (``measure_lathe``): the tool in the turret."""
    screen: Literal["measure_lathe"]
    tool: dict | None


ScreenContext = WorkpieceScreenContext | ToolScreenContext | LatheScreenContext


def _screen_context(env: _Env, page: TaskPage, form: dict | None, *, answer=None, alarm=None, errors=None,
                    notice: str = "") -> ScreenContext:
    """The context of the task's input screen: the keys all screens share, then the screen's own."""
    spec = task_spec(page.task)
    common = _common_context(env, page, form, answer=answer, alarm=alarm, errors=errors or {}, notice=notice)
    if spec.lathe:
        return LatheScreenContext(screen="measure_lathe", tool=lathe_tool_info(env), **common)
    if spec.family.tool_measuring:
        return ToolScreenContext(screen="measure_tool", tool=_spindle_tool(env), **common)
    return WorkpieceScreenContext(screen="measure_workpiece", tool=None, **common)


def _spindle_tool(env: _Env) -> ToolInfo:
    """The tool in the spindle, its radius with wear from the tool table (None when it has no row)."""
    st = env.machine.status()
    tool = ToolInfo(t=st["tool"], length=st["tool_length"], mode=env.gud.tool_offset_mode,
                    probe_number=env.gud.tool_probe_number)
    if st["tool"] is not None:
        try:
            row = env.services.tools.get(st["tool"])
            tool["radius"] = float(row.get("radius") or 0.0) + float((row.get("wear") or {}).get("radius") or 0.0)
        except EXPECTED:
            tool["radius"] = None
    return tool


def _shown_answer(session, answer: dict | None) -> dict | None:
    """The answer the screen shows: the one given, else the session's visible one; only with a result."""
    if answer is None:
        answer = _visible_answer(session)
    return answer if answer is not None and "result" in answer else None


def _setup_of(answer: dict | None) -> dict | None:
    """The set-up support's hand-over, until it was carried out or left (then the result stays)."""
    setup = (answer or {}).get("setup_support")
    return None if setup and setup.get("done") else setup


def _field_rows(fields: list[FieldSpec], data: FormData, errors: dict, locked: bool) -> list[FieldRow]:
    return [FieldRow(spec=f, value=data.values.get(f.name, ""), error=errors.get(f.name), locked=f.locks and locked,
                     id=f.name.replace(".", "-")) for f in fields]


class _SessionPart(TypedDict):
    running: bool
    progress: dict
    points: list[dict]
    can_calculate: bool
    next_point: int | None
    session_id: str | None
    alarm_remedy: str
    notice: str


def _session_part(session, n_points: int, alarm, notice: str) -> _SessionPart:
    """The keys read from the task's session (or their values without one)."""
    if session is None:
        return _SessionPart(running=False, progress={}, points=[{"n": n, "stored": False} for n in range(1, n_points + 1)],
                            can_calculate=False, next_point=1, session_id=None, alarm_remedy="", notice=notice or "")
    # running before the outcome: NC Start's thread sets the outcome, then ends running. Read the
    # other way round, a measurement ending meanwhile showed neither its progress nor its outcome,
    # and no later session event would ask again
    running = bool(session.running)
    return _SessionPart(running=running, progress=session.progress or {}, points=session.to_api()["points"],
                        can_calculate=session.can_calculate, next_point=session.next_point() or None,
                        session_id=session.id,
                        alarm_remedy=((session.last_alarm or {}).get("remedy") if alarm else "") or "",
                        notice=notice or session.notice or "")


def _common_context(env: _Env, page: TaskPage, form: dict | None, *, answer, alarm, errors: dict,
                    notice: str) -> TaskScreenContext:
    task, spec = page.task, task_spec(page.task)
    fields, session, data = _typed(env, task, form)
    live = _session_part(session, spec.points, alarm, notice)
    answer = _shown_answer(session, answer)
    result = (answer or {}).get("result")
    correction = (answer or {}).get("correction")
    help_context = task_help.context(env.services, task, data.values)     # help picture, equipment (issue 17 item 5)
    return TaskScreenContext(
        lathe=spec.lathe, diamon=env.machine.diameter_programming, page=page, task=task,
        fields=_field_rows(fields, data, errors, _stored_any(session)), form_error=errors.get("_form"),
        n_points=spec.points, single=spec.points == 1,
        # on the tool probe the operator positions the tool, not the workpiece probe
        positions_tool=spec.category in (Category.TOOL_PROBE_CALIBRATION, Category.TOOL_MEASURING),
        answer=answer, setup=_setup_of(answer),
        result_rows=result_rows(task, result, env.gud),
        correction=correction, correction_rows=correction_rows(correction, env.gud),
        warnings=list((answer or {}).get("warnings") or (session.warnings if session is not None else [])),
        alarm=alarm,
        svgs=_svgs(env, task, data.params, session, answer),
        vkeys_task=True,
        tool_mode=data.values.get("target") == TOOL_TARGET,
        decision=_decision(answer), decision_alarm=(result or {}).get("alarm"),
        start_denied=_start_denied(env, spec, data),
        help_picture=help_context["help_picture"], equipment=help_context["equipment"],
        **live,
    )


def _start_denied(env: _Env, spec, data) -> str:
    """Why this level may not start the task with the chosen target ('' when it may): the checks
    NC Start makes (``require_measurement``), asked when the screen opens, so that the lock shows
    before it bites (issue 29 item 4)."""
    reason = denied(env.request, "measure")
    if reason:
        return reason
    target = data.params.get("target") if spec.lathe else data.target
    if target is None and spec.corrects_zero_offset and not spec.lathe:
        target = env.machine.active_offset
    function = measuring_function(spec.category, target)
    return denied(env.request, function) if function else ""


def _decision(answer: dict | None) -> str | None:
    decision = ((answer or {}).get("result") or {}).get("decision")
    return _(DECISIONS[decision]) if decision in DECISIONS else None


def _render(request: Request, ctx: ScreenContext, message: str = "", level: str = "info", status_code: int = 200):
    """Full page on a normal GET; on htmx the screen + softkeys + message line."""
    if not is_htmx(request):
        return render_screen(request, TEMPLATE, dict(ctx), status_code=status_code)
    return render_blocks(request, TEMPLATE, ["screen", "vsoftkeys", "hsoftkeys", "message"],
                         {**ctx, "message": message, "level": level}, status_code)


def input_screen(task: str):
    """The GET handler registered in ``measure.INPUT_SCREENS``: the task's open session as the
    server holds it (a refresh or a second tab loses nothing, design.md §9.1), else a fresh
    screen. Back (leave) discards the points (jog-measuring §3.1)."""

    def handler(request: Request):
        return _render(request, _screen_context(_Env(request), _page(task), None))

    return handler


for _task in PAGES:
    measure.INPUT_SCREENS[_task] = input_screen(_task)


def input_screen_with(request: Request, task: str, message: str = "", notice: str = ""):
    """The input screen of ``task`` with a message and a notice (what the set-up support did)."""
    return _render(request, _screen_context(_Env(request), _page(task), None, notice=notice), message)


# --- actions -------------------------------------------------------------------------------

def _error_view(env: _Env, page: TaskPage, form: dict, exc: WorkflowError):
    fields = task_spec(page.task).form(env.form_env)
    errors, alarm, notice = {}, None, ""
    if exc.field:
        name = field_of_error(fields, exc.field)
        errors[name] = friendly(fields, name, exc.message)
    elif exc.code == "alarm":
        alarm = exc.message
    else:
        notice = exc.message
    line = next(iter(errors.values())) if errors else exc.message     # the message line names the field too
    return _screen_context(env, page, form, alarm=alarm, errors=errors, notice=notice), line


def _apply_form(env: _Env, page: TaskPage, form: dict):
    """The session for the typed params: recreated while no point is stored, else updated."""
    _fields, session, data = _typed(env, page.task, form)
    if _stored_any(session) and not session.running:
        return env.workflow.update_params(session.id, data.params, data.target)
    return env.workflow.create(page.task, data.params, data.target)


NC_ANSWER_WAIT_S = 0.4      # a short measurement answers at once; a longer one shows its progress


def _nc_start(env: _Env, page: TaskPage, form: dict):
    """NC Start runs on in the background (design.md §9.1): a measurement that ends within
    NC_ANSWER_WAIT_S answers with its outcome, a longer one with its progress, which the screen
    fetches again (``progress``) on each session event of the live feed until the outcome."""
    session = _apply_form(env, page, form)
    require_measurement(env.request, session.task, session.target)    # 403 shown on the screen
    env.workflow.start(session.id, wait=False)
    n = (session.progress or {}).get("point", 1)
    if not env.workflow.wait_ended(session, NC_ANSWER_WAIT_S):      # woken when it ends
        return {}, f"NC Start: measuring P{n}"
    message, level = _outcome(session, n)
    if level == "error":
        raise WorkflowError(409, "alarm", message)
    return {"answer": _visible_answer(session)}, message


def _outcome(session, n: int) -> tuple[str, str]:
    """The message line once point ``n`` ended: (text, level)."""
    if session.last_alarm:
        return f"{session.last_alarm['code']} {session.last_alarm['text']}", "error"
    answer = _visible_answer(session)
    if session.single_point and answer and "result" in answer:
        return "Measurement done" + (": WO activated" if answer.get("activated") else ""), "info"
    try:
        stored = session.slot(n).stored
    except KeyError:
        stored = False
    if stored:
        return f"P{n} stored" + ("; press Calculate" if session.can_calculate else ""), "info"
    return "", "info"


def _calculate(env: _Env, page: TaskPage, form: dict):
    session = env.session_of(page.task)
    if session is None:
        raise WorkflowError(409, "points_missing", "Calculate needs all points stored")
    session = _apply_form(env, page, form)
    require_measurement(env.request, session.task, session.target)
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


@router.post("/measure/task/{task}/start", name="measure_task_start", dependencies=[needs("measure")])
async def nc_start(request: Request, task: str):
    return await _act(request, task, _nc_start)


@router.get("/measure/task/{task}/progress", name="measure_task_progress", dependencies=[needs("view")])
async def progress(request: Request, task: str, n: int | None = None):
    """Fetched on each session event while NC Start runs (static/live.js): the screen with its
    progress, then the screen with the outcome."""
    page = _page(task)

    def run():
        env = _Env(request)
        session = env.session_of(task)
        if session is not None and session.running:
            return _render(request, _screen_context(env, page, None), "", "info")
        message, level = _outcome(session, n or 1) if session is not None else ("", "info")
        alarm = message if level == "error" else None
        return _render(request, _screen_context(env, page, None, alarm=alarm), message, level)

    return await run_in_threadpool(run)


@router.post("/measure/task/{task}/calculate", name="measure_task_calculate", dependencies=[needs("measure")])
async def calculate(request: Request, task: str):
    return await _act(request, task, _calculate)


@router.post("/measure/task/{task}/invalidate/{n}", name="measure_task_invalidate", dependencies=[needs("measure")])
async def invalidate(request: Request, task: str, n: int):
    return await _act(request, task, _invalidate(n))


@router.post("/measure/task/{task}/refresh", name="measure_task_refresh", dependencies=[needs("measure")])
async def refresh(request: Request, task: str):
    """Re-draw from the typed values (after Reset, and the Select softkey of tool-probe calibration)."""
    def action(env, page, form):
        if form.get("_select") == "mode":
            form["mode"] = "length_diameter" if form.get("mode", "length") == "length" else "length"
        return {}, ""
    return await _act(request, task, action)


@router.post("/measure/task/{task}/check/{name}", name="measure_task_check", dependencies=[needs("measure")])
async def check_field(request: Request, task: str, name: str):
    """A field changed: its error next to it, the live SVG redrawn; setpoints go into the session."""
    _page(task)
    form = dict(await request.form())

    def run():
        env = _Env(request)
        fields, session, data = _typed(env, task, form)
        error = None
        try:
            task_spec(task).validate(data.params, env.form_env.plane)
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


@router.post("/measure/task/{task}/svg", name="measure_task_svg", dependencies=[needs("measure")])
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


@router.post("/measure/task/{task}/leave", name="measure_task_leave", dependencies=[needs("measure")])
def leave(request: Request, task: str):
    """Back: leaving the input screen aborts the measurement and discards stored points (jog-measuring §3.1)."""
    page = _page(task)
    workflow = request.app.state.services.workflow
    session = workflow.session
    if session is not None and session.task == task:
        workflow.delete(session.id)
    return measure.menu_screen(request, page.back[1])
