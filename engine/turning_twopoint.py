"""CYCLE994: 2-point measurement on a diameter with protection zone (turning.md §6).

Steps: coords "WCS" (X radius), the NC reference is the ball centre as the NC computes it; a
stored skew e is applied as in engine.turning_probe. The two points lie symmetrically about W
at ``s± = ±_SETVAL/2`` (X with DIAMON) or ``±_SETVAL`` (DIAMOF, Z, Y unless _CHBIT[19]) — first
the point on the positive side, then the negative one [L21572–L21575].

Motion (turning.md §6.3 [I]); measuring axis a (X or Y; the detour runs along Z [L21806–L21812]):
- outside (OD, the ball starts beyond s⁺): P1 −a from ``s⁺ + t(−a) + _FA``; back and up to
  ``+zone`` (if higher); Z to ``Z_det = +|_SZA|``; a to ``−zone``; Z back; P2 +a from
  ``s⁻ + t(+a) − _FA``. zone = _SZO (/2 with DIAMON on X; on Y with _CHBIT[19]); zone ≤ s⁺ + r ->
  61334. _MVAR=1 with an outside start -> 61307 (variant table [L21771–L21772], turning §12 Q10).
- inside (ID, the ball starts between s⁻ and s⁺): P1 +a, P2 −a; _MVAR=2 crosses at the
  measuring Z, _MVAR=1 via Z_det (out of the bore and back), _SZO unused.
- _MA=1 (Z): faces at ±_SETVAL; the outside crossing (and the _MVAR=1 inside one) runs via X to
  the zone on the probe's side.
The probe ends _FA in front of the negative point [L21852–L21854].

Evaluation (turning.md §6.4): ``s_i = c_i − t(d_i)`` with the trigger values (_CHBIT[7]=0) or
``t(d) = −d·_WP[k,0]/2`` (_CHBIT[7]=1, the ball diameter: ``s_i = c_i + d_i·_WP[k,0]/2``);
diameter ``s1 − s2`` (X with DIAMON; else the radius ``(s1 − s2)/2`` about W). A clamping
eccentricity in X cancels in s1 − s2 (both points at the same spindle angle).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.turning import (
    LatheContext,
    LatheMotion,
    LathePoint,
    LatheProbe,
    LatheProgram,
    LatheSteps,
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


def two_point_trigger(record: LatheProbe, k: str, ball_diameter: bool) -> float:
    """t(d) for CYCLE994: the calibrated value (_CHBIT[7]=0, 61341 if 0) or −d·_WP[k,0]/2
    (_CHBIT[7]=1: the ball diameter, pre-travel ignored [L21640–L21650, L26394–L26397])."""
    if not ball_diameter:
        return trigger_for(record, k)
    if record.effective_diameter <= 0.0:
        raise MeasuringError(alarms.NOT_CALIBRATED_IN_PLANE, "_CHBIT[7]=1 needs the ball diameter in _WP[k,0]")
    d = 1 if k[1] == "+" else -1
    return -d * record.effective_diameter / 2.0


def _zone(call: WorkpieceCall, axis: str, ctx: LatheContext, y_like_x: bool) -> float:
    """The ball-centre limit of _SZO on ``axis`` (its axis is X, or Y for _MA=3): /2 with DIAMON on
    X, on Y only with _CHBIT[19] [L21784–L21788]; the user includes the ball radius [L21577–L21580]."""
    return abs(to_radius(call.szo, axis, ctx.diamon, y_like_x))


def _starts_inside(call: WorkpieceCall, c0: float, half: float, expected_inside: bool | None) -> bool:
    """Whether the probe starts inside the diameter (ball centre ``c0`` on the measuring axis);
    61307 where it stands beyond the negative point or contradicts the task or _MVAR."""
    if c0 > half:
        inside = False
    elif -half < c0 < half:
        inside = True
    else:
        raise MeasuringError(alarms.WRONG_VARIANT, "CYCLE994: the probe must start opposite the positive "
                                                   "measuring point (turning.md §6.3)")
    if expected_inside is not None and bool(expected_inside) != inside:
        raise MeasuringError(alarms.WRONG_VARIANT, f"the probe starts {'inside' if inside else 'outside'} the "
                                                   "diameter, contradicting the task's `inside` (turning.md §6.3)")
    if call.mvar == 1 and not inside:
        raise MeasuringError(alarms.WRONG_VARIANT, "_MVAR=1 measures an inside diameter, but the probe starts "
                                                   "outside (turning.md §6.3)")
    return inside


@dataclass(frozen=True)
class _Route:
    """From P1 to the start of P2 (at ``q2`` on the measuring axis ``a``) around the part."""

    m: LatheMotion
    call: WorkpieceCall
    ctx: LatheContext
    a: str
    q2: float
    measuring_cross: float
    label: str

    def via_zone(self) -> LatheSteps:
        m, a, q2, cross, label = self.m, self.a, self.q2, self.measuring_cross, self.label
        if a == "Z":                                        # via X to the zone on the probe's side
            side = 1.0 if cross >= 0.0 else -1.0
            limit = _zone(self.call, "X", self.ctx, False)
            out = side * max(side * float(m.ball_pos()[0]), limit)
            yield from m.move_axis("X", out, f"{label} detour X", ball=True)
            yield from m.move_axis("Z", q2, f"{label}2 start of probing", ball=True)
            yield from m.move_axis("X", cross, f"{label}2 back to the measuring X", ball=True)
        else:
            yield from m.move_axis("Z", abs(float(self.call.sza)), f"{label} detour Z", ball=True)
            yield from m.move_axis(a, q2, f"{label}2 start of probing", ball=True)
            yield from m.move_axis("Z", cross, f"{label}2 back to the measuring Z", ball=True)

    def around_od(self, zone: float, clearance: float) -> LatheSteps:
        """An outside diameter: up to the protection zone ``zone`` (beyond the measuring point +
        ball radius ``clearance``), over in Z, down beyond the far side, back to the measuring Z."""
        m, a, label = self.m, self.a, self.label
        if not zone > clearance:
            raise MeasuringError(alarms.PROTECTION_ZONE, f"protection zone {zone:g} must exceed the measuring "
                                                         f"point + ball radius {clearance:g} (turning.md §6.3)")
        yield from m.move_axis(a, max(float(m.ball_pos()[index(a)]), zone), f"{label} detour: up to the zone",
                               ball=True)
        yield from m.move_axis("Z", abs(float(self.call.sza)), f"{label} detour Z", ball=True)
        yield from m.move_axis(a, -zone, f"{label} detour: down to the zone", ball=True)
        yield from m.move_axis("Z", self.measuring_cross, f"{label} detour: back to the measuring Z", ball=True)
        yield from m.move_axis(a, self.q2, f"{label}2 start of probing", ball=True)


def two_point_program(call: WorkpieceCall, start: npt.ArrayLike, ctx: LatheContext, label: str = "P",
                      target: ToolTarget | None = None, inside: bool | None = None) -> LatheProgram:
    """The point program of CYCLE994 (module docstring). Returns a LathePoint with the touches
    "P1" (positive side) and "P2" (negative side) and ``info["inside"]``. ``inside`` (the task's,
    turning §10.2): a start position that contradicts it -> 61307 before any motion."""
    expected_inside = inside
    if call.cycle != 994:
        raise ValueError("two_point_program runs CYCLE994")
    chk = check_workpiece(call, ctx, target)
    fa = check_fa(call.fa)
    feed = measuring_feed(call.vms, fa)
    p0 = np.asarray(start, float)
    m = LatheMotion(p0, ctx, "WCS", offset=chk.record.skew_vector())
    a = chk.axis
    j = index(a)
    half = to_radius(call.setval, a, ctx.diamon, chk.y_like_x)
    if not half > 0.0:
        raise ValueError(f"CYCLE994 needs _SETVAL > 0, got {call.setval!r}")
    ball0 = m.ball_pos()
    inside = _starts_inside(call, float(ball0[j]), half, expected_inside)
    d1 = 1 if inside else -1
    k1, k2 = key(a, d1), key(a, -d1)
    check_probe_direction(chk.probe.sl, k1)
    check_probe_direction(chk.probe.sl, k2)
    use_ball = ctx.bit(7)
    t1, t2 = two_point_trigger(chk.record, k1, use_ball), two_point_trigger(chk.record, k2, use_ball)
    q1 = half + t1 - d1 * fa
    q2 = -half + t2 + d1 * fa
    r = chk.probe.effective("radius")
    detour = "X" if a == "Z" else "Z"
    measuring_cross = float(ball0[index(detour)])
    info = {"axis": a, "inside": inside, "setpoint_radius": half, "keys": (k1, k2)}
    yield from m.move_axis(a, q1, f"{label}1 start of probing", ball=True)
    p1 = yield from m.touch(k1, 2.0 * fa, feed, call.nmsp, f"{label}1 {k1}", expected=fa, role=f"{label}1")
    route = _Route(m, call, ctx, a, q2, measuring_cross, label)
    if inside and call.mvar == 2:
        yield from m.move_axis(a, q2, f"{label}2 start of probing", ball=True)         # across at the measuring Z
    elif inside or a == "Z":
        yield from route.via_zone()
    else:                                                   # OD with the protection zone (figure steps 3–7)
        yield from route.around_od(_zone(call, a, ctx, chk.y_like_x), half + r)
    p2 = yield from m.touch(k2, 2.0 * fa, feed, call.nmsp, f"{label}2 {k2}", expected=fa, role=f"{label}2")
    return LathePoint(cycle=994, mvar=call.mvar, coords="WCS", start=p0.copy(), touches=(p1, p2), info=info)


def evaluate_two_point(call: WorkpieceCall, point: LathePoint, ctx: LatheContext, ev: float = 0.0,
                       target: ToolTarget | None = None) -> WorkpieceMeasurement:
    """s1, s2 and the diameter s1 − s2 (module docstring; turning.md §6.4), then
    engine.turning_workpiece.measurement (D = act − EV − SETVAL_eff). ``ev`` = _EV[n−1]."""
    chk = check_workpiece(call, ctx, target)
    e = chk.record.skew_vector()
    use_ball = ctx.bit(7)
    p1, p2 = point.touches
    s = []
    for t in (p1, p2):      # s_i = c_i − t(d_i), c = rec + e (turning.md §6.4 [L21728–L21769], turning §12 Q16)
        s.append(t.value + float(e[index(t.axis)]) - two_point_trigger(chk.record, t.key, use_ball))
    inside = bool(point.info.get("inside", p1.sign > 0))
    # diameter s1 − s2, passed as the radius (s1 − s2)/2 (shown doubled with DIAMON on X), turning §6.4
    return measurement(call, chk, ctx, 0.5 * (s[0] - s[1]), ev=ev, surfaces={"P1": s[0], "P2": s[1]},
                       start=point.start, inside=inside)
