"""Adapter between the workflow and engine.plan: builds the PlanContext from the settings.

Workpiece tasks: GUD feeds/paths and the active probe record (skew in the measuring WCS).
Tool tasks (``toolprobe.calibrate``, ``tool.length``, ``tool.diameter``, spec §7): the tool in
the spindle (tool table row: radius = geometry + wear, L1 = the NC's offset length), the stored
tool-probe record ``_TP[n]`` (trigger values keyed "X-", "X+", "Y-", "Y+", "Z-", MCS) and the
E_MESS_MT_* settings (spec §8.3).

Effective tool-probe widths (E_MESS_MT_DL / E_MESS_MT_DR, "must be set at commissioning"): the
GUD value when > 0, else the tool-probe record's ``disc_diameter`` (shape data entered on the
tool-probe screen / ``PUT /api/tool-probes/{n}``). Neither set -> alarm 61230 naming both places.

[I] First calibration: the cycle expects rough trigger values (math §14.5); without a stored
"Z-" value the first −infeed touch searches over max(2·E_MESS_MT_D, E_MESS_D_M) instead of
2·E_MESS_MT_D, so the operator may start the calibration tool up to that far above the probe.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from engine import plan as engine_plan
from engine.compensation import skew_in_wcs
from engine.types import MeasuringError, ProbeRecord, ProbeStep

TASK_POINTS = engine_plan.TASK_POINTS
planned_path = engine_plan.planned_path

TOOL_FAMILIES = ("tool", "toolprobe")
PROBE_TOOL_TYPES = (710,)
ALARM_NO_TOOL = 61311          # "No D number active ... for the tool (tool measuring)" (spec §10)
ALARM_PROBE_AS_TOOL = 61314    # spec §10 [I]: "tool measuring with the probe as active tool"
ALARM_DIAMETER = 61230         # "Tool probe diameter too small" (E_MESS_MT_DL/DR)


def validate_params(task: str, params: dict, plane) -> dict:
    """engine.plan.validate_params; for tool tasks ``compensation`` stays absent unless given,
    so the finisher falls back to the setting _JM_B[0] (``tool_offset_mode``)."""
    out = engine_plan.validate_params(task, params, plane)
    if task in ("tool.length", "tool.diameter") and "compensation" not in (params or {}):
        out.pop("compensation", None)
    return out


def point_program(task: str, params: dict, n: int, start, ctx: engine_plan.PlanContext):
    """engine.plan.point_program; a first tool-probe calibration searches longer (module doc)."""
    program = engine_plan.point_program(task, params, n, start, ctx)
    if task != "toolprobe.calibrate" or f"{ctx.plane.infeed}-" in (ctx.tool_probe or {}):
        return program
    return _first_probe_longer(program, max(2.0 * ctx.mt_path, ctx.measuring_path))


def _first_probe_longer(program, distance: float):
    reply, first = None, True
    try:
        while True:
            step = program.send(reply)
            if first and isinstance(step, ProbeStep):
                first = False
                step = dataclasses.replace(step, distance=max(float(step.distance), distance))
            reply = yield step
    except StopIteration as done:
        return done.value


def is_tool_task(task: str) -> bool:
    return task.split(".")[0] in TOOL_FAMILIES


def tool_probe_widths(settings: dict, record: dict | None) -> tuple[float, float]:
    """(E_MESS_MT_DL, E_MESS_MT_DR): the GUD value when > 0, else the record's disc diameter."""
    disc = float((record or {}).get("disc_diameter") or 0.0)
    dl = float(settings.get("mt_dl") or 0.0) or disc
    dr = float(settings.get("mt_dr") or 0.0) or disc
    return dl, dr


def active_tool(ctx) -> dict:
    """The cutter in the spindle (tool table row); 61311/61314 when none or the 3D probe."""
    tool = ctx.tool
    if not tool:
        raise MeasuringError(ALARM_NO_TOOL, "No tool active: load the tool to be measured into the spindle")
    if int(tool.get("type", 0)) in PROBE_TOOL_TYPES:
        raise MeasuringError(ALARM_PROBE_AS_TOOL, f"T{tool['t']} is the workpiece probe (type 710): "
                                                  "load a cutter for tool measuring")
    return tool


def _check_tool_data(task: str, params: dict, tool: dict, dl: float, dr: float, radius: float,
                     length: float) -> None:
    need_dl = task == "tool.length"
    need_dr = task == "tool.diameter" or (task == "toolprobe.calibrate"
                                          and params.get("mode") == "length_diameter")
    for needed, width, gud in ((need_dl, dl, "E_MESS_MT_DL (settings mt_dl)"),
                               (need_dr, dr, "E_MESS_MT_DR (settings mt_dr)")):
        if needed and width <= 0.0:
            raise MeasuringError(ALARM_DIAMETER, f"Tool probe diameter too small: set {gud} or the disc "
                                                 "diameter of the tool probe record (Tool probe data)")
    if length <= 0.0 or (radius <= 0.0 and (task != "toolprobe.calibrate" or need_dr)):
        raise MeasuringError(61351, f"Tool length or radius is 0: enter the approximate values of T{tool['t']}")


def tool_fields(ctx, task: str = "", params: dict | None = None, check: bool = True) -> dict:
    """PlanContext keyword arguments of tool measuring (spindle tool, _TP record, E_MESS_MT_*).

    ``check``: refuse missing data with the manual's alarms (NC Start); without it (the screen's
    preview) missing data just leaves the defaults."""
    s = ctx.settings
    if check:
        tool = active_tool(ctx)
    else:
        tool = ctx.tool
        if not tool or int(tool.get("type", 0)) in PROBE_TOOL_TYPES:
            return {}
    record = (ctx.extra or {}).get("tool_probe") or {}
    wear = tool.get("wear") or {}
    radius = float(tool.get("radius", 0.0)) + float(wear.get("radius", 0.0))
    length = float(ctx.tool_length)
    dl, dr = tool_probe_widths(s, record)
    if check:
        _check_tool_data(task, params or {}, tool, dl, dr, radius, length)
    return dict(
        tool_probe={k: float(v) for k, v in (record.get("trigger") or {}).items()},
        tool_radius=radius,
        tool_length=length,
        mt_axes=int(s.get("mt_ax", 133)),
        mt_diameter_length=dl,
        mt_diameter_radius=dr,
        mt_dz=float(s.get("mt_dz", 2.0)),
        mt_dir=int(s.get("mt_dir", -1)),
        mt_path=float(s.get("mt_d", 10.0)),
        mt_feed=float(s.get("mt_fm", 100.0)),
        path_length=float(s.get("d_l", 2.0)),
        path_radius=float(s.get("d_r", 1.0)),
        max_surface_speed=float(s.get("mt_max_v", 100.0)),
        max_spindle_speed=float(s.get("mt_max_s", 1000.0)),
        max_feed_rotating=float(s.get("mt_max_f", 20.0)),
        min_feed_rotating=float(s.get("mt_min_f", 1.0)),
        feed_factor1=float(s.get("mt_f_fak1", 10.0)),
        feed_factor2=float(s.get("mt_f_fak2", 0.0)),
        min_accuracy=float(s.get("mt_min_d", 0.01)),
    )


def context_from(ctx, session=None) -> engine_plan.PlanContext:
    """PlanContext from the MeasuringContext (GUD settings of spec §8, active probe/tool records).

    With a tool-task ``session`` the tool data are checked (alarms 61311/61314/61230/61351);
    without a session (live preview) they are filled in when a cutter is in the spindle."""
    s = ctx.settings
    probe = ctx.probe or ProbeRecord()
    wcs2bcs = ctx.chain().wcs2bcs
    task = getattr(session, "task", "") or ""
    if session is None:
        extra = tool_fields(ctx, check=False)
    elif is_tool_task(task):
        extra = tool_fields(ctx, task, getattr(session, "params", {}) or {}, check=True)
    else:
        extra = {}
    return engine_plan.PlanContext(
        plane=ctx.plane,
        probe=probe,
        skew_wcs=skew_in_wcs(probe, wcs2bcs, ctx.spindle_angle) if ctx.probe else np.zeros(3),
        measuring_feed=float(s.get("measuring_feed", 300.0)),
        position_feed=float(s.get("position_feed", 2000.0)),
        position_feed_infeed=float(s.get("position_feed_infeed", 2000.0)),
        measuring_path=float(s.get("measuring_path", 50.0)),
        attempts=int(s.get("attempts", 1)),
        fast_feed=float(s.get("fast_feed", 900.0)) if s.get("two_stage") else None,
        rapid_return=bool(s.get("rapid_return", False)),
        spigot_safety=float(s.get("spigot_safety", 5.0)),
        **extra,
    )
