"""Adapter between the workflow and engine.plan: builds the PlanContext from the GUD settings.

Workpiece tasks: GUD feeds/paths and the active probe record (skew in the measuring WCS).
Tool tasks (``toolprobe.calibrate``, ``tool.length``, ``tool.diameter``, jog-measuring §7): the tool in
the spindle (tool table row: radius = geometry + wear, L1 = the NC's offset length), the stored
tool-probe record ``_TP[n]`` (trigger values keyed "X-", "X+", "Y-", "Y+", "Z-", MCS) and the
E_MESS_MT_* settings (jog-measuring §8.3).

Effective tool-probe widths (E_MESS_MT_DL / E_MESS_MT_DR, "must be set at commissioning"): the
GUD value when > 0, else the tool-probe record's ``disc_diameter`` (shape data entered on the
tool-probe screen / ``PUT /api/tool-probes/{n}``). Neither set -> alarm TOOL_PROBE_DIAMETER
naming both places.
"""

from __future__ import annotations

import numpy as np

from app.gud import GudSettings
from app.records import is_probe_tool
from engine import alarms
from engine import plan as engine_plan
from engine.compensation import skew_in_wcs
from engine.types import MeasuringError


def tool_probe_widths(settings: GudSettings, record: dict | None) -> tuple[float, float]:
    """(E_MESS_MT_DL, E_MESS_MT_DR): the GUD value when > 0, else the record's disc diameter."""
    disc = float((record or {}).get("disc_diameter") or 0.0)
    dl = float(settings.mt_dl or 0.0) or disc
    dr = float(settings.mt_dr or 0.0) or disc
    return dl, dr


def active_tool(ctx) -> dict:
    """The cutter in the spindle (tool table row); NO_D_NUMBER/TOOL_TYPE when none or the 3D probe."""
    tool = ctx.tool
    if not tool:
        raise MeasuringError(alarms.NO_D_NUMBER, "No tool active: load the tool to be measured into the spindle")
    if is_probe_tool(tool):
        raise MeasuringError(alarms.TOOL_TYPE, f"T{tool['t']} is the workpiece probe (type 710): "
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
            raise MeasuringError(alarms.TOOL_PROBE_DIAMETER, f"Tool probe diameter too small: set {gud} or the disc "
                                                 "diameter of the tool probe record (Tool probe data)")
    if length <= 0.0 or (radius <= 0.0 and (task != "toolprobe.calibrate" or need_dr)):
        raise MeasuringError(alarms.TOOL_SIZE_ZERO, f"Tool length or radius is 0: enter the approximate values of T{tool['t']}")


def tool_fields(ctx, task: str = "", params: dict | None = None, check: bool = True) -> dict:
    """PlanContext keyword arguments of tool measuring (spindle tool, _TP record, E_MESS_MT_*).

    ``check``: refuse missing data with the manual's alarms (NC Start); without it (the screen's
    preview) missing data just leaves the defaults."""
    s = ctx.settings
    if check:
        tool = active_tool(ctx)
    else:
        tool = ctx.tool
        if not tool or is_probe_tool(tool):
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
        mt_axes=int(s.mt_ax),
        mt_diameter_length=dl,
        mt_diameter_radius=dr,
        mt_dz=float(s.mt_dz),
        mt_dir=int(s.mt_dir),
        mt_path=float(s.mt_d),
        mt_feed=float(s.mt_fm),
        path_length=float(s.d_l),
        path_radius=float(s.d_r),
        max_surface_speed=float(s.mt_max_v),
        max_spindle_speed=float(s.mt_max_s),
        max_feed_rotating=float(s.mt_max_f),
        min_feed_rotating=float(s.mt_min_f),
        feed_factor1=float(s.mt_f_fak1),
        feed_factor2=float(s.mt_f_fak2),
        min_accuracy=float(s.mt_min_d),
    )


def context_from(ctx, spec=None, params: dict | None = None) -> engine_plan.PlanContext:
    """PlanContext from the MeasuringContext (GUD settings of jog-measuring §8, active probe/tool records).

    For a tool task's ``spec`` (app.workflow.tasks.TaskSpec) the tool data are checked with the
    manual's alarms; without a spec (live preview) they are filled in when a cutter is in the
    spindle."""
    s = ctx.settings
    probe = ctx.probe           # None without a probe in the spindle: a workpiece plan then refuses
    wcs2bcs = ctx.chain().wcs2bcs
    if spec is None:
        extra = tool_fields(ctx, check=False)
    elif spec.family.tool_measuring:
        extra = tool_fields(ctx, spec.name, params or {}, check=True)
    else:
        extra = {}
    return engine_plan.PlanContext(
        plane=ctx.plane,
        probe_record=probe,
        skew_wcs=skew_in_wcs(probe, wcs2bcs, ctx.spindle_angle) if probe is not None else np.zeros(3),
        spindle_angle=float(ctx.spindle_angle),
        wcs2bcs=wcs2bcs,
        measuring_feed=float(s.measuring_feed),
        position_feed=float(s.position_feed),
        position_feed_infeed=float(s.position_feed_infeed),
        measuring_path=float(s.measuring_path),
        attempts=int(s.attempts),
        fast_feed=float(s.fast_feed) if s.two_stage else None,
        rapid_return=bool(s.rapid_return),
        spigot_safety=float(s.spigot_safety),
        ring_chords=bool(s.cal_chords),
        **extra,
    )
