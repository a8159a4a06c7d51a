"""Probing plans and evaluations of the measuring cycles that have no JOG counterpart
(measuring-math §10, measuring-math §13): CYCLE979 bore/shaft at an angle, CYCLE997 sphere, CYCLE119.

Pure numpy, like the rest of the engine. The programs follow the contract of
``engine.plan.point_program``: generators that yield steps, receive ``None`` after a move and a
``Latch`` after a probing move, and return the stored point; every probing uses
``engine.plan_base.Motion`` (skew-compensated positioning, measuring feed, ``E_MESS_D_M`` = the
cycle's ``_FA`` as the measuring path before and after the expected surface) and
``engine.compensation.make_touch`` (the probe record's trigger values), so that touches mean the
same as those of the JOG tasks.

- ``angle_circle_program``: CYCLE979 bore/shaft (measuring-math §10.1): 3 or 4 radial touches at
  ``_STA1 + (i−1)·_INCA`` around the setpoint centre, the probe moving on a circle (polyline)
  ``_FA`` from the nominal contour between them; the stored ``CirclePoint`` is evaluated by
  ``engine.evaluate.circle_from_touches`` (circle fit of the ball centres, R ± ρ: CYCLE116).
- ``angle_line_program``: CYCLE979 slot/web (measuring-math §10.2): one touch per point along ±û
  on the line through the setpoint centre at ``_STA1``, the web crossed over with ``_ID``; the
  points are evaluated by ``engine.evaluate.distance_along_line``.
- ``sphere_program`` / ``evaluate_sphere``: CYCLE997 one sphere (measuring-math §13.2), paraxial (±a at the
  nominal height, ±o through the found a-centre, −p on top of the found centre) or at an angle
  (radial touches on the horizontal section, CYCLE116 of their ball centres), with or without
  diameter determination (one more +a touch through the centre) and the repeat variant.
- ``cycle119``: the rigid frame that carries three setpoint points onto three measured ones
  (measuring-math §13.3, Kabsch) and its distortion ``_RES``; ``reframed`` writes it into a target frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.compensation import effective_radius, make_touch
from engine.evaluate import line_unit
from engine.fit import fit_circle
from engine.frames import Frame
from engine.params import MAX_CIRCLE_POINTS, MIN_CIRCLE_POINTS
from engine.plan_base import Motion, PlanContext
from engine.plan_workpiece import Program, ball_offset, circle_point
from engine.planes import Plane
from engine.types import CirclePoint, EdgePoint, FloatArray, MeasuringError, Touch

ARC_STEP_DEG = 10.0          # circular intermediate moves as chords of at most this angle


def _u(plane: Plane, theta_deg: float) -> FloatArray:
    t = math.radians(theta_deg)
    return math.cos(t) * plane.unit(plane.first) + math.sin(t) * plane.unit(plane.second)


def _arc(m: Motion, centre: FloatArray, radius: float, plane: Plane, theta0: float, theta1: float,
         feed: float | None, label: str) -> Program[None]:
    """Ball centre along the circle (centre, radius) in the plane from ``theta0`` to ``theta1``
    (counter-clockwise for theta1 > theta0, G3; else G2), as chords of <= ARC_STEP_DEG."""
    steps = max(1, int(math.ceil(abs(theta1 - theta0) / ARC_STEP_DEG)))
    for k in range(1, steps + 1):
        theta = theta0 + (theta1 - theta0) * k / steps
        target = centre + radius * _u(plane, theta) - m.ball_offset
        yield from m.move(target, f"{label} arc", feed=feed if feed else "auto")


# --- CYCLE979 bore / shaft at an angle (measuring-math §10.1) -------------------------------------

def angle_circle_program(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str
                         ) -> Program[CirclePoint]:
    """CYCLE979 bore (``inner``) or shaft: ``params`` = {"center": (a, o) setpoint centre in the
    plane, "diameter", "start_angle" (_STA1), "increment" (_INCA), "points" (the manual's 3 or 4; up to 36),
    "inner" (bool), "circle_feed" (_RF, mm/min; None = positioning feed)}. Measuring height =
    the start height; the probe ends ``_FA`` before the last point."""
    plane = ctx.plane
    m = Motion(start, ctx, ball_offset=ball_offset(ctx))
    inner = bool(params["inner"])
    n = int(params["points"])
    if not MIN_CIRCLE_POINTS <= n <= MAX_CIRCLE_POINTS:
        raise MeasuringError(alarms.WRONG_VARIANT, f"CYCLE979 measures {MIN_CIRCLE_POINTS}..{MAX_CIRCLE_POINTS} "
                             f"points (the manual: 3 or 4), not {n}")
    rho = effective_radius(ctx.probe)
    fa = ctx.measuring_path
    rn = float(params["diameter"]) / 2.0
    radius = rn - rho - fa if inner else rn + rho + fa        # ball centre circle, _FA from the contour
    if radius <= 0.0:
        raise MeasuringError(alarms.MEASURING_PATH, f"bore Ø{2 * rn:g} too small for the probe and _FA {fa:g}")
    here = m.start + m.ball_offset
    height = float(plane.to_aop(here)[2])
    ca, co = (float(v) for v in params["center"])
    centre = plane.to_xyz(np.array([ca, co, height]))
    sta1, inca = float(params["start_angle"]), float(params["increment"])
    if abs(sta1 + (n - 1) * inca) > 360.0 + 1e-9 or abs(sta1) > 360.0:
        raise MeasuringError(alarms.WRONG_VARIANT, "_STA1 and the increments must stay within ±360°")
    feed = params.get("circle_feed")
    touches: list[Touch] = []
    for i in range(n):
        theta = sta1 + i * inca
        u = _u(plane, theta)
        if i == 0:
            yield from m.to_ball(centre + radius * u, f"{label} P1 start")
        else:
            yield from _arc(m, centre, radius, plane, sta1 + (i - 1) * inca, theta, feed, f"{label} P{i + 1}")
        d = u if inner else -u
        latch = yield from m.probe(d, 2.0 * fa, f"{label} P{i + 1}", expected=fa)
        touches.append(make_touch(latch.rec, d, ctx.probe, plane, skew_wcs=ctx.skew_wcs, spindle_angle=ctx.spindle_angle, wcs2bcs=ctx.wcs2bcs,
                                  latched_mcs=latch.latched_mcs))
        yield from m.to_ball(centre + radius * u, f"{label} P{i + 1} retract")
    return circle_point(tuple(touches), ctx, inner)


# --- CYCLE979 slot / web at an angle (measuring-math §10.2) --------------------------------------

def angle_line_program(params: dict[str, Any], n: int, start: FloatArray, ctx: PlanContext, label: str
                       ) -> Program[EdgePoint]:
    """CYCLE979 slot (``inner``) or web, point ``n`` (1, 2) on the line through ``center`` (a, o)
    along û = (cos _STA1, sin _STA1) (manual §5.6.1, measuring-math §10.2). ``params`` =
    {"center", "width" (_SETVAL), "start_angle" (_STA1), "inner", "lift" (web: _ID > 0 above the
    measuring height to cross over)}. Measuring height = the start height.

    Slot: P1 travels +û, P2 −û; web: P1 from the +û side travelling −û, P2 from the −û side
    travelling +û, lifted by _ID to cross over (as CYCLE977's web: up, over, down). Each probing
    starts with the ball ``_FA`` from the nominal wall (P1', P2'); after P1 the probe goes back to
    P1', after P2 it stays at P2': the cycle ends ``_FA`` before the last point (manual §5.6.1)."""
    plane = ctx.plane
    m = Motion(start, ctx, ball_offset=ball_offset(ctx))
    inner = bool(params["inner"])
    rho, fa = effective_radius(ctx.probe), ctx.measuring_path
    half = float(params["width"]) / 2.0
    reach = half - rho - fa if inner else half + rho + fa       # centre -> P1'/P2' (ball centre)
    if reach <= 0.0:
        raise MeasuringError(alarms.MEASURING_PATH, f"slot {2 * half:g} too narrow for the probe and _FA {fa:g}")
    u = line_unit(plane, float(params["start_angle"]))            # the evaluation's û
    here = m.start + m.ball_offset
    height = float(plane.to_aop(here)[2])
    ca, co = (float(v) for v in params["center"])
    centre = plane.to_xyz(np.array([ca, co, height]))
    side = 1.0 if n == 1 else -1.0                              # P1 on the +û side, P2 on the −û side
    before = centre + side * reach * u
    d = side * u if inner else -side * u
    if n == 2 and not inner:
        lift = float(params["lift"]) * plane.infeed_unit
        yield from m.to_ball(here + lift, f"{label} lift")
        yield from m.to_ball(before + lift, f"{label} over the web")
    yield from m.to_ball(before, f"{label} start")
    latch = yield from m.probe(d, 2.0 * fa, label, expected=fa)
    yield from m.to_ball(before, f"{label} retract")
    return EdgePoint(make_touch(latch.rec, d, ctx.probe, plane, skew_wcs=ctx.skew_wcs, spindle_angle=ctx.spindle_angle,
                                wcs2bcs=ctx.wcs2bcs, latched_mcs=latch.latched_mcs))


# --- CYCLE997 sphere (measuring-math §13.2) -----------------------------------------------------

@dataclass(frozen=True)
class SpherePoint:
    """One measured sphere: the touches in probing order and what they give.

    ``kind`` "paraxial" (touches +a, −a, +o, −o, −p[, +a]) or "angle" (n radial, −p[, +a]);
    ``nominal_diameter`` = _SETVAL; ``determine`` = diameter determination (one more +a touch)."""

    kind: str
    nominal_diameter: float
    determine: bool
    touches: tuple[Touch, ...]
    center: FloatArray
    diameter: float
    n_radial: int = 4


def evaluate_sphere(point: SpherePoint, plane: Plane) -> tuple[FloatArray, float]:
    """(centre (3,) WCS, diameter) of a measured sphere (measuring-math §13.2).

    paraxial: ca = (s1 + s2)/2, co = (s3 + s4)/2 (surface points, exact by symmetry);
    angle: (ca, co) = CYCLE116 of the radial touches' ball centres; z_top = s5_p;
    R = R_n, or with diameter determination R = ca − s6_a; cp = z_top − R."""
    t = point.touches
    a_hat, o_hat = plane.unit(plane.first), plane.unit(plane.second)
    if point.kind == "paraxial":
        ca = float(0.5 * (t[0].surface + t[1].surface) @ a_hat)
        co = float(0.5 * (t[2].surface + t[3].surface) @ o_hat)
        k = 4
    else:
        k = point.n_radial
        centres = np.array([plane.to_aop(x.ball_centre)[:2] for x in t[:k]])
        ca, co = (float(v) for v in fit_circle(centres).center)
    top = t[k]
    z_top = float(plane.to_aop(top.surface)[2])
    radius = point.nominal_diameter / 2.0
    if point.determine:
        radius = ca - float(t[-1].surface @ a_hat)           # the last diameter touch
        if radius <= 0.0:
            raise MeasuringError(alarms.CIRCLE_UNDETERMINED, f"sphere: non-positive radius {radius:.6f}")
    cp = z_top - radius
    return plane.to_xyz(np.array([ca, co, cp])), 2.0 * radius


def sphere_program(params: dict[str, Any], start: FloatArray, ctx: PlanContext, label: str
                   ) -> Program[SpherePoint]:
    """CYCLE997, one sphere: ``params`` = {"center": (x, y, z) nominal centre Q in the WCS,
    "diameter" (_SETVAL), "angle" (bool), "start_angle", "increment", "points" (3/4),
    "determine" (diameter), "refine" (default True, see below), "repeat" (119: again from the found centre), "circle_feed" (_RF)}.

    The probe crosses over the sphere ``_FA`` above its nominal top (or at the start height when
    that is higher) and ends there above the found centre."""
    plane = ctx.plane
    m = Motion(start, ctx, ball_offset=ball_offset(ctx))
    rn = float(params["diameter"]) / 2.0
    if not rn > 0.0:
        raise MeasuringError(alarms.SPHERE_DIAMETER, f"sphere diameter {2 * rn:g}: _SETVAL must be > 0")
    reach = rn + effective_radius(ctx.probe) + ctx.measuring_path
    start_height = float(plane.to_aop(m.start + m.ball_offset)[2])
    q = np.asarray(params["center"], dtype=float)
    runs = 2 if params.get("repeat") else 1             # >= 1: the loop sets point
    for run in range(runs):
        qp = float(plane.to_aop(q)[2])
        moves = _SphereMoves(m, ctx, safe=max(start_height, qp + reach))
        tag = f"{label} run {run + 1}" if runs > 1 else label
        point = yield from _sphere_run(moves, params, q, rn, reach, tag)
        q = point.center
        ca, co, _cp = plane.to_aop(point.center)
        yield from moves.go(moves.at(ca, co, moves.safe), f"{tag} end")
    return point


class _SphereMoves:
    """The probe's moves around one sphere: across at the safe height, touches along a direction."""

    def __init__(self, m: Motion, ctx: PlanContext, *, safe: float) -> None:
        self.m, self.ctx, self.plane, self.safe = m, ctx, ctx.plane, safe

    def at(self, a: float, o: float, p: float) -> FloatArray:
        return self.plane.to_xyz(np.array([a, o, p]))

    def go(self, target: FloatArray, what: str) -> Program[None]:
        """Up to the safe height, across, down to ``target`` (ball centre).

        The crossing is at the safe height also when the probe already stands there (a start
        at or above the safe height): a diagonal from there down to an equator point can cut
        through the sphere (issue 24)."""
        m, plane, safe = self.m, self.plane, self.safe
        here = plane.to_aop(m.pos + m.ball_offset)
        ta, to, tp = plane.to_aop(target)
        if not (abs(here[0] - ta) < 1e-9 and abs(here[1] - to) < 1e-9):
            if here[2] < safe - 1e-9:
                yield from m.to_ball(self.at(here[0], here[1], safe), f"{what} up")
            yield from m.to_ball(self.at(ta, to, max(safe, float(here[2]))), f"{what} across")
        yield from m.to_ball(target, what)

    def touch(self, origin: FloatArray, d: FloatArray, what: str) -> Program[Touch]:
        m, ctx, fa = self.m, self.ctx, self.ctx.measuring_path
        yield from self.go(origin, f"{what} start")
        latch = yield from m.probe(d, 2.0 * fa, what, expected=fa)
        yield from m.to_ball(origin, f"{what} retract")
        return make_touch(latch.rec, d, ctx.probe, self.plane, skew_wcs=ctx.skew_wcs, spindle_angle=ctx.spindle_angle,
                          wcs2bcs=ctx.wcs2bcs, latched_mcs=latch.latched_mcs)


def _sphere_run(moves: _SphereMoves, params: dict[str, Any], q: FloatArray, rn: float, reach: float,
                tag: str) -> Program[SpherePoint]:
    """One run around the sphere nominally at ``q``: the equator touches, the top, the diameter."""
    plane = moves.plane
    qa, qo, qp = (float(v) for v in plane.to_aop(q))
    if params.get("angle"):
        touches, ca, co, k = yield from _sphere_equator_at_angle(moves, params, (qa, qo, qp), reach, tag)
        kind = "angle"
    else:
        touches, ca, co, k = yield from _sphere_equator_paraxial(moves, (qa, qo, qp), reach, tag)
        kind = "paraxial"
    top = yield from moves.touch(moves.at(ca, co, qp + reach), -plane.infeed_unit, f"{tag} P{k + 1} -{plane.infeed}")
    touches.append(top)
    if params.get("determine"):
        touches += yield from _sphere_diameter_touches(moves, params, top, (ca, co), rn, reach, tag, k + 2)
    point = SpherePoint(kind, 2.0 * rn, bool(params.get("determine")), tuple(touches), np.zeros(3), 0.0, k)
    centre, diameter = evaluate_sphere(point, plane)
    return SpherePoint(kind, 2.0 * rn, point.determine, point.touches, centre, diameter, k)


def _sphere_equator_at_angle(moves: _SphereMoves, params: dict[str, Any], q: tuple[float, float, float],
                             reach: float, tag: str) -> Program[tuple[list[Touch], float, float, int]]:
    """3 or 4 touches on the equator from ``start_angle`` by ``increment``, on arcs between them:
    (touches, the circle's centre a, o, the number of touches)."""
    plane = moves.plane
    n = int(params.get("points", 3))
    if n not in (3, 4):
        raise MeasuringError(alarms.WRONG_VARIANT, f"CYCLE997 at an angle measures 3 or 4 points, not {n}")
    sta1, inca = float(params.get("start_angle", 0.0)), float(params.get("increment", 120.0))
    centre = moves.at(*q)
    touches: list[Touch] = []
    for i in range(n):
        theta = sta1 + i * inca
        u = _u(plane, theta)
        if i:
            yield from _arc(moves.m, centre, reach, plane, theta - inca, theta, params.get("circle_feed"),
                            f"{tag} P{i + 1}")
        touches.append((yield from moves.touch(centre + reach * u, -u, f"{tag} P{i + 1}")))
    ca, co = (float(v) for v in fit_circle(np.array([plane.to_aop(t.ball_centre)[:2] for t in touches])).center)
    return touches, ca, co, n


def _sphere_equator_paraxial(moves: _SphereMoves, q: tuple[float, float, float], reach: float,
                             tag: str) -> Program[tuple[list[Touch], float, float, int]]:
    """Two touches along the abscissa, two along the ordinate through their middle: (touches,
    the centre a, o, 4)."""
    plane = moves.plane
    qa, qo, qp = q
    a_hat, o_hat = plane.unit(plane.first), plane.unit(plane.second)
    at, touch = moves.at, moves.touch
    touches = [(yield from touch(at(qa - reach, qo, qp), a_hat, f"{tag} P1 +{plane.first}")),
               (yield from touch(at(qa + reach, qo, qp), -a_hat, f"{tag} P2 -{plane.first}"))]
    ca = float(0.5 * (touches[0].surface + touches[1].surface) @ a_hat)
    touches.append((yield from touch(at(ca, qo - reach, qp), o_hat, f"{tag} P3 +{plane.second}")))
    touches.append((yield from touch(at(ca, qo + reach, qp), -o_hat, f"{tag} P4 -{plane.second}")))
    co = float(0.5 * (touches[2].surface + touches[3].surface) @ o_hat)
    return touches, ca, co, 4


def _sphere_diameter_touches(moves: _SphereMoves, params: dict[str, Any], top: Touch, centre: tuple[float, float],
                             rn: float, reach: float, tag: str, first: int) -> Program[list[Touch]]:
    """P6 through the centre as known so far (p = z_top − R); "refine" [I]: when the found R moves
    that height by more than 1e-6 mm, once more at the corrected height (the chord error
    (Δp)²/2(R+ρ) of the first touch then drops below 1e-10 mm). ``first``: the first one's number."""
    plane = moves.plane
    a_hat = plane.unit(plane.first)
    z_top = float(plane.to_aop(top.surface)[2])
    a_found, co = centre
    height = z_top - rn
    touches: list[Touch] = []
    for attempt in range(3 if params.get("refine", True) else 1):
        t6 = yield from moves.touch(moves.at(a_found - reach, co, height), a_hat, f"{tag} P{first + attempt} diameter")
        touches.append(t6)
        new_height = z_top - (a_found - float(t6.surface @ a_hat))
        if abs(new_height - height) <= 1e-6:
            break
        height = new_height
    return touches


# --- CYCLE119 (measuring-math §13.3) ----------------------------------------------------------------

@dataclass(frozen=True)
class FrameFit:
    """m ≈ R·s + t (both in the measuring WCS) and the distortion _RES = Σ|R·s_i + t − m_i|."""

    rotation: FloatArray
    translation: FloatArray
    residual: float


def cycle119(setpoints: npt.ArrayLike, actual: npt.ArrayLike) -> FrameFit:
    """The rigid frame carrying the setpoint triangle onto the measured one (Kabsch, measuring-math §13.3 [I]).
    Collinear or coincident points of either triangle -> 61411."""
    s = np.asarray(setpoints, dtype=float)
    m = np.asarray(actual, dtype=float)
    if s.shape != (3, 3) or m.shape != (3, 3):
        raise ValueError("CYCLE119 takes three setpoint and three measured points (3x3)")
    for name, tri in (("setpoint", s), ("measured", m)):
        area = 0.5 * float(np.linalg.norm(np.cross(tri[1] - tri[0], tri[2] - tri[0])))
        scale = max(float(np.max(np.linalg.norm(tri - tri.mean(axis=0), axis=1))), 1e-300)
        if area <= 1e-9 * scale * scale:
            raise MeasuringError(alarms.FRAME_IMPOSSIBLE, f"the {name} points lie on one line or coincide")
    s_bar, m_bar = s.mean(axis=0), m.mean(axis=0)
    h = (s - s_bar).T @ (m - m_bar)
    u, _sv, vt = np.linalg.svd(h)
    v = vt.T
    rotation = v @ np.diag([1.0, 1.0, float(np.sign(np.linalg.det(v @ u.T)) or 1.0)]) @ u.T
    translation = m_bar - rotation @ s_bar
    residual = float(np.sum(np.linalg.norm(s @ rotation.T + translation - m, axis=1)))
    return FrameFit(rotation, translation, residual)


def reframed(fit: FrameFit, *, target_frame: Frame, target_parent2bcs: Frame, meas2bcs: Frame) -> Frame:
    """The target frame after CYCLE119: its WCS reads the setpoints where the points were measured.

    New WCS -> BCS = meas2bcs ∘ (R, t); target = parent2bcs⁻¹ ∘ that (for the frame active while
    measuring: R_new = R_old·R, T_new = T_old + R_old·t). Always coarse (fine cleared, measuring-math §2.1);
    rotary-axis offsets kept."""
    new_wcs2bcs = meas2bcs.compose(Frame.from_matrix(fit.rotation, fit.translation))
    target = target_parent2bcs.inverse().compose(new_wcs2bcs)
    return Frame.from_matrix(target.rotation, target.translation, dict(target_frame.rotary))
