"""Point programs of tool-probe calibration and tool length/diameter (jog-measuring §7, measuring-math §14).

Coordinates: MCS, NC reference = tool tip (steps use coords="MCS"). Tool probe record
``ctx.tool_probe`` = _TP[n,0..4] keyed by travel direction (tool edge at switching, jog-measuring §7.2).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import numpy as np

from engine import alarms
from engine.plan_base import Motion, PlanContext, ToolPoint, ToolProbePoint, ToolTouch, spindle
from engine.plan_workpiece import Program
from engine.toolmeasure import probe_centre, spindle_speed_feeds
from engine.types import FloatArray, MeasuringError

if TYPE_CHECKING:
    from engine.types import HitLatch


def rotating_speed_feeds(radius: float, ctx: PlanContext) -> tuple[float, list[float]]:
    """Speed and stage feeds of a rotating-spindle measurement (engine.toolmeasure, measuring-math §14.2)
    with the GUD7 values of ``ctx``."""
    sf = spindle_speed_feeds(radius, max_surface_speed=ctx.max_surface_speed,
                             max_speed=ctx.max_spindle_speed, accuracy=ctx.min_accuracy,
                             min_feed=ctx.min_feed_rotating, max_feed=ctx.max_feed_rotating,
                             factor1=ctx.feed_factor1, factor2=ctx.feed_factor2)
    return sf.speed, list(sf.feeds)


def stationary_feeds(ctx: PlanContext) -> list[float]:
    """jog-measuring §11 Q20: coarse at E_MESS_F_FAK1·E_MESS_MT_FM (≤ E_MESS_F), fine at E_MESS_MT_FM."""
    return [min(ctx.position_feed, ctx.feed_factor1 * ctx.mt_feed), ctx.mt_feed]


def axis_allowed(code: int, axis: str, sign: float) -> bool:
    """E_MESS_MT_AX digit code (jog-measuring §8.3): units X, tens Y, hundreds Z; 1 −, 2 +, 3 both."""
    digit = (int(code) // 10 ** "XYZ".index(axis)) % 10
    return digit == 3 or (digit == 1 and sign < 0) or (digit == 2 and sign > 0)


def _with_height(point: FloatArray, p: FloatArray, height: float) -> FloatArray:
    return point - float(point @ p) * p + height * p


def _tp(ctx: PlanContext, key: str) -> float:
    if not ctx.tool_probe or key not in ctx.tool_probe:
        raise MeasuringError(alarms.NOT_CALIBRATED_IN_PLANE, f"Tool probe not calibrated ({key} missing): calibrate the tool probe")
    return float(ctx.tool_probe[key])


def _probe_centre(ctx: PlanContext, axis: str, fallback: float) -> float:
    """Probe centre on a plane axis (engine.toolmeasure.probe_centre), else ``fallback``."""
    return probe_centre(ctx.tool_probe or {}).get(axis, fallback)


def _touch(key: str, latch: HitLatch, feed: float) -> ToolTouch:
    return ToolTouch(key=key, rec=np.asarray(latch.rec, float).copy(), latched_mcs=latch.latched_mcs,
                     feed=float(feed))


def toolprobe_program(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str
                      ) -> Program[ToolProbePoint]:
    """Tool probe calibration (jog-measuring §7.2 [I], measuring-math §14.5 automatic order): −p; then +a, −a, +o,
    −o (+a, −a again) at E_MESS_MT_DZ below the found upper edge, each from the side (out,
    down, probe in, back, up); −p again at the found centre. Stationary spindle, E_MESS_MT_FM,
    path E_MESS_MT_D. Directions excluded by E_MESS_MT_AX are skipped."""
    plane = ctx.plane
    m = Motion(start, ctx, coords="MCS")
    p, path, feeds = plane.infeed_unit, ctx.mt_path, [ctx.mt_feed]
    down = f"{plane.infeed}-"
    touches: list[ToolTouch] = []
    first = yield from m.probe(-p, 2.0 * path, f"{label} {down}", expected=path, feeds=feeds)
    touches.append(_touch(down, first, feeds[0]))
    yield from m.back(m.start)
    if params.get("mode") == "length_diameter":
        if ctx.tool_radius <= 0.0:
            raise MeasuringError(alarms.TOOL_SIZE_ZERO, "Tool length or radius is 0 (calibration tool radius)")
        if ctx.mt_diameter_radius <= 0.0:
            raise MeasuringError(alarms.TOOL_PROBE_DIAMETER, "Tool probe diameter too small (E_MESS_MT_DR)")
        top, start_h = float(first.rec @ p), float(m.start @ p)
        low = top - ctx.mt_dz                           # tool lower edge DZ below the upper edge
        out_r = ctx.mt_diameter_radius / 2.0 + ctx.tool_radius   # expected tool-centre distance
        centre = m.start.copy()
        # ±1st, ±2nd through the found 1st-axis centre, then ±1st again through the found centre:
        # on a disc probe the first 1st-axis chord is off-centre; the repeat makes it a diameter
        # (normal incidence, as the hole's 2nd pass). The last touch of each key counts.
        for axis in (plane.first, plane.second, plane.first):
            u = plane.unit(axis)
            recs: dict[float, FloatArray] = {}
            for sign in (1.0, -1.0):                    # + direction first (measuring-math §14.5)
                if not axis_allowed(ctx.mt_axes, axis, sign):
                    continue
                d, key = sign * u, f"{axis}{'+' if sign > 0 else '-'}"
                yield from m.move(centre - (out_r + path) * d, f"{label} {key} outward")
                yield from m.move(_with_height(m.pos, p, low), f"{label} {key} down")
                latch = yield from m.probe(d, 2.0 * path, f"{label} {key}", expected=path, feeds=feeds)
                touches.append(_touch(key, latch, feeds[0]))
                recs[sign] = latch.rec
                yield from m.move(latch.rec - path * d, f"{label} {key} back")
                yield from m.move(_with_height(m.pos, p, start_h), f"{label} {key} up")
            if len(recs) == 2:
                centre = centre + float((0.5 * (recs[1.0] + recs[-1.0]) - centre) @ u) * u
        yield from m.move(centre, f"{label} to centre")
        yield from m.move(_with_height(centre, p, top + path), f"{label} approach")
        last = yield from m.probe(-p, 2.0 * path, f"{label} {down} centre", expected=path, feeds=feeds)
        touches.append(_touch(down, last, feeds[0]))
        yield from m.move(_with_height(m.pos, p, start_h), f"{label} up")
    yield from m.back(m.start)
    return ToolProbePoint(mode=params.get("mode", "length"), touches=tuple(touches),
                          tool_radius=float(ctx.tool_radius), tool_length=float(ctx.tool_length))


def tool_length_program(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str
                        ) -> Program[ToolPoint]:
    """Tool length (jog-measuring §7.3): stationary and centred if 2R ≤ E_MESS_MT_DL, else rotating with
    the tool offset R − V along +1st (jog-measuring §11 Q12); stationary: displaced by V. Two-stage −p probing
    from the start height (1st stage), fine stages from E_MESS_D_L above the first switch."""
    plane = ctx.plane
    m = Motion(start, ctx, coords="MCS")
    p, a = plane.infeed_unit, plane.unit(plane.first)
    o = plane.unit(plane.second)
    if ctx.mt_diameter_length <= 0.0:
        raise MeasuringError(alarms.TOOL_PROBE_DIAMETER, "Tool probe diameter too small (E_MESS_MT_DL)")
    top = _tp(ctx, f"{plane.infeed}-")
    radius, v = float(ctx.tool_radius), float(params.get("offset_v", 0.0))
    rotating = 2.0 * radius > ctx.mt_diameter_length
    lateral = radius - v if rotating else v
    start_h = float(m.start @ p)
    above = start_h - top
    if above < 0.0:
        raise MeasuringError(alarms.TOOL_TIP_POSITION, "Change tool tip position: the tool is below the probe's upper edge")
    centre = (_probe_centre(ctx, plane.first, float(m.start @ a)) * a
              + _probe_centre(ctx, plane.second, float(m.start @ o)) * o)
    yield from m.move(_with_height(centre + lateral * a, p, start_h), f"{label} over probe")
    if rotating:
        speed, feeds = rotating_speed_feeds(radius, ctx)
        first_path = ctx.mt_path
        yield spindle(speed=speed, label=f"{label} spindle on")
    else:
        speed, feeds, first_path = 0.0, stationary_feeds(ctx), ctx.path_length
    key = f"{plane.infeed}-"
    latch = yield from m.probe(-p, above + first_path, f"{label} {key}", expected=above, feeds=feeds,
                               fine_retract=ctx.path_length)
    if rotating:
        yield spindle(speed=0.0, label=f"{label} spindle stop")
    yield from m.back(_with_height(m.pos, p, start_h), f"{label} up")
    yield from m.back(m.start)
    return ToolPoint(kind="length", touch=_touch(key, latch, feeds[-1]), rotating=rotating,
                     speed=float(speed), feeds=tuple(float(f) for f in feeds), offset_v=v,
                     lateral_offset=float(lateral), tool_radius=radius, tool_length=float(ctx.tool_length))


def tool_diameter_program(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str
                          ) -> Program[ToolPoint]:
    """Tool radius (jog-measuring §7.3): rotating spindle, approach along E_MESS_MT_DIR on the 1st axis,
    tip E_MESS_MT_DZ below the probe's upper edge raised by V (jog-measuring §11 Q12), centred on the 2nd
    axis; 1st stage from at least E_MESS_MT_D before the expected switch, fine stages E_MESS_D_R."""
    plane = ctx.plane
    m = Motion(start, ctx, coords="MCS")
    p, a, o = plane.infeed_unit, plane.unit(plane.first), plane.unit(plane.second)
    radius, v = float(ctx.tool_radius), float(params.get("offset_v", 0.0))
    if radius <= 0.0:
        raise MeasuringError(alarms.TOOL_SIZE_ZERO, "Tool length or radius is 0 (enter the approximate radius)")
    if ctx.mt_diameter_radius <= 0.0:
        raise MeasuringError(alarms.TOOL_PROBE_DIAMETER, "Tool probe diameter too small (E_MESS_MT_DR)")
    if ctx.mt_dz <= 0.0:
        raise MeasuringError(alarms.TOOL_PROBE_DZ_ZERO, "Distance probe upper edge to measuring position is 0 (E_MESS_MT_DZ)")
    sign = -1.0 if ctx.mt_dir < 0 else 1.0
    key = f"{plane.first}{'+' if sign > 0 else '-'}"
    d = sign * a
    # travel −a touches the +a face at _TP[a-] (tool centre there + R); travel +a: _TP[a+] − R
    expected_a = _tp(ctx, key) - sign * radius
    height = _tp(ctx, f"{plane.infeed}-") - ctx.mt_dz + v
    start_h = float(m.start @ p)
    before = max(ctx.mt_path, sign * (expected_a - float(m.start @ a)))
    approach = ((expected_a - sign * before) * a
                + _probe_centre(ctx, plane.second, float(m.start @ o)) * o + start_h * p)
    yield from m.move(approach, f"{label} beside probe")
    yield from m.move(_with_height(approach, p, height), f"{label} down")
    speed, feeds = rotating_speed_feeds(radius, ctx)
    yield spindle(speed=speed, label=f"{label} spindle on")
    latch = yield from m.probe(d, before + ctx.mt_path, f"{label} {key}", expected=before, feeds=feeds,
                               fine_retract=ctx.path_radius)
    yield spindle(speed=0.0, label=f"{label} spindle stop")
    yield from m.back(_with_height(approach, p, height), f"{label} back")
    yield from m.back(approach, f"{label} up")
    yield from m.back(m.start)
    return ToolPoint(kind="radius", touch=_touch(key, latch, feeds[-1]), rotating=True,
                     speed=float(speed), feeds=tuple(float(f) for f in feeds), offset_v=v,
                     lateral_offset=0.0, tool_radius=radius, tool_length=float(ctx.tool_length))
