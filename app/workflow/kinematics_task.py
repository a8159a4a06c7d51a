"""Task ``kinematics.measure`` (design.md §10.6, CYCLE996-like): the rotary axes from a calibration sphere.

Params: ``sphere`` {``center`` (MCS, every rotary axis at 0), ``diameter``}, ``axis`` (a head axis
or the rotary table's), ``positions`` (3..36 angles, deg: one point P1..Pn each), ``mode``
``check`` (report only) or ``optimise`` (Calculate writes the measured line into the control's
kinematic data: the operator's confirmation; needs the ``settings`` level, audited, undoable),
``clearance`` (mm, default 5). One NC Start measures one position (engine.plan_kinematics);
Calculate fits the axis (engine.kinematics) after the sphere check (setting
``kinematics_sphere_tolerance``, default 0.02 mm, KinematicsOpt-like).

Result: ``{"axes": {axis: {"point", "direction", "residual", ...}}, "deviation": {axis: {...}},
"sphere_diameter", "spheres": [...], "nominal": {axis: ...}, "mode", "written"}``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from app.workflow import forms
from app.workflow.context import MeasuringContext
from engine import alarms
from engine import checks as engine_checks
from engine.checks import ParamError
from engine.compensation import effective_radius
from engine.kinematics import HEAD, TABLE, check_sphere_diameter, fit_axis, line_deviation, sphere_at_position
from engine.plan_kinematics import SphereProgram, sphere_position_program
from engine.planes import Plane
from engine.tasks import EngineTask, Family
from engine.types import MeasuringError

TASK = "kinematics.measure"
MODES = {"check": "check", "optimise": "optimise", "optimize": "optimise"}
MAX_POSITIONS = 36
DEFAULT_PARTNER_DEG = 30.0
ROTARY = ("A", "B", "C")


def _centre(value: Any) -> list[float]:
    if isinstance(value, dict):
        missing = [a for a in "XYZ" if a not in value]
        if missing:
            raise ParamError("sphere.center", f"sphere.center: X, Y and Z are needed, missing {', '.join(missing)}")
        value = [value[a] for a in "XYZ"]
    if not isinstance(value, list | tuple) or len(value) != 3:
        raise ParamError("sphere.center", "sphere.center: [x, y, z] in MCS (mm) is needed")
    return [engine_checks.param_real("sphere.center", v) for v in value]


def validate(params: dict, plane: Plane) -> dict:
    """The task's params, normalised; ParamError names the field."""
    sphere = params.get("sphere")
    if not isinstance(sphere, dict):
        raise ParamError("sphere", "sphere: {\"center\": [x, y, z], \"diameter\": mm} is needed")
    diameter = engine_checks.param_real("sphere.diameter", sphere.get("diameter"))
    if not 0.0 < diameter <= 500.0:
        raise ParamError("sphere.diameter", "sphere.diameter: must be > 0 and <= 500 mm")
    axis = params.get("axis")
    if axis not in ROTARY:
        raise ParamError("axis", f"axis: one of {', '.join(ROTARY)}, got {axis!r}")
    positions = params.get("positions")
    if not isinstance(positions, list) or not 3 <= len(positions) <= MAX_POSITIONS:
        raise ParamError("positions", f"positions: a list of 3..{MAX_POSITIONS} angles (deg) is needed")
    angles = [engine_checks.param_real("positions", v) for v in positions]
    if len({round(a, 6) for a in angles}) < 3:
        raise ParamError("positions", "positions: at least 3 different angles are needed")
    mode = params.get("mode", "check")
    if mode not in MODES:
        raise ParamError("mode", f"mode: \"check\" or \"optimise\", got {mode!r}")
    clearance = engine_checks.param_real("clearance", params.get("clearance", 5.0))
    if not 0.5 <= clearance <= 50.0:
        raise ParamError("clearance", "clearance: 0.5 .. 50 mm")
    out = {"sphere": {"center": _centre(sphere.get("center")), "diameter": diameter}, "axis": axis,
           "positions": angles, "mode": MODES[mode], "clearance": clearance}
    if "partner_angle" in params:
        partner = engine_checks.param_real("partner_angle", params["partner_angle"])
        if not -180.0 <= partner <= 180.0 or abs(partner) < 5.0:
            raise ParamError("partner_angle", "partner_angle: 5° .. 180° (either sign): the inner head axis "
                             "tilts the probe off the outer one")
        out["partner_angle"] = partner
    return out


def partner_of(params: dict, facts: dict) -> tuple[str, float] | None:
    """The inner head axis held at ``partner_angle`` (default 30°) while the outer one turns, when
    the outer one's line runs along the tool axis at the zero position (C of an A/C or B/C head:
    the ball would sit on it) or when ``partner_angle`` is given."""
    lines = facts.get("lines", {})
    head = sorted(a for a, line in lines.items() if line.get("unit", HEAD) == HEAD)
    axis = params["axis"]
    if len(head) != 2 or axis != head[1]:
        return None
    along_tool = abs(float(np.asarray(lines[axis]["direction"], dtype=float)[2])) > 0.9
    if "partner_angle" not in params and not along_tool:
        return None
    return head[0], float(params.get("partner_angle", DEFAULT_PARTNER_DEG))


def _machine_facts(ctx: MeasuringContext) -> dict:
    return ctx.extra.get("kinematics") or {"lines": {}, "rotary_axes": (), "limits": {}}


def _probe_vector(ctx: MeasuringContext) -> np.ndarray:
    """v = ball centre − tool reference point at the zero position: skew(φ) − L_ball·ẑ (the NC's
    probe length; with _CBIT[14] L refers to the tip, the centre is r above it, measuring-math §5.2)."""
    probe = ctx.probe
    length = float(ctx.tool_length)
    if probe is None:
        return np.array([0.0, 0.0, -length])
    if probe.length_to_tip:
        length -= probe.ball_diameter / 2.0
    phi = math.radians(ctx.spindle_angle)
    sx, sy = probe.skew
    return np.array([sx * math.cos(phi) - sy * math.sin(phi), sx * math.sin(phi) + sy * math.cos(phi), -length])


def _line(facts: dict, axis: str) -> tuple[np.ndarray, np.ndarray]:
    line = facts["lines"][axis]
    return np.asarray(line["point"], dtype=float), np.asarray(line["direction"], dtype=float)


def _swivel_z(params: dict, facts: dict, ctx: MeasuringContext, rho: float) -> float | None:
    """Ball height to turn the axes at: the probe length above the hub (2ρ' over the sphere), at
    most 1 mm below where the Z limit puts the ball; None without a Z limit."""
    z_limit = facts.get("limits", {}).get("Z")
    if z_limit is None:
        return None
    v = _probe_vector(ctx)
    rho_start = float(params["sphere"]["diameter"]) / 2.0 + rho + float(params["clearance"])
    wanted = float(params["sphere"]["center"][2]) + 2.0 * rho_start + float(np.linalg.norm(v))
    return min(wanted, float(z_limit[1]) + float(v[2]) - 1.0)


def _program(params: dict, n: int, start, ctx: MeasuringContext, label: str):
    facts = _machine_facts(ctx)
    axis = params["axis"]
    line = facts["lines"].get(axis)
    if line is None:
        raise MeasuringError(alarms.ROTARY_AXIS, f"{axis} has no kinematic data on this machine")
    kind = line.get("unit", HEAD)
    probe = ctx.probe
    rho = effective_radius(probe) if probe is not None else 0.0
    reference = n > len(params["positions"])
    prog = SphereProgram(
        axis=axis, kind=kind, angle=0.0 if reference else float(params["positions"][n - 1]),
        rotary_axes=tuple(facts["rotary_axes"]), partner=partner_of(params, facts), reference=reference,
        sphere=np.asarray(params["sphere"]["center"], dtype=float), sphere_diameter=float(params["sphere"]["diameter"]),
        ball_radius=rho, clearance=float(params["clearance"]),
        measuring_feed=float(ctx.settings.measuring_feed), position_feed=float(ctx.settings.position_feed),
        table_line=_line(facts, axis) if kind == TABLE else None, swivel_z=_swivel_z(params, facts, ctx, rho))
    return sphere_position_program(prog, np.asarray(start, dtype=float), label)


def finish_kinematics(session, ctx: MeasuringContext, points: list) -> tuple[dict, dict]:
    """Sphere check, axis fit, deviation from the control's data; ``optimise``: what to write."""
    params = session.params
    axis = params["axis"]
    facts = _machine_facts(ctx)
    probe = ctx.probe
    rho = effective_radius(probe) if probe is not None else 0.0
    measured = [sphere_at_position(p.angle, p.latched, rho) for p in points]
    nominal_d = float(params["sphere"]["diameter"])
    check_sphere_diameter(measured, nominal_d, float(ctx.settings.kinematics_sphere_tolerance))
    zero = [s for s, p in zip(measured, points, strict=True) if getattr(p, "reference", False)]
    spheres = [s for s, p in zip(measured, points, strict=True) if not getattr(p, "reference", False)]
    line = facts["lines"][axis]
    nominal = _line(facts, axis)
    kind = line.get("unit", HEAD)
    partner = partner_of(params, facts)
    fitted = fit_axis(kind, [s.axes_centre for s in spheres], [s.angle for s in spheres], _probe_vector(ctx),
                      nominal, zero_centre=zero[0].axes_centre if zero else None)
    deviation = line_deviation(fitted, nominal)
    result = {
        "axes": {axis: fitted.to_api()},
        "deviation": {axis: deviation},
        "nominal": {axis: {"point": [float(v) for v in nominal[0]], "direction": [float(v) for v in nominal[1]]}},
        "sphere_diameter": float(np.mean([s.diameter for s in measured])),
        "partner": None if partner is None else {partner[0]: partner[1]},
        "spheres": [{"angle": s.angle, "axes_center": [float(v) for v in s.axes_centre], "diameter": s.diameter,
                     "rms": s.rms, "touches": s.n} for s in spheres],
        "unit": kind, "mode": params["mode"], "written": False,
    }
    answer: dict = {"result": result, "activated": False, "setup_support": None,
                    "correction": {"target": "measure_only", "before": None, "after": None}}
    if params["mode"] != "optimise":
        return answer, {"offset": None}
    after = {"point": result["axes"][axis]["point"], "direction": result["axes"][axis]["direction"]}
    result["written"] = True
    answer["correction"] = {"target": "kinematics", "before": {axis: result["nominal"][axis]}, "after": {axis: after}}
    return answer, {"offset": None, "kinematics_update": {axis: after}}


def kinematics_form(variant: str, env: forms.FormEnv) -> list[forms.FieldSpec]:
    """The JOG screen's fields (templates/kinematics.html draws them itself)."""
    return []


def check_machine(params: dict, facts: dict) -> None:
    """The axis must carry kinematic data here and the positions lie within its limits (400)."""
    axis = params["axis"]
    if axis not in facts.get("lines", {}):
        known = ", ".join(sorted(facts.get("lines", {}))) or "none"
        raise ParamError("axis", f"axis: {axis} is no swivel-head or rotary-table axis of this machine "
                         f"(axes with kinematic data: {known})")
    lo, hi = facts.get("limits", {}).get(axis, (-math.inf, math.inf))
    outside = [a for a in params["positions"] if not lo <= a <= hi]
    if outside:
        raise ParamError("positions", f"positions: {', '.join(f'{a:g}' for a in outside)} outside the limits "
                         f"of {axis} [{lo:g}, {hi:g}]")
    partner = partner_of(params, facts)
    if partner is not None:
        p_lo, p_hi = facts.get("limits", {}).get(partner[0], (-math.inf, math.inf))
        if not p_lo <= partner[1] <= p_hi:
            raise ParamError("partner_angle", f"partner_angle: {partner[1]:g}° is outside the limits of "
                             f"{partner[0]} [{p_lo:g}, {p_hi:g}]")


def program(params: dict, n: int, start, ctx: MeasuringContext, label: str):
    """The probing program of position ``n`` (engine.plan_kinematics)."""
    return _program(params, n, start, ctx, label)


ENGINE_TASK = EngineTask(TASK, Family.SPIGOT, 3, validate, program)   # type: ignore[arg-type]  # reads the MeasuringContext
