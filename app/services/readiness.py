"""Readiness checklist of the prerequisites (spec/jog-measuring.md §1.6 [I], alarms §10).

Each check says ok/fail, how serious a failure is (``error`` would block NC Start, ``warning``
only warns: measuring with an uncalibrated probe is allowed) and the manual's alarm it maps to.
Checks apply to task categories: ``workpiece`` (edge, corner, pocket, hole, spigot, plane),
``probe_calibration`` (probe.*), ``tool_probe_calibration`` (toolprobe.*) and
``tool_measuring`` (tool.*).

This module only reports; NC Start keeps its own refusals (workflow and engine alarms).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

from app.errors import InvalidInput
from app.records import PROBE_TOOL_TYPE, is_probe_tool
from app.services.measuring import MeasuringEnv
from app.workflow.planning import tool_probe_widths
from app.workflow.tasks import TASKS, Category, task_spec
from engine import alarms

WORKPIECE, PROBE_CAL, TOOLPROBE_CAL, TOOL = (c.value for c in (
    Category.WORKPIECE, Category.PROBE_CALIBRATION, Category.TOOL_PROBE_CALIBRATION, Category.TOOL_MEASURING))
CATEGORIES = (WORKPIECE, PROBE_CAL, TOOLPROBE_CAL, TOOL)
ALL = CATEGORIES



@dataclass(frozen=True)
class Check:
    id: str
    group: str
    label: str
    ok: bool
    message: str
    alarm: int | None = None
    severity: str = "error"            # "error": would block NC Start; "warning": measuring allowed
    applies: tuple[str, ...] = ALL

    def to_api(self) -> dict:
        return {**asdict(self), "applies": list(self.applies)}


def category_of(task: str) -> str:
    return task_spec(task).category.value


class ReadinessService:
    def __init__(self, services):
        self._services = services

    def report(self, task: str | None = None) -> dict:
        if task is not None and task not in TASKS:
            raise InvalidInput(f"task: unknown measuring task {task!r}", field="task")
        checks = self.checks(task)
        ready = {c: not any(not k.ok and k.severity == "error" and c in k.applies for k in checks)
                 for c in CATEGORIES}
        answer: dict[str, object] = {"task": task, "ready": ready, "checks": [c.to_api() for c in checks]}
        if task is not None:
            cat = category_of(task)
            relevant = [c for c in checks if cat in c.applies and not c.ok]
            answer.update({
                "category": cat,
                "ready_for_task": ready[cat],
                "blocking": [c.to_api() for c in relevant if c.severity == "error"],
                "warnings": [c.to_api() for c in relevant if c.severity == "warning"],
            })
        return answer

    def checks(self, task: str | None = None) -> list[Check]:
        s = self._services
        ctx = MeasuringEnv(s.db, s.machine, s.settings).measuring_context()
        status = s.machine.machine.status()
        return [*_machine_checks(s.machine, status), *_probe_checks(ctx, status), *_tool_checks(ctx, status, task)]


def _machine_checks(machine, status) -> list[Check]:
    geo = [a for a in ("X", "Y", "Z") if a in machine.axes]
    newest = status.alarms[-1] if status.alarms else None
    has_tp = machine.has_tool_probe
    return [
        Check("geometry_axes", "Machine", "All three geometry axes exist", len(geo) == 3,
              f"geometry axes {', '.join(geo) or 'none'}", alarms.NO_GEOMETRY_AXIS.number),
        Check("referenced", "Machine", "Machine axes referenced", True,
              "the simulated axes are referenced at power-on"),
        Check("no_alarm", "Machine", "No alarm pending", newest is None,
              "no alarm" if newest is None else f"{newest.text}: press Reset",
              newest.code if newest else None),
        Check("tool_probe_present", "Machine", "Switching tool probe installed", has_tp,
              "tool probe on the table" if has_tp else "this machine has no tool probe",
              None, "error", (TOOLPROBE_CAL, TOOL)),
    ]


def _probe_checks(ctx, status) -> list[Check]:
    """The workpiece probe: active, its offset, calibrated in the plane, the override, the frames."""
    plane, tool, t = ctx.plane, ctx.tool, status.tool
    is_probe = is_probe_tool(tool)
    wp = (WORKPIECE, PROBE_CAL)
    if t is None:
        msg = "no tool in the spindle: load the 3D probe"
    elif is_probe:
        msg = f"T{t} is the 3D probe (type {PROBE_TOOL_TYPE})"
    else:
        msg = f"T{t} is type {tool.get('type') if tool else '?'}, not a 3D probe (type {PROBE_TOOL_TYPE})"
    out = [Check("probe_active", "Probe", "Workpiece probe is the active tool", is_probe, msg,
                 alarms.PROBE_TYPE.number, "error", wp)]
    length = float(status.tool_length)
    has_d = t is not None and tool is not None and length > 0
    out.append(Check("probe_offset", "Probe", "Tool offset (D number) of the probe active",
                     has_d and is_probe,
                     f"L1 = {length:.3f} mm" if has_d else "no tool offset active",
                     alarms.NO_D_NUMBER.number, "error", wp))
    out.append(_probe_calibrated(ctx, is_probe))
    cal_ovr = (ctx.probe_data or {}).get("calibration_override")
    ovr_ok = cal_ovr is None or abs(float(cal_ovr) - float(status.feed_override)) < 1e-9
    out.append(Check("override", "Probe", "Feed override as during calibration", ovr_ok,
                     "no calibration override recorded" if cal_ovr is None else
                     f"now {status.feed_override:g} %, calibrated at {float(cal_ovr):g} %",
                     None, "warning", (WORKPIECE,)))
    out.append(Check("plane", "Probe", "Working plane", True,
                     f"{plane.name}: infeed axis {plane.infeed}", None, "warning", wp))
    out.append(Check("no_scale", "Probe", "No scale factor in the frames", True,
                     "frames carry translation and rotation only", alarms.SCALE_FACTOR.number, "error", wp))
    return out


def _probe_calibrated(ctx, is_probe: bool) -> Check:
    plane = ctx.plane
    probe_data = ctx.probe_data or {}
    cal_plane = probe_data.get("calibrated_plane")
    cal_r, cal_l = bool(probe_data.get("calibrated_radius")), bool(probe_data.get("calibrated_length"))
    plane_ok = cal_plane in (None, plane.name)
    calibrated = is_probe and cal_r and cal_l and plane_ok
    if not is_probe:
        msg = "no probe in the spindle"
    elif calibrated:
        msg = f"probe {ctx.extra.get('probe_number')} calibrated (length and radius) in {cal_plane or plane.name}"
    else:
        missing = [w for w, ok in (("length", cal_l), ("radius", cal_r)) if not ok]
        if not plane_ok:
            missing.append(f"plane {plane.name} (calibrated in {cal_plane})")
        msg = ("not calibrated: " + ", ".join(missing)
               + "; measuring is allowed, results carry pre-travel and eccentricity")
    return Check("probe_calibrated", "Probe", f"Probe calibrated in the active plane {plane.name}",
                 calibrated, msg, alarms.NOT_CALIBRATED_IN_PLANE.number, "warning", (WORKPIECE,))


def _tool_checks(ctx, status, task: str | None) -> list[Check]:
    """Tool measuring: a cutter active with its data, the tool probe's widths and calibration."""
    tool, t = ctx.tool, status.tool
    is_probe = is_probe_tool(tool)
    length = float(status.tool_length)
    tool_probe = (ctx.extra or {}).get("tool_probe") or {}
    tp_n = (ctx.extra or {}).get("tool_probe_number", 1)
    tl = (TOOLPROBE_CAL, TOOL)
    cutter = tool is not None and not is_probe
    if tool is None:
        msg, alarm = "no tool in the spindle: load the tool to measure", alarms.NO_D_NUMBER.number
    elif is_probe:
        msg, alarm = f"T{t} is the workpiece probe: load a cutter", alarms.TOOL_TYPE.number
    else:
        msg, alarm = f"T{t} (type {tool.get('type')})", alarms.NO_D_NUMBER.number
    out = [Check("cutter_active", "Tool", "A cutter is the active tool", cutter, msg, alarm, "error", tl)]
    if cutter and tool is not None:
        radius = float(tool.get("radius", 0.0)) + float((tool.get("wear") or {}).get("radius", 0.0))
        data_ok = length > 0 and radius > 0
        msg = f"L1 {length:.3f} mm, R {radius:.3f} mm"
    else:
        data_ok, msg = False, "no cutter in the spindle"
    out.append(Check("tool_data", "Tool", "Approximate tool length and radius entered", data_ok, msg,
                     alarms.TOOL_SIZE_ZERO.number, "error", (TOOL,)))
    dl, dr = tool_probe_widths(ctx.settings, tool_probe)
    out.append(Check("tool_probe_widths", "Tool", "Tool probe effective diameter set",
                     dl > 0 and dr > 0, f"E_MESS_MT_DL {dl:g} mm, E_MESS_MT_DR {dr:g} mm",
                     alarms.TOOL_PROBE_DIAMETER.number, "error", tl))
    tp_l, tp_d = bool(tool_probe.get("calibrated_length")), bool(tool_probe.get("calibrated_diameter"))
    need_d = task == "tool.diameter"
    tp_ok = tp_l and (tp_d or not need_d)
    state = ", ".join(f"{w} {'calibrated' if ok else 'not calibrated'}"
                      for w, ok in (("length", tp_l), ("diameter", tp_d)))
    out.append(Check("tool_probe_calibrated", "Tool",
                     f"Tool probe {tp_n} calibrated" + (" (length and diameter)" if need_d else ""),
                     tp_ok, state, alarms.NOT_CALIBRATED_IN_PLANE.number, "error", (TOOL,)))
    return out
