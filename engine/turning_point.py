"""CYCLE974: 1-point measurement with ZO determination, tool offset, or spindle reversal
(turning.md §5).

Steps: coords "WCS" (the measuring WCS, X radius), the NC reference is the ball centre as the NC
computes it from L1/L2; a stored skew e is applied as in engine.turning_probe. Only the axis
of _MA moves [I]; with reversal the spindle (the workpiece) turns: SPOS _STA1, then _STA1+180°.

Evaluation (turning.md §5.4 [L20919–L21078], turning §5.5 [L21079–L21356], turning §5.6 [L21357–L21530]):
``s = c_switch − t(d)`` (c = rec + e, t = _WP trigger of the travel direction), with reversal
``s = (s₀ + s₁₈₀)/2`` — a clamping eccentricity e_X shifts s₀ by +e_X and s₁₈₀ by −e_X, the
mean removes it [S000]; ``act = 2·s`` on X with DIAMON. The decision for the tool offset is the
strategy's (engine.turning_workpiece.finish_workpiece); the ZO variant decides itself (_TSA only).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.turning import (
    LatheContext,
    LatheMotion,
    LathePoint,
    LatheProgram,
    check_fa,
    check_probe_direction,
    index,
    key,
    measuring_feed,
    to_radius,
)
from engine.turning_offsets import ToolTarget
from engine.turning_workpiece import (
    WorkpieceCall,
    WorkpieceMeasurement,
    check_workpiece,
    measurement,
    trigger_for,
)
from engine.types import MeasuringError


def point_program(call: WorkpieceCall, start: npt.ArrayLike, ctx: LatheContext, label: str = "P1",
                  target: ToolTarget | None = None) -> LatheProgram:
    """The point program of CYCLE974 (turning.md §5.3 [I]).

    d = sign(s_set − c0) on _MA (c0 = ball centre at the call), allowed for the SL (61315); the
    expected switch c = s_set + t(d); probing starts at c − d·_FA (or at c0 when c0 already lies
    between that point and the surface) and runs to c + d·_FA; back to the start of probing;
    _NMSP repeats. _MVAR=1000: SPOS _STA1 before, _STA1 + 180° before the second measurement.
    """
    if call.cycle != 974:
        raise ValueError("point_program runs CYCLE974")
    chk = check_workpiece(call, ctx, target)
    fa = check_fa(call.fa)
    feed = measuring_feed(call.vms, fa)
    p0 = np.asarray(start, float)
    m = LatheMotion(p0, ctx, "WCS", offset=chk.record.skew_vector())
    j = index(chk.axis)
    s_set = to_radius(call.setval, chk.axis, ctx.diamon, chk.y_like_x)
    c0 = float(m.ball_pos()[j])
    if abs(s_set - c0) < 1e-12:
        raise MeasuringError(alarms.TOOL_TIP_POSITION, "the probe starts at the setpoint: the direction is not "
                                                       "defined (position it opposite the surface)")
    d = 1 if s_set > c0 else -1
    k = key(chk.axis, d)
    check_probe_direction(chk.probe.sl, k)
    t = trigger_for(chk.record, k)
    c_exp = s_set + t
    q = c_exp - d * fa
    angles = (float(call.sta1) % 360.0, (float(call.sta1) + 180.0) % 360.0) if call.mvar == 1000 else (None,)
    if angles[0] is not None:                  # SPOS _STA1 with the probe at its start (turning.md §5.6)
        yield from m.spos(angles[0], f"{label} SPOS {angles[0]:g}")
    if d * (c0 - q) > 0.0:                                  # already between q and the surface
        distance = d * (c_exp + d * fa - c0)
        if distance <= fa:
            raise MeasuringError(alarms.TOOL_TIP_POSITION, "the probe starts too close to the surface "
                                                           "(less than _FA before the expected switch)")
        expected = d * (c_exp - c0)
    else:
        yield from m.move_axis(chk.axis, q, f"{label} start of probing", ball=True)
        distance, expected = 2.0 * fa, fa
    touches = []
    for i, angle in enumerate(angles):
        if angle is not None:
            yield from m.spos(angle, f"{label} SPOS {angle:g}")
        role = label if angle is None else (f"{label} {'0' if i == 0 else '180'}")
        touches.append((yield from m.touch(k, distance, feed, call.nmsp, f"{role} {k}", expected=expected,
                                           role=role)))
    return LathePoint(cycle=974, mvar=call.mvar, coords="WCS", start=p0.copy(), touches=tuple(touches),
                      info={"axis": chk.axis, "direction": k, "setpoint": s_set, "trigger": t})


def evaluate_point(call: WorkpieceCall, point: LathePoint, ctx: LatheContext, ev: float = 0.0,
                   target: ToolTarget | None = None) -> WorkpieceMeasurement:
    """s = rec + e − t(d) per touch, the mean over the two spindle positions with reversal
    (turning.md §5.4–turning §5.6); -> engine.turning_workpiece.measurement. ``ev`` = _EV[n−1] of _EVNUM."""
    chk = check_workpiece(call, ctx, target)
    e = chk.record.skew_vector()
    surfaces = {}
    for touch in point.touches:
        t = trigger_for(chk.record, touch.key)
        surfaces[touch.role] = touch.value + float(e[index(touch.axis)]) - t   # s = c − t(d), turning §5.4 [L20919]
    s = float(np.mean(list(surfaces.values())))        # reversal: (s0 + s180)/2, turning §5.6 [L21362–L21370]
    d = point.touches[0].sign
    return measurement(call, chk, ctx, s, ev=ev, surfaces=surfaces, start=point.start, direction=d)
