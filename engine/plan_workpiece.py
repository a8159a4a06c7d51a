"""Point programs of the workpiece tasks and the workpiece-probe calibration.

Edges, corners, orient plane, probe length (spec §2.5, §2.6, §2.9, §5.2): one touch from the
start. Holes/pockets/spigots (spec §2.7, §2.8; measuring-math §8.2): ±1st axis, mid-point,
±2nd axis; circles twice. Ring calibration (spec §5.3, measuring-math §7.3).
"""

from __future__ import annotations

from collections.abc import Generator

import numpy as np

from engine.compensation import effective_radius, make_touch, parallel_axis, trigger_key
from engine.evaluate import circle_from_touches, rect_from_touches
from engine.plan_base import Motion, PlanContext, RingCalibrationPoint, RingPass, spindle
from engine.planes import Plane
from engine.types import CirclePoint, EdgePoint, Latch, RectPoint, Step, Touch

Program = Generator[Step, Latch | None, object]


# --- directions ---------------------------------------------------------------------------

def sign_of(direction: str) -> float:
    return 1.0 if direction == "+" else -1.0


def corner_direction(kind: str, position: int, n: int, plane: Plane) -> np.ndarray:
    """Travel direction of corner point n (spec §2.6 [I] table, design.md §3).

    Positions 1..4 = front-left, front-right, back-right, back-left (counter-clockwise from the
    corner at min 1st/min 2nd axis). P1, P2 (edge ∥ 1st axis) are probed along the 2nd axis,
    P3, P4 along the 1st. Outside: toward the material; inside: toward the wall (= opposite).
    """
    at_min_first = position in (1, 4)
    at_min_second = position in (1, 2)
    if n <= 2:
        axis, toward_material = plane.second, (1.0 if at_min_second else -1.0)
    else:
        axis, toward_material = plane.first, (1.0 if at_min_first else -1.0)
    sign = toward_material if kind == "outside" else -toward_material
    return sign * plane.unit(axis)


def edge_direction(task: str, params: dict, n: int, plane: Plane) -> np.ndarray:
    """Travel direction of an edge-type point (spec §2.5, §2.6, §2.9, §5.2)."""
    if task in ("edge.set", "edge.align"):
        return sign_of(params["direction"]) * plane.unit(params["axis"])
    if task == "edge.distance":
        key = "direction" if n == 1 else "direction_p2"
        return sign_of(params[key]) * plane.unit(params["axis"])
    if task.startswith("corner."):
        return corner_direction(params["kind"], int(params["position"]), n, plane)
    return -plane.infeed_unit          # plane.align, probe.length: −infeed (spec §2.9, §5.2)


def plane_directions(plane: Plane, angle_deg: float) -> tuple[np.ndarray, np.ndarray]:
    """1st/2nd plane axis turned by the probing angle about the infeed axis (spec §2.3)."""
    c, s = np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))
    a, o = plane.unit(plane.first), plane.unit(plane.second)
    return c * a + s * o, -s * a + c * o


def ball_offset(ctx: PlanContext) -> np.ndarray:
    """True ball centre − NC reference: skew (§1.3), + r·p̂ when L1 refers to the tip (§5.2)."""
    off = np.asarray(ctx.skew_wcs, dtype=float).copy()
    if ctx.probe.length_to_tip:
        off = off + (ctx.probe.ball_diameter / 2.0) * ctx.plane.infeed_unit
    return off


def _key(d: np.ndarray) -> str:
    j, sign = parallel_axis(d)
    return trigger_key(j, sign)


# --- edge-type points -----------------------------------------------------------------------

def edge_program(d: np.ndarray, start: np.ndarray, ctx: PlanContext, label: str,
                 raw: bool = False) -> Program:
    """Probe from the start along d, return to the start (spec §2.4, §11 Q10: stroke 2·E_MESS_D_M).

    ``raw`` (probe.length): no skew, so ``touch.ball_centre`` = rec (+ r·p̂ with L1 to the tip).
    """
    m = Motion(start, ctx)
    latch = yield from m.probe(d, 2.0 * ctx.measuring_path, label, expected=ctx.measuring_path)
    yield from m.back(m.start)
    skew = np.zeros(3) if raw else ctx.skew_wcs
    return EdgePoint(make_touch(latch.rec, d, ctx.probe, ctx.plane, skew_wcs=skew,
                                latched_mcs=latch.latched_mcs))


# --- inner features: hole, rectangular pocket, ring gauge -------------------------------------

def _inner_chord(m: Motion, centre: np.ndarray, d: np.ndarray, reach: float | None,
                 label: str) -> Program:
    """One inner touch from the (ball) centre along d.

    ``reach`` = expected ball travel centre → switching (approx/2 − ρ). The stroke starts
    E_MESS_D_M before it but not beyond the centre and ends E_MESS_D_M after it (spec §11 Q10);
    without an approximate size: from the centre over 2·E_MESS_D_M (spec §2.3).
    """
    path = m.ctx.measuring_path
    if reach is None:
        pre, stroke, expected = 0.0, 2.0 * path, path
    else:
        reach = max(reach, 0.0)
        pre = max(0.0, reach - path)
        stroke, expected = reach - pre + path, reach - pre
    yield from m.to_ball(centre + pre * d, f"{label} approach")
    latch = yield from m.probe(d, stroke, label, expected=expected)
    return latch


def _pass(m: Motion, centre: np.ndarray, u1: np.ndarray, u2: np.ndarray, chord, sizes,
          label: str, point_of) -> Program:
    """+u1, −u1, to the found u1-centre, +u2, −u2 (measuring-math §8.2, '+ direction first').

    ``point_of(latch, d)``: the point whose chord mid-points give the centre — the compensated
    surface estimate (symmetric for any chord offset, even with per-direction pre-travel), or
    the raw rec for calibration (math §7.3). Returns the 4 latches and the found centre.
    """
    l1 = yield from chord(m, centre, u1, sizes[0], f"{label} +1st")
    l2 = yield from chord(m, centre, -u1, sizes[0], f"{label} -1st")
    s1, s2 = point_of(l1, u1), point_of(l2, -u1)
    mid = centre + float((0.5 * (s1 + s2) - centre) @ u1) * u1      # chord mid-point along u1
    l3 = yield from chord(m, mid, u2, sizes[1], f"{label} +2nd")
    l4 = yield from chord(m, mid, -u2, sizes[1], f"{label} -2nd")
    s3, s4 = point_of(l3, u2), point_of(l4, -u2)
    found = mid + float((0.5 * (s3 + s4) - mid) @ u2) * u2
    return (l1, l2, l3, l4), found


def _surface_of(ctx: PlanContext):
    def point_of(latch: Latch, d: np.ndarray) -> np.ndarray:
        return make_touch(latch.rec, d, ctx.probe, ctx.plane, skew_wcs=ctx.skew_wcs).surface
    return point_of


def _raw_rec(latch: Latch, d: np.ndarray) -> np.ndarray:
    return np.asarray(latch.rec, dtype=float)


# --- outer features: spigot, rectangular spigot -------------------------------------------------

def _outer_chord_factory(dz: float):
    def chord(m: Motion, centre: np.ndarray, d: np.ndarray, half: float, label: str) -> Program:
        """Spigot path (spec §2.8 [I]): out to half + ρ + safety at start height, down DZ, probe
        inward, back by the safety distance, up DZ. Stroke: safety + min(E_MESS_D_M, half + ρ)
        (ends at most at the centre, spec §11 Q10)."""
        ctx = m.ctx
        p = ctx.plane.infeed_unit
        rho = effective_radius(ctx.probe)
        safety = ctx.spigot_safety
        yield from m.to_ball(centre - (half + rho + safety) * d, f"{label} outward")
        yield from m.move(m.pos - dz * p, f"{label} down DZ")
        latch = yield from m.probe(d, safety + min(ctx.measuring_path, half + rho), label,
                                   expected=safety)
        yield from m.move(latch.rec - safety * d, f"{label} retract")
        yield from m.move(m.pos + dz * p, f"{label} up DZ")
        return latch
    return chord


# --- evaluation of the stored point -------------------------------------------------------------

def _touches(latches, dirs, ctx: PlanContext) -> tuple[Touch, ...]:
    return tuple(make_touch(lt.rec, d, ctx.probe, ctx.plane, skew_wcs=ctx.skew_wcs,
                            latched_mcs=lt.latched_mcs) for lt, d in zip(latches, dirs, strict=True))


def circle_point(touches: tuple[Touch, ...], ctx: PlanContext, inner: bool) -> CirclePoint:
    """Centre/diameter of the 2nd-pass touches (+u1, −u1, +u2, −u2) as the evaluation
    computes them (engine.evaluate.circle_from_touches, measuring-math §8.3)."""
    centre, diameter = circle_from_touches(touches, ctx.plane, "hole" if inner else "spigot", ctx.probe)
    return CirclePoint(center=centre, diameter=diameter, touches=touches)


def rect_point(touches: tuple[Touch, ...], ctx: PlanContext, inner: bool) -> RectPoint:
    """L, W, centre from ±1st, ±2nd touches (engine.evaluate.rect_from_touches, math §8.3)."""
    centre, length, width = rect_from_touches(touches, ctx.plane, "pocket" if inner else "spigot")
    return RectPoint(center=centre, length=length, width=width, touches=touches)


# --- programs -----------------------------------------------------------------------------------

def _circle_program(params: dict, start: np.ndarray, ctx: PlanContext, label: str, chord, half,
                    inner: bool) -> Program:
    """Pass 1 finds the centre, pass 2 from the found centre makes every travel line a
    diameter, so each touch hits the wall at normal incidence — where the calibrated
    per-direction trigger values hold — and both chords are diameters."""
    m = Motion(start, ctx, ball_offset=ball_offset(ctx))
    u1, u2 = plane_directions(ctx.plane, float(params.get("probe_angle", 0.0)))
    surf = _surface_of(ctx)
    _, found = yield from _pass(m, m.start + m.ball_offset, u1, u2, chord, (half, half),
                                f"{label} pass 1", surf)
    latches, _ = yield from _pass(m, found, u1, u2, chord, (half, half), f"{label} pass 2", surf)
    yield from m.back(m.start)
    return circle_point(_touches(latches, (u1, -u1, u2, -u2), ctx), ctx, inner)


def hole_program(params: dict, start: np.ndarray, ctx: PlanContext, label: str) -> Program:
    """Hole at measuring depth (spec §2.7.1), inner chords from the centre."""
    diameter = params.get("diameter")
    reach = None if not diameter else diameter / 2.0 - effective_radius(ctx.probe)
    return (yield from _circle_program(params, start, ctx, label, _inner_chord, reach, inner=True))


def spigot_program(params: dict, start: np.ndarray, ctx: PlanContext, label: str) -> Program:
    """Circular spigot from above (spec §2.8): outer path per direction (down DZ, probe inward)."""
    chord = _outer_chord_factory(float(params["infeed"]))
    return (yield from _circle_program(params, start, ctx, label, chord, params["diameter"] / 2.0,
                                       inner=False))


def rect_program(params: dict, start: np.ndarray, ctx: PlanContext, label: str, inner: bool) -> Program:
    """Rectangular pocket (at depth) / spigot (from above, DZ): ±1st, mid, ±2nd (spec §2.7.1, §2.8)."""
    m = Motion(start, ctx, ball_offset=ball_offset(ctx))
    a, o = plane_directions(ctx.plane, 0.0)
    length, width = params.get("length"), params.get("width")
    if inner:
        rho = effective_radius(ctx.probe)
        sizes = (None if not length else length / 2.0 - rho, None if not width else width / 2.0 - rho)
        chord = _inner_chord
    else:
        sizes, chord = (length / 2.0, width / 2.0), _outer_chord_factory(float(params["infeed"]))
    latches, _ = yield from _pass(m, m.start + m.ball_offset, a, o, chord, sizes, label, _surface_of(ctx))
    yield from m.back(m.start)
    return rect_point(_touches(latches, (a, -a, o, -o), ctx), ctx, inner)


def ring_program(params: dict, start: np.ndarray, ctx: PlanContext, label: str) -> Program:
    """Probe radius calibration in a ring of known D, unknown centre (spec §5.3, math §7.3).

    SPOS 0°, find the centre (±1st, mid, ±2nd, mid); pass 1 at SPOS 180°, pass 2 at SPOS 0°,
    both from the found centre; end at the pass-2 centre (ball on the ring centre at 0°).
    Raw recs only: positioning uses no skew and the nominal radius, never old trigger values.
    """
    m = Motion(start, ctx)                      # ball_offset 0: calibration must not use old data
    a, o = plane_directions(ctx.plane, 0.0)
    dirs = (a, -a, o, -o)
    reach = params["diameter"] / 2.0 - ctx.probe.ball_diameter / 2.0
    yield spindle(angle=0.0, label=f"{label} SPOS 0")

    def as_pass(angle: float, latches) -> RingPass:
        return RingPass(angle, {_key(d): np.asarray(lt.rec, float).copy() for d, lt in zip(dirs, latches, strict=True)},
                        {_key(d): lt.latched_mcs for d, lt in zip(dirs, latches, strict=True)})

    latches, centre = yield from _pass(m, m.start, a, o, _inner_chord, (reach, reach), f"{label} centre",
                                       _raw_rec)
    search = as_pass(0.0, latches)
    yield from m.move(centre, f"{label} to centre")
    passes = []
    for angle in (180.0, 0.0):
        yield spindle(angle=angle, label=f"{label} SPOS {angle:g}")
        latches, found = yield from _pass(m, centre, a, o, _inner_chord, (reach, reach),
                                          f"{label} SPOS {angle:g}", _raw_rec)
        passes.append(as_pass(angle, latches))
    yield from m.move(found, f"{label} to centre")
    return RingCalibrationPoint(diameter=float(params["diameter"]), search=search, passes=tuple(passes))
