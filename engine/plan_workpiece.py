"""Point programs of the workpiece tasks and the workpiece-probe calibration.

Edges, corners, orient plane, probe length (jog-measuring §2.5, jog-measuring §2.6, jog-measuring §2.9, jog-measuring §5.2): one touch from the
start. Holes/pockets/spigots (jog-measuring §2.7, jog-measuring §2.8; measuring-math §8.2): ±1st axis, mid-point,
±2nd axis; circles twice. Ring calibration (jog-measuring §5.3, measuring-math §7.3).
"""

from __future__ import annotations

from collections.abc import Callable, Generator
from typing import TYPE_CHECKING, Any, TypeVar

import numpy as np

from engine.compensation import effective_radius, make_touch, parallel_axis, trigger_key
from engine.evaluate import circle_from_touches, rect_from_touches
from engine.plan_base import (
    BoreCalibrationPoint,
    Motion,
    PlanContext,
    RingCalibrationPoint,
    RingPass,
    spindle,
)
from engine.planes import Plane
from engine.types import CirclePoint, EdgePoint, FloatArray, Latch, RectPoint, Step, Touch

if TYPE_CHECKING:
    from engine.types import HitLatch

_R = TypeVar("_R")
Program = Generator[Step, Latch | None, _R]     # a probing program returning _R (a point, a latch)
# one chord: (motion, centre, direction, expected reach or half size (None: unknown), label)
Chord = Callable[[Motion, FloatArray, FloatArray, "float | None", str], Program["HitLatch"]]
PointOf = Callable[["HitLatch", FloatArray], FloatArray]   # the point a chord's latch gives
Latches4 = tuple["HitLatch", "HitLatch", "HitLatch", "HitLatch"]


# --- directions ---------------------------------------------------------------------------

def sign_of(direction: str) -> float:
    return 1.0 if direction == "+" else -1.0


def corner_direction(kind: str, position: int, n: int, plane: Plane) -> FloatArray:
    """Travel direction of corner point n (jog-measuring §2.6 [I] table, design.md §3).

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


def plane_directions(plane: Plane, angle_deg: float) -> tuple[FloatArray, FloatArray]:
    """1st/2nd plane axis turned by the probing angle about the infeed axis (jog-measuring §2.3)."""
    c, s = np.cos(np.radians(angle_deg)), np.sin(np.radians(angle_deg))
    a, o = plane.unit(plane.first), plane.unit(plane.second)
    return c * a + s * o, -s * a + c * o


def ball_offset(ctx: PlanContext) -> FloatArray:
    """True ball centre − NC reference: skew (measuring-math §1.3), + r·p̂ when L1 refers to the tip (measuring-math §5.2)."""
    off = np.asarray(ctx.skew_wcs, dtype=float).copy()
    if ctx.probe.length_to_tip:
        off = off + (ctx.probe.ball_diameter / 2.0) * ctx.plane.infeed_unit
    return off


def _key(d: FloatArray) -> str:
    axis = parallel_axis(d)
    if axis is None:
        raise ValueError(f"ring calibration directions are axis-parallel, got {d}")
    return trigger_key(*axis)


# --- edge-type points -----------------------------------------------------------------------

def edge_program(d: FloatArray, start: FloatArray, ctx: PlanContext, label: str,
                 raw: bool = False) -> Program[EdgePoint]:
    """Probe from the start along d, return to the start (jog-measuring §2.4, jog-measuring §11 Q10: stroke 2·E_MESS_D_M).

    ``raw`` (probe.length): no skew, so ``touch.ball_centre`` = rec (+ r·p̂ with L1 to the tip).
    """
    m = Motion(start, ctx)
    latch = yield from m.probe(d, 2.0 * ctx.measuring_path, label, expected=ctx.measuring_path)
    yield from m.back(m.start)
    skew = np.zeros(3) if raw else ctx.skew_wcs
    return EdgePoint(make_touch(latch.rec, d, ctx.probe, ctx.plane, skew_wcs=skew, spindle_angle=ctx.spindle_angle, wcs2bcs=ctx.wcs2bcs,
                                latched_mcs=latch.latched_mcs))


def surface_program(d: FloatArray, setpoint: float, start: FloatArray, ctx: PlanContext, label: str,
                    stay: bool) -> Program[EdgePoint]:
    """CYCLE976 ``_MVAR=0`` (manual §5.3.3, measuring-math §7.5): along the travel d (± one axis)
    to ``_FA`` in front of the surface at ``setpoint`` (ball surface, nominal radius), probe over
    2·_FA, then back: to that place (``stay``: _MA=3, "the ball _FA from the surface") or to the
    start (_MA=1/2). ``touch.ball_centre`` = c = rec + e (stored skew)."""
    m = Motion(start, ctx)
    j = int(np.argmax(np.abs(d)))
    before = m.start.copy()
    before[j] = setpoint - float(d[j]) * (ctx.probe.ball_diameter / 2.0 + ctx.measuring_path)
    yield from m.move(before, f"{label} approach")
    latch = yield from m.probe(d, 2.0 * ctx.measuring_path, label, expected=ctx.measuring_path)
    yield from m.back(before if stay else m.start)
    return EdgePoint(make_touch(latch.rec, d, ctx.probe, ctx.plane, skew_wcs=ctx.skew_wcs,
                                spindle_angle=ctx.spindle_angle, wcs2bcs=ctx.wcs2bcs,
                                latched_mcs=latch.latched_mcs))


# --- inner features: hole, rectangular pocket, ring gauge -------------------------------------

def _inner_chord(m: Motion, centre: FloatArray, d: FloatArray, reach: float | None,
                 label: str) -> Program[HitLatch]:
    """One inner touch from the (ball) centre along d.

    ``reach`` = expected ball travel centre → switching (approx/2 − ρ). The stroke starts
    E_MESS_D_M before it but not beyond the centre and ends E_MESS_D_M after it (jog-measuring §11 Q10);
    without an approximate size: from the centre over 2·E_MESS_D_M (jog-measuring §2.3).
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


def _pass(m: Motion, centre: FloatArray, u1: FloatArray, u2: FloatArray, chord: Chord,
          sizes: tuple[float | None, float | None], label: str, point_of: PointOf
          ) -> Program[tuple[Latches4, FloatArray]]:
    """+u1, −u1, to the found u1-centre, +u2, −u2 (measuring-math §8.2, '+ direction first').

    ``point_of(latch, d)``: the point whose chord mid-points give the centre — the compensated
    surface estimate (symmetric for any chord offset, even with per-direction pre-travel), or
    the raw rec for calibration (measuring-math §7.3). Returns the 4 latches and the found centre.
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


def _surface_of(ctx: PlanContext) -> PointOf:
    def point_of(latch: HitLatch, d: FloatArray) -> FloatArray:
        return make_touch(latch.rec, d, ctx.probe, ctx.plane, skew_wcs=ctx.skew_wcs, spindle_angle=ctx.spindle_angle, wcs2bcs=ctx.wcs2bcs).surface
    return point_of


def _raw_rec(latch: HitLatch, d: FloatArray) -> FloatArray:
    return np.asarray(latch.rec, dtype=float)


# --- outer features: spigot, rectangular spigot -------------------------------------------------

def _outer_chord_factory(dz: float) -> Chord:
    def chord(m: Motion, centre: FloatArray, d: FloatArray, size: float | None, label: str) -> Program[HitLatch]:
        """Spigot path (jog-measuring §2.8 [I]): out to half + ρ + safety at start height, down DZ, probe
        inward, back by the safety distance, up DZ. Stroke: safety + min(E_MESS_D_M, half + ρ)
        (ends at most at the centre, jog-measuring §11 Q10)."""
        ctx = m.ctx
        p = ctx.plane.infeed_unit
        rho = effective_radius(ctx.probe)
        safety = ctx.spigot_safety
        if size is None:
            raise ValueError("an outer chord needs the spigot's size")
        half = size
        yield from m.to_ball(centre - (half + rho + safety) * d, f"{label} outward")
        yield from m.move(m.pos - dz * p, f"{label} down DZ")
        latch = yield from m.probe(d, safety + min(ctx.measuring_path, half + rho), label,
                                   expected=safety)
        yield from m.move(latch.rec - safety * d, f"{label} retract")
        yield from m.move(m.pos + dz * p, f"{label} up DZ")
        return latch
    return chord


# --- evaluation of the stored point -------------------------------------------------------------

def _touches(latches: tuple[HitLatch, ...], dirs: tuple[FloatArray, ...], ctx: PlanContext) -> tuple[Touch, ...]:
    return tuple(make_touch(lt.rec, d, ctx.probe, ctx.plane, skew_wcs=ctx.skew_wcs, spindle_angle=ctx.spindle_angle, wcs2bcs=ctx.wcs2bcs,
                            latched_mcs=lt.latched_mcs) for lt, d in zip(latches, dirs, strict=True))


def circle_point(touches: tuple[Touch, ...], ctx: PlanContext, inner: bool) -> CirclePoint:
    """Centre/diameter of the 2nd-pass touches (+u1, −u1, +u2, −u2) as the evaluation
    computes them (engine.evaluate.circle_from_touches, measuring-math §8.3)."""
    centre, diameter = circle_from_touches(touches, ctx.plane, "hole" if inner else "spigot", ctx.probe)
    return CirclePoint(center=centre, diameter=diameter, touches=touches)


def rect_point(touches: tuple[Touch, ...], ctx: PlanContext, inner: bool) -> RectPoint:
    """L, W, centre from ±1st, ±2nd touches (engine.evaluate.rect_from_touches, measuring-math §8.3)."""
    centre, length, width = rect_from_touches(touches, ctx.plane, "pocket" if inner else "spigot")
    return RectPoint(center=centre, length=length, width=width, touches=touches)


# --- programs -----------------------------------------------------------------------------------

def _circle_program(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str, chord: Chord,
                    half: float | None, inner: bool) -> Program[CirclePoint]:
    """Pass 1 finds the centre, pass 2 from the found centre makes every travel line a
    diameter, so each touch hits the wall at normal incidence — where the calibrated
    per-direction trigger values hold — and both chords are diameters."""
    m = Motion(start, ctx, ball_offset=ball_offset(ctx))
    u1, u2 = plane_directions(ctx.plane, float(params.get("probe_angle", 0.0)))
    surf = _surface_of(ctx)
    _, found = yield from _pass(m, m.start + m.ball_offset, u1, u2, chord, (half, half),
                                f"{label} pass 1", surf)
    given = circle_directions(params, ctx.plane)
    latches: tuple[HitLatch, ...]
    if given is None:
        latches, _ = yield from _pass(m, found, u1, u2, chord, (half, half), f"{label} pass 2", surf)
        dirs: tuple[FloatArray, ...] = (u1, -u1, u2, -u2)
    else:           # N touches from the found centre, each along a diameter (design.md §10.2)
        dirs, hits = tuple(given), []
        for k, d in enumerate(dirs, start=1):
            hits.append((yield from chord(m, found, d, half, f"{label} touch {k}")))
        latches = tuple(hits)
    yield from m.back(m.start)
    return circle_point(_touches(latches, dirs, ctx), ctx, inner)


def circle_directions(params: dict[str, Any], plane: Plane) -> list[FloatArray] | None:
    """The travel directions of ``params.points`` / ``params.angles`` (engine.params.circle_touches):
    evenly spaced from the probing angle, or the given angles from the 1st plane axis; None: the
    manual's ±1st, ±2nd pass."""
    if "angles" in params:
        thetas = [float(a) for a in params["angles"]]
    elif "points" in params:
        n = int(params["points"])
        thetas = [float(params.get("probe_angle", 0.0)) + 360.0 * k / n for k in range(n)]
    else:
        return None
    return [plane_directions(plane, theta)[0] for theta in thetas]


def hole_program(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str) -> Program[CirclePoint]:
    """Hole at measuring depth (jog-measuring §2.7.1), inner chords from the centre."""
    diameter = params.get("diameter")
    reach = None if not diameter else diameter / 2.0 - effective_radius(ctx.probe)
    return (yield from _circle_program(params, start, ctx, label, _inner_chord, reach, inner=True))


def spigot_program(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str
                   ) -> Program[CirclePoint]:
    """Circular spigot from above (jog-measuring §2.8): outer path per direction (down DZ, probe inward)."""
    chord = _outer_chord_factory(float(params["infeed"]))
    return (yield from _circle_program(params, start, ctx, label, chord, params["diameter"] / 2.0,
                                       inner=False))


def rect_program(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str, inner: bool
                 ) -> Program[RectPoint]:
    """Rectangular pocket (at depth) / spigot (from above, DZ): ±1st, mid, ±2nd (jog-measuring §2.7.1, jog-measuring §2.8)."""
    m = Motion(start, ctx, ball_offset=ball_offset(ctx))
    a, o = plane_directions(ctx.plane, 0.0)
    length, width = params.get("length"), params.get("width")
    sizes: tuple[float | None, float | None]
    chord: Chord
    if inner:
        rho = effective_radius(ctx.probe)
        sizes = (None if not length else length / 2.0 - rho, None if not width else width / 2.0 - rho)
        chord = _inner_chord
    else:
        sizes, chord = (params["length"] / 2.0, params["width"] / 2.0), _outer_chord_factory(float(params["infeed"]))
    latches, _ = yield from _pass(m, m.start + m.ball_offset, a, o, chord, sizes, label, _surface_of(ctx))
    yield from m.back(m.start)
    return rect_point(_touches(latches, (a, -a, o, -o), ctx), ctx, inner)


def ring_program(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str
                 ) -> Program[RingCalibrationPoint]:
    """Probe radius calibration in a ring of known D, unknown centre (jog-measuring §5.3, measuring-math §7.3).

    SPOS 0°, find the centre (±1st, mid, ±2nd, mid); pass 1 at SPOS 180°, pass 2 at SPOS 0°,
    both from the found centre; end at the pass-2 centre (ball on the ring centre at 0°).
    Raw recs only: positioning uses no skew and the nominal radius, never old trigger values.

    ``params["directions"]`` = n ≠ 4 or ``params["chord_offset"]`` = h > 0 (both optional;
    engine.lobing map, engine.calibration first_harmonic="estimate"): after the same centre search
    each pass probes n directions 360°/n apart (from +1st, counter-clockwise) from the found
    centre — with h > 0 twice, along chords h to either side of it (oblique incidence); the passes
    key their recs "0", "30", ... (with h: "0/+", "0/-", ...) with the unit directions in
    RingPass.directions; the probe ends at the found centre. Default: the program above.
    """
    n_dirs = int(params.get("directions", 4) or 4)
    chord_offset = float(params.get("chord_offset", 0.0) or 0.0)
    if not chord_offset and ctx.ring_chords:     # chords halfway out (docs/noise-bound.md: h = (R − r)/2)
        chord_offset = 0.5 * (params["diameter"] / 2.0 - ctx.probe.ball_diameter / 2.0)
    if n_dirs != 4 or chord_offset:
        return (yield from _ring_program_n(params, start, ctx, label, n_dirs, chord_offset))
    m = Motion(start, ctx)                      # ball_offset 0: calibration must not use old data
    a, o = plane_directions(ctx.plane, 0.0)
    dirs = (a, -a, o, -o)
    reach = params["diameter"] / 2.0 - ctx.probe.ball_diameter / 2.0
    yield spindle(angle=0.0, label=f"{label} SPOS 0")

    def as_pass(angle: float, latches: Latches4) -> RingPass:
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


BORE_KEYS = ("+1", "-1", "+2", "-2")       # manual §5.3.1: + direction first, abscissa before ordinate


def bore_units(plane: Plane, angle: float, keys: tuple[str, ...]) -> tuple[FloatArray, ...]:
    """The travel directions of ``keys`` ("+1", "-2", ...): the plane axes turned by ``angle``
    (_STA1; at an angle the order _STA1, _STA1+180°, _STA1+90°, _STA1+270°, measuring-math §7.1)."""
    u1, u2 = plane_directions(plane, angle)
    return tuple((1.0 if k[0] == "+" else -1.0) * (u1 if k[1] == "1" else u2) for k in keys)


def bore_calibration_program(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str
                             ) -> Program[BoreCalibrationPoint]:
    """CYCLE976 in a bore of diameter ``params["diameter"]`` along ``params["keys"]`` turned by
    ``params["angle"]`` (manual §5.3.1/§5.3.2, measuring-math §7.2–7.4).

    Known centre (``params["known_centre"]``): the start is MP; each direction is probed from it
    and the probe returns to it. Unknown centre (4 directions): a pass at SPOS 180° and one at
    SPOS 0° (+u1, −u1, to the found u1-centre, +u2, −u2, raw recs); the probe ends at the centre
    of the 0° pass (the ball on the bore centre)."""
    diameter = float(params["diameter"])
    angle = float(params.get("angle", 0.0) or 0.0)
    keys = tuple(params.get("keys") or BORE_KEYS)
    units = bore_units(ctx.plane, angle, keys)
    reach = diameter / 2.0 - ctx.probe.ball_diameter / 2.0
    m = Motion(start, ctx)
    if params.get("known_centre", True):
        latches = []
        for key, d in zip(keys, units, strict=True):
            latches.append((yield from _inner_chord(m, m.start, d, reach, f"{label} {key}")))
        yield from m.back(m.start)
        return BoreCalibrationPoint(diameter, angle, keys, units, tuple(np.asarray(lt.rec, float).copy() for lt in latches),
                                    centre=m.start.copy())
    u1, u2 = units[0], units[2]
    centres = []
    for spos in (180.0, 0.0):
        yield spindle(angle=spos, label=f"{label} SPOS {spos:g}")
        latches4, found = yield from _pass(m, m.pos.copy(), u1, u2, _inner_chord, (reach, reach),
                                           f"{label} SPOS {spos:g}", _raw_rec)
        centres.append(found)
        yield from m.move(found, f"{label} to centre")
    recs = tuple(np.asarray(lt.rec, float).copy() for lt in latches4)
    return BoreCalibrationPoint(diameter, angle, BORE_KEYS, bore_units(ctx.plane, angle, BORE_KEYS), recs,
                                pass_centres=(centres[0], centres[1]))


def _ring_program_n(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str, n_dirs: int,
                    chord_offset: float = 0.0) -> Program[RingCalibrationPoint]:
    """n-direction ring calibration (ring_program, ``params["directions"]``, ``["chord_offset"]``)."""
    if n_dirs < 4:
        raise ValueError(f"a ring calibration needs 4 or more directions, got {n_dirs}")
    reach_max = params["diameter"] / 2.0 - ctx.probe.ball_diameter / 2.0
    if not 0.0 <= chord_offset < 0.9 * reach_max:
        raise ValueError(f"chord_offset must lie in [0, {0.9 * reach_max:g}) mm, got {chord_offset:g}")
    m = Motion(start, ctx)
    a, o = plane_directions(ctx.plane, 0.0)
    axis_dirs = (a, -a, o, -o)
    reach = params["diameter"] / 2.0 - ctx.probe.ball_diameter / 2.0
    yield spindle(angle=0.0, label=f"{label} SPOS 0")
    latches, centre = yield from _pass(m, m.start, a, o, _inner_chord, (reach, reach), f"{label} centre",
                                       _raw_rec)
    search = RingPass(0.0, {_key(d): np.asarray(lt.rec, float).copy() for d, lt in zip(axis_dirs, latches, strict=True)},
                      {_key(d): lt.latched_mcs for d, lt in zip(axis_dirs, latches, strict=True)})
    yield from m.move(centre, f"{label} to centre")
    steps = [360.0 * k / n_dirs for k in range(n_dirs)]
    passes = []
    for angle in (180.0, 0.0):
        yield spindle(angle=angle, label=f"{label} SPOS {angle:g}")
        recs: dict[str, FloatArray] = {}
        raw: dict[str, FloatArray | None] = {}
        dirs: dict[str, FloatArray] = {}
        for theta in steps:
            d, d_perp = plane_directions(ctx.plane, theta)
            for side in ((0.0,) if not chord_offset else (1.0, -1.0)):
                key = f"{theta:g}" if not chord_offset else f"{theta:g}/{'+' if side > 0 else '-'}"
                origin = centre + side * chord_offset * d_perp
                chord = float(np.sqrt(reach * reach - chord_offset * chord_offset))
                if side:
                    yield from m.move(origin, f"{label} chord {key}")
                latch = yield from _inner_chord(m, origin, d, chord, f"{label} SPOS {angle:g} {key}°")
                recs[key], raw[key], dirs[key] = np.asarray(latch.rec, dtype=float).copy(), latch.latched_mcs, d.copy()
                yield from m.move(origin, f"{label} back")
                if side:
                    yield from m.move(centre, f"{label} to centre")
        passes.append(RingPass(angle, recs, raw, dirs))
    return RingCalibrationPoint(diameter=float(params["diameter"]), search=search, passes=tuple(passes))
