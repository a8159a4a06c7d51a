"""What the lathe tasks' input screens show besides the common ones (turning.md §10.1, turning §10.2).

The screens are the common task screens (app/web/task_screens.py, templates/measure_task.html)
with the lathe's fields (app.workflow.forms.lathe_form); this module gives them the result and
correction rows in the lathe's terms (L1/L2/SL, trigger values per travel direction, X as a
diameter where the cycle reports it so, labelled), the tool in the turret, and the live view:
the real set-up drawn X up / Z right with the planned path of the NC reference point.
"""

from __future__ import annotations

import numpy as np
from markupsafe import Markup

from app.i18n import N_, _
from app.workflow.executor import StepExecutor
from engine.turning_plan import lathe_planned_path, prepare
from engine.types import MoveStep, ProbeStep

from .failsafe import EXPECTED, PictureFailed, drawn
from .lathe_view import lathe_svg
from .templating import fmt_result

DIA = "mm Ø"


def lathe_result_rows(result: dict) -> list[tuple[str, str, str]]:
    """(label, value text, unit): the turning §10.2 result keys; diameters labelled as such."""
    rows: list[tuple[str, str, str]] = []
    unit = DIA if result.get("unit") == "diameter" else "mm"
    for key, label in (("diameter", N_("Diameter")), ("actual", N_("Actual value")), ("setpoint", N_("Setpoint")),
                       ("deviation", N_("Deviation D")), ("mean_value", N_("Mean value Mv")),
                       ("empirical_value", N_("Empirical value EV"))):
        value = result.get(key)
        if isinstance(value, int | float) and not isinstance(value, bool):
            if key == "actual" and "diameter" in result:
                continue                          # CYCLE994: its actual value is the diameter
            rows.append((_(label), fmt_result(key, value), unit))
    if isinstance(result.get("compensation"), int | float):
        rows.append((_("Compensation (radius)"), fmt_result("compensation", result["compensation"]), "mm"))
    for name, data in (result.get("length") or {}).items():
        rows.append((_("%(name)s measured") % {"name": name}, fmt_result("length", data["actual"]), "mm"))
        rows.append((_("%(name)s difference") % {"name": name}, fmt_result("length", data["difference"]), "mm"))
    if isinstance(result.get("radius"), dict):
        rows.append((_("%(name)s measured") % {"name": "R"}, fmt_result("radius", result["radius"]["actual"]), "mm"))
    for key, value in (result.get("trigger") or {}).items():
        rows.append((_("Trigger %(direction)s") % {"direction": key}, fmt_result("trigger", value), "mm"))
        diff = (result.get("difference") or {}).get(key) if isinstance(result.get("difference"), dict) else None
        if diff is not None:
            rows.append((_("Difference %(direction)s") % {"direction": key}, fmt_result("difference", diff), "mm"))
    for axis, value in (result.get("skew") or {}).items():
        rows.append((_("Position deviation %(axis)s") % {"axis": axis}, fmt_result("skew", value), "mm"))
    if isinstance(result.get("effective_diameter"), int | float):
        rows.append((_("Effective ball diameter"), fmt_result("d", result["effective_diameter"]), "mm"))
    if result.get("written"):
        rows.append((_("Written"), ", ".join(result["written"]), ""))
    return rows


LATHE_TOOL_FIELDS = (("l1", "L1"), ("l2", "L2"), ("radius", "R"))


def lathe_correction_rows(correction: dict) -> list[dict]:
    """Before/after rows of what a lathe task wrote: tool data (L1, L2, R and their wear), the
    tool probe faces (_TP), the probe record (_WP trigger values, diameter, position deviation)
    or a zero offset (its translations)."""
    before, after = correction.get("before") or {}, correction.get("after") or {}
    if "trans" in after:
        return [row for axis, new in (after.get("trans") or {}).items()
                for row in _row(_("Offset %(axis)s") % {"axis": axis}, f"trans.{axis}",
                                (before.get("trans") or {}).get(axis), new)]
    if "l1" in after:
        return _tool_rows(before, after)
    if "trigger" in after:
        return _probe_rows(before, after)
    return [row for key, new in after.items() if isinstance(new, int | float)     # _TP / _TPW faces
            for row in _row(_("Face %(direction)s") % {"direction": key}, key, before.get(key), new)]


def _row(label: str, field: str, old, new) -> list[dict]:
    """The row of one value as it was and is (none when nothing was written)."""
    if new is None:
        return []
    old = 0.0 if old is None else float(old)
    return [{"label": label, "field": field, "before": fmt_result("length", old),
             "after": fmt_result("length", float(new)), "changed": abs(float(new) - old) > 1e-9}]


def _tool_rows(before: dict, after: dict) -> list[dict]:
    rows = [row for key, label in LATHE_TOOL_FIELDS for row in _row(label, key, before.get(key), after.get(key))]
    old_wear, new_wear = before.get("wear") or {}, after.get("wear") or {}
    return rows + [row for key, label in LATHE_TOOL_FIELDS
                   for row in _row(_("Wear %(name)s") % {"name": label}, f"wear.{key}", old_wear.get(key),
                                   new_wear.get(key))]


def _probe_rows(before: dict, after: dict) -> list[dict]:
    rows = [row for key, new in (after.get("trigger") or {}).items()
            for row in _row(_("Trigger %(direction)s") % {"direction": key}, f"trigger.{key}",
                            (before.get("trigger") or {}).get(key), new)]
    rows += _row(_("Effective diameter"), "effective_diameter", before.get("effective_diameter"),
                 after.get("effective_diameter"))
    old_deviation = before.get("position_deviation") or {}
    return rows + [row for axis, new in (after.get("position_deviation") or {}).items()
                   for row in _row(_("Position deviation %(axis)s") % {"axis": axis}, f"position_deviation.{axis}",
                                   old_deviation.get(axis), new)]


def lathe_tool_info(env) -> dict | None:
    """The tool in the turret as the screen shows it: T, type, SL, L1, L2, R (tool table, radius)."""
    st = env.machine.status()
    t = st.get("tool")
    info = {"t": t, "lathe": True, "lengths": st.get("tool_lengths") or {}}
    if t is None:
        return info
    try:
        row = env.services.tools.get(t)
    except EXPECTED:
        return info
    wear = row.get("wear") or {}
    info.update(type=row.get("type"), sl=row.get("sl"), l1=row.get("l1"), l2=row.get("l2"),
                radius=float(row.get("radius") or 0.0) + float(wear.get("radius") or 0.0),
                name=row.get("name"))
    return info


def path_steps(prep, start, tip) -> list[tuple[str, list[float]]]:
    """The planned NC reference points (MCS) of the program driven with ideal latches, each with
    how it is reached ("start", "move" or "probe")."""
    pos = np.asarray(start, dtype=float)
    points = []

    def mcs(p, coords):
        return tip.wcs2bcs.child2parent(p) if coords == "WCS" else np.asarray(p, dtype=float)

    points.append(("start", [float(v) for v in mcs(pos, prep.coords)]))
    for step in lathe_planned_path(prep, start):
        if isinstance(step, MoveStep):
            pos, kind = np.asarray(step.target, dtype=float), "move"
        elif isinstance(step, ProbeStep):
            travel = step.expected if step.expected is not None else step.distance / 2.0
            pos, kind = pos + travel * np.asarray(step.direction, dtype=float), "probe"
        else:
            continue
        points.append((kind, [float(v) for v in mcs(pos, prep.coords)]))
    return points


def next_path_steps(machine_service, ctx, spec, params: dict) -> list[tuple[str, list[float]]]:
    """The planned path of the next NC Start from where the tool tip is (MCS points with their
    kind): the task screen's picture and the 3D view (app/web/scene3d.py) draw the same path."""
    normalised = spec.validate(params, ctx.plane)
    plan_ctx = spec.plan_context(ctx, normalised)
    prep = prepare(spec.name, normalised, plan_ctx)
    tip = spec.tool_tip(ctx)
    start = StepExecutor(machine_service.machine, ctx.chain().wcs2bcs, ctx.tool_length, ctx.plane.infeed_unit,
                         tip=tip).current(prep.coords)
    return path_steps(prep, start, tip)


def _next_path(env, spec, params: dict) -> list[list[float]]:
    """The planned path of the next NC Start from where the tool tip is (MCS points)."""
    return [p for _kind, p in next_path_steps(env.machine, env.measuring_context(), spec, params)]


def lathe_svgs(env, spec, params: dict | None, answer: dict | None) -> list:
    """The real set-up with the planned path of the next NC Start (never breaks the screen)."""
    try:
        setup = drawn("the lathe set-up", lambda: (env.machine.scene_geometry(), env.machine.limits()), None)
        if setup is None:
            return []
        path = None
        if params is not None and not (answer or {}).get("result"):
            path = drawn("the lathe's planned path", lambda: _next_path(env, spec, params), None)
    except PictureFailed as failed:     # a bug, logged: its error line stands in the picture's place
        return [failed.line]
    scene, limits = setup
    focus = {"lathe.toolprobe.calibrate": ("tool_probe",), "lathe.tool.measure": ("tool_probe",),
             "lathe.tool.auto": ("tool_probe",), "lathe.probe.groove": ("groove",)}.get(spec.name, ("part",))
    return [Markup(lathe_svg(scene, limits, path=path, svg_id="task-lathe", focus=focus,
                             caption=_("Real set-up, X up / Z right (MCS radius); dashed: the planned path")))]
