"""The lathe tasks of turning.md §10.2: params -> cycle call -> point program -> evaluation.

Tasks (one point each): ``lathe.toolprobe.calibrate`` (CYCLE982 0/10/100000/100010),
``lathe.tool.measure`` (1/11/100001/100011 and the mill variants), ``lathe.tool.auto`` (2/12),
``lathe.probe.groove`` (CYCLE973 xxx13), ``lathe.probe.surface`` (973 0), ``lathe.point``
(CYCLE974 100/0/1000), ``lathe.two_point`` (CYCLE994 1/2).

Usage: ``p = validate_lathe_params(task, params)`` (ParamError = ValueError naming the field,
HTTP 422); ``prep = prepare(task, p, ctx)`` (the cycle call, the context with the task's channel
bits and groove, the tool target); ``prep.coords`` tells the workflow whether the start and the
steps are MCS or WCS (X always a radius); ``lathe_program(prep, start)`` is the generator for
engine.plan.run_program; ``evaluate_lathe(prep, point, ev=..)``; for lathe.point / lathe.two_point
with a tool target or measure only, apply the mean-value strategy to ``evaluation.measurement``
and call ``finish_lathe(prep, evaluation, decision=.., amount=.., ...)``.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from functools import partial
from typing import Any

import numpy as np
import numpy.typing as npt

from engine.alarms import AlarmDef
from engine.checks import ParamError, param_bool, param_choice, param_int, param_number
from engine.plan import run_program
from engine.turning import (
    AXIS_MA,
    LatheContext,
    LathePoint,
    LatheProgram,
    LatheTool,
)
from engine.turning_mills import evaluate_mill, mill_program
from engine.turning_offsets import ToolTarget
from engine.turning_point import evaluate_point, point_program
from engine.turning_probe import (
    Cycle973,
    ProbeCalibrationResult,
    evaluate_probe_calibration,
    probe_calibration_program,
)
from engine.turning_tools import (
    Cycle982,
    ToolProbeResult,
    ToolResult,
    decode_982,
    evaluate_toolprobe,
    evaluate_turning_tool,
    toolprobe_program,
    turning_tool_program,
)
from engine.turning_twopoint import evaluate_two_point, two_point_program
from engine.turning_workpiece import WorkpieceCall, WorkpieceMeasurement, WorkpieceResult, finish_workpiece
from engine.types import Latch, MeasuringError, MoveStep, ProbeStep, Step

LATHE_TASKS = ("lathe.toolprobe.calibrate", "lathe.tool.measure", "lathe.tool.auto", "lathe.probe.groove",
               "lathe.probe.surface", "lathe.point", "lathe.two_point")

# design jog-measuring §9.3 tolerance object -> cycle parameter; defaults MM jog-measuring §3.2 / turning.md §0.9
TOLERANCE_KEYS = {"upper": "tul", "lower": "tll", "zero_range": "tzl", "mean_range": "tmv",
                  "dim_difference": "tdif", "safe_area": "tsa", "k": "k", "evnum": "evnum"}
TOLERANCE_DEFAULTS = {"upper": 1.0, "lower": -1.0, "zero_range": 0.001, "mean_range": 0.7, "dim_difference": 1.2,
                      "safe_area": 2.0, "k": 1.0, "evnum": 0}
TASK_TOLERANCES = {
    "lathe.toolprobe.calibrate": ("zero_range", "safe_area"),
    "lathe.tool.measure": ("zero_range", "dim_difference", "safe_area", "evnum"),
    "lathe.tool.auto": ("zero_range", "dim_difference", "safe_area", "evnum"),
    "lathe.probe.groove": ("zero_range", "safe_area"),
    "lathe.probe.surface": ("zero_range", "safe_area"),
    "lathe.point": ("upper", "lower", "zero_range", "mean_range", "dim_difference", "safe_area", "k", "evnum",
                    "keep_mean", "setpoint"),
    "lathe.two_point": ("upper", "lower", "zero_range", "mean_range", "dim_difference", "safe_area", "k", "evnum",
                        "keep_mean", "setpoint"),
}


# --- validation -------------------------------------------------------------------------------


def _tolerance(task: str, params: Mapping[str, Any]) -> dict[str, Any]:
    raw = params.get("tolerance", {}) or {}
    if not isinstance(raw, Mapping):
        raise ParamError("tolerance", "tolerance must be an object")
    allowed = TASK_TOLERANCES[task]
    out: dict[str, Any] = {}
    for k, v in raw.items():
        f = f"tolerance.{k}"
        if k not in allowed:
            raise ParamError(f, f"{f} is not used by {task} (allowed: {', '.join(allowed)})")
        if k == "keep_mean":
            if not isinstance(v, bool):
                raise ParamError(f, f"{f} must be true or false")
            out[k] = v
        elif k == "evnum":
            out[k] = param_int(raw, k, 0, 0, field_name=f)
        elif k == "k":
            out[k] = param_number(raw, k, field_name=f)
            if out[k] == 0:
                raise ParamError(f, f"{f} (the weighting factor) must not be 0")
        else:
            out[k] = param_number(raw, k, field_name=f)
            if k in ("zero_range", "mean_range", "dim_difference", "safe_area") and out[k] is not None and out[k] < 0:
                raise ParamError(f, f"{f} must be >= 0, got {v!r}")
    return out


def _groove(params: Mapping[str, Any]) -> dict[str, Any]:
    g = params.get("groove")
    if not isinstance(g, Mapping) or not g:
        raise ParamError("groove", "groove is required: the _KB values or {\"number\": n}")
    if "number" in g:
        if len(g) != 1:
            raise ParamError("groove", "groove gives either a stored record number or the values")
        return {"number": param_int(g, "number", 1, 1, field_name="groove.number")}
    keys = ("x_minus", "x_plus", "bottom_z", "z_minus", "z_plus", "top_x", "bottom_x")
    out: dict[str, Any] = {}
    for k in g:
        if k not in keys:
            raise ParamError(f"groove.{k}", f"groove.{k} is not a groove value ({', '.join(keys)})")
        out[k] = param_number(g, k, required=True, field_name=f"groove.{k}")
    return out


ZO_NAMES = {**{f"G{54 + i}": 1 + i for i in range(4)}, **{f"G{500 + n}": n for n in range(5, 100)},
            **{f"BASIC_{n}": 1011 + n for n in range(16)}, "BASIC_REF": 2000}


def _target(params: Mapping[str, Any], zero_offsets: bool) -> str | dict[str, Any]:
    """``measure_only``, a zero offset (where the task may write one) or a tool object."""
    t = params.get("target", "measure_only")
    if t in (None, "measure_only"):
        return "measure_only"
    if isinstance(t, str):
        if not zero_offsets or t.upper() not in ZO_NAMES:
            raise ParamError("target", f"target {t!r} is not a zero offset of lathe.point "
                                       f"(G54..G57, G505..G599, BASIC_0..BASIC_15, BASIC_REF) nor a tool object")
        return t.upper()
    if not isinstance(t, Mapping):
        raise ParamError("target", "target must be a zero offset name or a tool object")
    tool = param_int(t, "tool", 0, 1, field_name="target.tool")
    edge = param_int(t, "edge", 1, 1, field_name="target.edge")
    correct = str(t.get("correct", "length")).lower()
    if correct not in ("length", "radius", "l1", "l2", "l3"):
        raise ParamError("target.correct", f"target.correct must be length, radius, L1, L2 or L3, got {correct!r}")
    mode = t.get("mode", "wear")
    if mode not in ("wear", "geometry"):
        raise ParamError("target.mode", f"target.mode must be wear or geometry, got {mode!r}")
    inverse = t.get("inverse", False)
    if not isinstance(inverse, bool):
        raise ParamError("target.inverse", "target.inverse must be true or false")
    return {"tool": tool, "edge": edge, "correct": correct, "mode": mode, "inverse": inverse}


def validate_lathe_params(task: str, params: Mapping[str, Any] | None) -> dict[str, Any]:
    """Normalised params with defaults (turning.md §10.2), or ParamError(field, message).

    Common: ``probe`` (_PRNUM, default 1), ``measuring_path`` (_FA > 0, default 2),
    ``feed`` (_VMS ≥ 0, default 0), ``measurements`` (_NMSP ≥ 1), ``tolerance`` (the keys the
    task uses, design jog-measuring §9.3). Mills on a lathe (extension): ``quantity`` length / radius /
    length_radius, ``reversal``, ``position`` axial / radial, ``start_angle`` (_STA1),
    ``correction_angle`` (_CORA). Values are taken in the units the cycles read them (turning §10.2
    "Units": ``setpoint`` and the 974/994 bands are diameters on X with DIAMON): nothing is
    converted here. The task's own params are its entry's in ``LATHE_TASK_RULES``.
    """
    rules = LATHE_TASK_RULES.get(task)
    if rules is None:
        raise ParamError("task", f"unknown lathe task {task!r}")
    p = dict(params or {})
    out: dict[str, Any] = {"probe": param_int(p, "probe", 1, 1), "measurements": param_int(p, "measurements", 1, 1),
                           "tolerance": _tolerance(task, p)}
    fa = param_number(p, "measuring_path", 2.0, required=True)     # null/"": refused, not a TypeError
    if fa <= 0.0:
        raise ParamError("measuring_path", f"measuring_path must be > 0, got {fa:g}")
    out["measuring_path"] = fa
    feed = param_number(p, "feed", 0.0, required=True)
    if feed < 0.0:
        raise ParamError("feed", f"feed must be >= 0 (0 = the cycle's default), got {feed:g}")
    out["feed"] = feed
    rules.params(p, out)
    return out


def _tool_params(p: Mapping[str, Any], out: dict[str, Any], *, calibrate: bool = False, auto: bool = False) -> None:
    """CYCLE982: the tool probe's calibration (``calibrate``), a tool measured, or automatically (``auto``)."""
    out["reference"] = param_choice(p, "reference", ("machine", "workpiece"), "machine")
    if not auto:
        out["axis"] = param_choice(p, "axis", ("Z", "X"), None, required=True)
        out["incremental"] = param_bool(p, "incremental", False)
        if out["incremental"]:
            out["direction"] = param_choice(p, "direction", ("+", "-"), None, required=True)
    if calibrate:
        return
    out["compensation"] = param_choice(p, "compensation", ("geometry", "wear"), "geometry")
    out["quantity"] = param_choice(p, "quantity", ("length", "radius", "length_radius"), "length")
    out["reversal"] = param_bool(p, "reversal", False)
    out["position"] = param_choice(p, "position", ("axial", "radial"), "axial")
    out["start_angle"] = param_number(p, "start_angle", 0.0, required=True)
    out["correction_angle"] = param_number(p, "correction_angle", 0.0, required=True)
    if auto and out["quantity"] != "length":
        raise ParamError("quantity", "lathe.tool.auto determines every quantity itself")
    if out.get("incremental") and out["quantity"] == "length_radius":
        raise ParamError("quantity", "length and radius cannot be measured incrementally")


def _groove_params(p: Mapping[str, Any], out: dict[str, Any]) -> None:
    """CYCLE973 in a reference groove."""
    out["groove"] = _groove(p)
    out["axis"] = param_choice(p, "axis", ("Z", "X"), None, required=True)
    out["direction"] = param_choice(p, "direction", ("+", "-", "both"), None, required=True)
    out["skew"] = param_bool(p, "skew", False)
    out["ball_diameter"] = param_bool(p, "ball_diameter", False)
    if out["direction"] != "both" and (out["skew"] or out["ball_diameter"]):
        name = "skew" if out["skew"] else "ball_diameter"
        raise ParamError(name, f"{name} needs direction \"both\": in one direction it cannot be determined "
                               "[L20293]")


def _surface_params(p: Mapping[str, Any], out: dict[str, Any]) -> None:
    """CYCLE973 on a surface."""
    out["axis"] = param_choice(p, "axis", ("Z", "X", "Y"), None, required=True)
    out["direction"] = param_choice(p, "direction", ("+", "-"), None, required=True)
    out["setpoint"] = param_number(p, "setpoint", required=True)


def _workpiece_params(p: Mapping[str, Any], out: dict[str, Any], *, zero_offsets: bool) -> None:
    """CYCLE974/994: axis, setpoint (the nominal; a different tolerance.setpoint is refused), target."""
    out["axis"] = param_choice(p, "axis", ("Z", "X", "Y"), None, required=True)
    out["setpoint"] = param_number(p, "setpoint", required=True)
    tol_set = out["tolerance"].get("setpoint")
    if tol_set is not None and tol_set != out["setpoint"]:
        raise ParamError("tolerance.setpoint", "tolerance.setpoint is not used: the task's setpoint is the "
                                               "nominal; a different value is refused (turning.md §10.2)")
    out["target"] = _target(p, zero_offsets)


def _point_params(p: Mapping[str, Any], out: dict[str, Any]) -> None:
    """CYCLE974: one point; a zero offset or a tool as target, the reversal measurement."""
    _workpiece_params(p, out, zero_offsets=True)
    out["reversal"] = param_bool(p, "reversal", False)
    angle = param_number(p, "start_angle", 0.0, required=True)
    if not 0.0 <= angle <= 360.0:
        raise ParamError("start_angle", f"start_angle must be 0..360 deg, got {angle:g}")
    out["start_angle"] = angle
    if out["reversal"] and isinstance(out["target"], str) and out["target"] != "measure_only":
        raise ParamError("reversal", "the reversal measurement corrects a tool, not a zero offset")


def _two_point_params(p: Mapping[str, Any], out: dict[str, Any]) -> None:
    """CYCLE994: a diameter between two points, inside or outside, with its protection zone."""
    _workpiece_params(p, out, zero_offsets=False)
    if out["setpoint"] <= 0.0:
        raise ParamError("setpoint", f"setpoint (the diameter) must be > 0, got {out['setpoint']:g}")
    out["inside"] = param_bool(p, "inside", False)
    out["use_ball_diameter"] = param_bool(p, "use_ball_diameter", False)
    zone = _zone(p.get("zone"))
    if not out["inside"] and (zone is None or "Z" not in zone or "X" not in zone):
        raise ParamError("zone", "an outside diameter needs the protection zone {\"Z\", \"X\"} for its detour")
    if out["inside"] and zone is not None and "Z" not in zone:
        raise ParamError("zone.Z", "an inside diameter with a zone leaves the bore via zone.Z")
    out["zone"] = zone


def _zone(zone: Any) -> dict[str, float | None] | None:
    if zone is None:
        return None
    if not isinstance(zone, Mapping):
        raise ParamError("zone", "zone must be an object {\"Z\": _SZA, \"X\": _SZO}")
    extra = [k for k in zone if k not in ("Z", "X")]
    z = {k: param_number(zone, k, field_name=f"zone.{k}") for k in ("Z", "X") if k in zone}
    if extra:
        raise ParamError(f"zone.{extra[0]}", "zone has the keys Z and X only")
    return z


# --- preparing the cycle call -------------------------------------------------------------------

@dataclass(frozen=True)
class LathePrep:
    """A task ready to run: its cycle call, the context it runs in, the tool target."""

    task: str
    params: dict[str, Any]
    call: Cycle982 | Cycle973 | WorkpieceCall
    ctx: LatheContext
    target: ToolTarget | None = None
    zero_offset: str | None = None
    info: dict[str, Any] = field(default_factory=dict)

    @property
    def coords(self) -> str:
        """"MCS" or "WCS": the system of the start position and of every step (X radius)."""
        if isinstance(self.call, Cycle982):
            return "WCS" if decode_982(self.call.mvar, self.call.cycle).workpiece else "MCS"
        if isinstance(self.call, Cycle973):
            return "WCS" if self.call.mvar == 0 else "MCS"
        return "WCS"


def _tol(p: dict[str, Any], name: str) -> Any:      # a number or None (the tolerance object)
    return p["tolerance"].get(name, TOLERANCE_DEFAULTS[name])


def prepare(task: str, params: dict[str, Any], ctx: LatheContext) -> LathePrep:
    """The cycle call of a validated task (turning.md §10.2 -> turning §1–turning §6 parameters) and the context
    with the task's channel bits: compensation -> _CHBIT[3], keep_mean -> _CHBIT[4],
    use_ball_diameter -> _CHBIT[7]; a groove given by value becomes _KB record 1 (``_CALNUM`` 1).
    The call is the task's entry's in ``LATHE_TASK_RULES``."""
    common = {"prnum": params["probe"], "fa": params["measuring_path"], "vms": params["feed"],
              "nmsp": params["measurements"]}
    return LATHE_TASK_RULES[task].call(task, params, ctx, common)


def _probe_tolerances(p: dict[str, Any], common: dict[str, Any]) -> dict[str, Any]:
    return {**common, "tzl": _tol(p, "zero_range"), "tsa": _tol(p, "safe_area")}


def _toolprobe_call(task: str, p: dict[str, Any], ctx: LatheContext, common: dict[str, Any]) -> LathePrep:
    """CYCLE982 calibrating the tool probe (turning §1)."""
    wp = 10 if p["reference"] == "workpiece" else 0
    inc = p["incremental"]
    call = Cycle982(mvar=wp + (100000 if inc else 0), ma=AXIS_MA[p["axis"]],
                    md=(0 if p.get("direction") == "+" else 1) if inc else None, **_probe_tolerances(p, common))
    return LathePrep(task, p, call, ctx)


def _tool_call(task: str, p: dict[str, Any], ctx: LatheContext, common: dict[str, Any], *,
               auto: bool = False) -> LathePrep:
    """CYCLE982 measuring a tool (turning §2), automatically (``auto``: _MVAR units digit 2)."""
    wp = 10 if p["reference"] == "workpiece" else 0
    chbit = dict(ctx.chbit)
    chbit[3] = 1 if p["compensation"] == "wear" else 0
    d4 = {"length": 0, "radius": 1, "length_radius": 2}[p["quantity"]]
    inc = p.get("incremental", False)
    mvar = (2 if auto else 1) + wp + 100 * int(p["reversal"]) + 1000 * d4 \
        + 10000 * int(p["position"] == "radial") + 100000 * int(inc)
    call = Cycle982(mvar=mvar, ma=AXIS_MA.get(p.get("axis", "Z"), 1), md=(0 if p.get("direction") == "+" else 1)
                    if inc else None, tdif=_tol(p, "dim_difference"), evnum=int(_tol(p, "evnum")),
                    sta1=p["start_angle"], cora=p["correction_angle"], **_probe_tolerances(p, common))
    return LathePrep(task, p, call, replace(ctx, chbit=chbit))


def _surface_call(task: str, p: dict[str, Any], ctx: LatheContext, common: dict[str, Any]) -> LathePrep:
    """CYCLE973 calibrating the probe on a surface (turning §3)."""
    call = Cycle973(mvar=0, ma=AXIS_MA[p["axis"]], md=0 if p["direction"] == "+" else 1,
                    setval=p["setpoint"], **_probe_tolerances(p, common))
    return LathePrep(task, p, call, ctx)


def _groove_call(task: str, p: dict[str, Any], ctx: LatheContext, common: dict[str, Any]) -> LathePrep:
    """CYCLE973 calibrating the probe in a groove (turning §3): a stored _KB record or the values as record 1."""
    g = p["groove"]
    both = p["direction"] == "both"
    mvar = 13 + 100 * int(p["ball_diameter"]) + 1000 * (2 if both else 1) + 10000 * int(p["skew"])
    md = 0 if p["direction"] == "+" else 1
    if "number" in g:
        calnum, run_ctx = g["number"], ctx
    else:
        kb = (g.get("x_plus", 0.0), g.get("x_minus", 0.0), g.get("bottom_z", 0.0), g.get("z_plus", 0.0),
              g.get("z_minus", 0.0), g.get("top_x", 0.0), g.get("bottom_x", 0.0))
        calnum, run_ctx = 1, replace(ctx, kb=(kb,))
    call = Cycle973(mvar=mvar, ma=AXIS_MA[p["axis"]], md=md, calnum=calnum, **_probe_tolerances(p, common))
    return LathePrep(task, p, call, run_ctx)


def _workpiece_target(p: dict[str, Any]) -> tuple[ToolTarget | None, str | None, int]:
    """(tool target, zero offset, _KNUM) of a workpiece task's ``target``."""
    t = p["target"]
    if isinstance(t, str) and t != "measure_only":
        return None, t, ZO_NAMES[t]
    if isinstance(t, Mapping):
        return ToolTarget(t=t["tool"], d=t["edge"], quantity=t["correct"], inverse=t["inverse"],
                          geometry=t["mode"] == "geometry"), None, 0
    return None, None, 0


def _workpiece_tolerances(p: dict[str, Any], ctx: LatheContext) -> tuple[dict[str, Any], dict[int, int]]:
    """The tolerance parameters of CYCLE974/994 and the channel bits with keep_mean (_CHBIT[4])."""
    tol = {TOLERANCE_KEYS[k]: _tol(p, k) for k in TOLERANCE_KEYS}
    tol["evnum"] = int(tol["evnum"])
    chbit = dict(ctx.chbit)
    if "keep_mean" in p["tolerance"]:
        chbit[4] = int(p["tolerance"]["keep_mean"])
    return tol, chbit


def _point_call(task: str, p: dict[str, Any], ctx: LatheContext, common: dict[str, Any]) -> LathePrep:
    """CYCLE974: one point, into a zero offset, a tool, or measure only (turning §4)."""
    tol, chbit = _workpiece_tolerances(p, ctx)
    target, zero, knum = _workpiece_target(p)
    mvar = 100 if zero else (1000 if p["reversal"] else 0)
    call = WorkpieceCall(cycle=974, mvar=mvar, setval=p["setpoint"], ma=AXIS_MA[p["axis"]], knum=knum,
                         tnum=target.t if target else 0, sta1=p["start_angle"], **common, **tol)
    return LathePrep(task, p, call, replace(ctx, chbit=chbit), target=target, zero_offset=zero,
                     info={"inside": p.get("inside")})


def _two_point_call(task: str, p: dict[str, Any], ctx: LatheContext, common: dict[str, Any]) -> LathePrep:
    """CYCLE994: a diameter by two points (turning §5), _CHBIT[7] with use_ball_diameter."""
    tol, chbit = _workpiece_tolerances(p, ctx)
    target, zero, _knum = _workpiece_target(p)
    chbit[7] = int(p["use_ball_diameter"])
    zone = p["zone"] or {}
    mvar = 1 if p["inside"] and p["zone"] else 2
    call = WorkpieceCall(cycle=994, mvar=mvar, setval=p["setpoint"], ma=AXIS_MA[p["axis"]],
                         tnum=target.t if target else 0, sza=zone.get("Z", 0.0), szo=zone.get("X", 0.0),
                         **common, **tol)
    return LathePrep(task, p, call, replace(ctx, chbit=chbit), target=target, zero_offset=zero,
                     info={"inside": p.get("inside")})


@dataclass(frozen=True)
class LatheTaskRules:
    """What one lathe task takes (its own params into the normalised ones) and which cycle call it
    makes of them (turning.md §10.2): the table replaces every branch on the task's name."""

    params: Callable[[Mapping[str, Any], dict[str, Any]], None]
    call: Callable[[str, dict[str, Any], LatheContext, dict[str, Any]], LathePrep]


LATHE_TASK_RULES: dict[str, LatheTaskRules] = {
    "lathe.toolprobe.calibrate": LatheTaskRules(partial(_tool_params, calibrate=True), _toolprobe_call),
    "lathe.tool.measure": LatheTaskRules(_tool_params, _tool_call),
    "lathe.tool.auto": LatheTaskRules(partial(_tool_params, auto=True), partial(_tool_call, auto=True)),
    "lathe.probe.groove": LatheTaskRules(_groove_params, _groove_call),
    "lathe.probe.surface": LatheTaskRules(_surface_params, _surface_call),
    "lathe.point": LatheTaskRules(_point_params, _point_call),
    "lathe.two_point": LatheTaskRules(_two_point_params, _two_point_call),
}
assert tuple(LATHE_TASK_RULES) == LATHE_TASKS


# --- running and evaluating ------------------------------------------------------------------------

def lathe_program(prep: LathePrep, start: npt.ArrayLike) -> LatheProgram:
    """The point program (a generator for engine.plan.run_program); ``start`` = the NC reference
    (tool tip or ball centre) in ``prep.coords``, X radius."""
    call, ctx = prep.call, prep.ctx
    if isinstance(call, Cycle982):
        variant = decode_982(call.mvar, call.cycle)
        if variant.kind == "calibrate":
            return toolprobe_program(call, start, ctx)
        if ctx.tool is not None and ctx.tool.family in ("mill", "drill"):
            return mill_program(call, start, ctx)
        return turning_tool_program(call, start, ctx)
    if isinstance(call, Cycle973):
        return probe_calibration_program(call, start, ctx)
    if call.cycle == 974:
        return _checked_point(prep, call, start)
    return _checked_two_point(prep, call, start)


def _checked_point(prep: LathePrep, call: WorkpieceCall, start: npt.ArrayLike) -> LatheProgram:
    return (yield from point_program(call, start, prep.ctx, target=prep.target))


def _checked_two_point(prep: LathePrep, call: WorkpieceCall, start: npt.ArrayLike) -> LatheProgram:
    return (yield from two_point_program(call, start, prep.ctx, target=prep.target,
                                         inside=prep.info.get("inside")))


@dataclass(frozen=True)
class LatheEvaluation:
    """``values``: the turning §10.2 result keys known after the evaluation; ``result``: the cycle's
    result object; ``measurement``: for lathe.point/two_point (tool or measure only) the
    WorkpieceMeasurement the strategy decides on (then ``finish_lathe``)."""

    task: str
    values: dict[str, Any]
    ovr: tuple[float, ...] | None
    ovi: tuple[int, ...] | None
    result: object
    measurement: WorkpieceMeasurement | None = None

    @property
    def needs_decision(self) -> bool:
        return self.measurement is not None


def evaluate_lathe(prep: LathePrep, point: LathePoint, *, ev: float = 0.0, frame: Mapping[str, Any] | None = None
                   ) -> LatheEvaluation:
    """Evaluate a stored point. ``ev`` = the EV memory value of _EVNUM (tool measuring, 974, 994);
    ``frame`` = {"coarse", "fine"} of the target zero offset (lathe.point with a ZO target)."""
    call, ctx = prep.call, prep.ctx
    r: ToolProbeResult | ToolResult | ProbeCalibrationResult | WorkpieceResult
    if isinstance(call, Cycle982):
        variant = decode_982(call.mvar, call.cycle)
        if variant.kind == "calibrate":
            r = evaluate_toolprobe(call, point, ctx)
        elif ctx.tool is not None and ctx.tool.family in ("mill", "drill"):
            r = evaluate_mill(call, point, ctx, ev=ev)
        else:
            r = evaluate_turning_tool(call, point, ctx, ev=ev)
        return LatheEvaluation(prep.task, dict(r.values), r.ovr, r.ovi, r)
    if isinstance(call, Cycle973):
        r = evaluate_probe_calibration(call, point, ctx)
        return LatheEvaluation(prep.task, dict(r.values), r.ovr, r.ovi, r)
    if call.cycle == 974:
        m = evaluate_point(call, point, ctx, ev=ev, target=prep.target)
    else:
        m = evaluate_two_point(call, point, ctx, ev=ev, target=prep.target)
    values = {"actual": m.actual, "deviation": m.deviation, "setpoint": m.setpoint, "difference": m.difference,
              "unit": "diameter" if m.diameter else "radius"}
    if call.cycle == 994:
        values["diameter"] = m.actual
    if m.zero_offset:
        r = finish_workpiece(call, m, ctx, frame=frame)
        return LatheEvaluation(prep.task, {**values, **r.values}, r.ovr, r.ovi, r)
    return LatheEvaluation(prep.task, values, None, None, m, measurement=m)


def finish_lathe(prep: LathePrep, evaluation: LatheEvaluation, *, decision: str, amount: float = 0.0,
                 mean_value: float | None = None, warning: AlarmDef | None = None,
                 tool: LatheTool | Mapping[str, Any] | None = None) -> WorkpieceResult:
    """lathe.point / lathe.two_point after the strategy: compensation (radius), tool update, the
    turning §10.2 values (``actual``/``diameter``, ``deviation``, ``decision``, ``compensation``), _OVR/_OVI."""
    if evaluation.measurement is None or not isinstance(prep.call, WorkpieceCall):  # only 974/994 measure
        raise ValueError(f"{prep.task}: nothing to decide (already finished)")
    r = finish_workpiece(prep.call, evaluation.measurement, prep.ctx, decision=decision, amount=amount,
                         mean_value=mean_value, warning=warning, tool=tool, target=prep.target)
    values = dict(r.values)
    if prep.call.cycle == 994:
        values["diameter"] = evaluation.measurement.actual
    return replace(r, values=values)


def lathe_planned_path(prep: LathePrep, start: npt.ArrayLike) -> list[Step]:
    """The program driven with ideal latches, for the live preview (as engine.plan.planned_path):
    every ProbeStep switches at its ``expected`` travel (halfway when unknown); an alarm of the
    program (e.g. a start in the forbidden band) ends the list."""
    pos = np.asarray(start, dtype=float)

    def ideal(step: Step) -> Latch | None:
        nonlocal pos
        if isinstance(step, MoveStep):
            pos = np.asarray(step.target, dtype=float)
        elif isinstance(step, ProbeStep):
            travel = step.expected if step.expected is not None else step.distance / 2.0
            pos = pos + travel * np.asarray(step.direction, dtype=float)
            return Latch(triggered=True, rec=pos.copy())
        return None

    steps: list[Step] = []
    with contextlib.suppress(MeasuringError):
        run_program(lathe_program(prep, start), ideal, steps)
    return steps
