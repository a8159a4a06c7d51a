"""Rotary-axis kinematics from a calibration sphere (design.md §10.6; CYCLE996-like).

Pure numpy. SINUMERIK CYCLE996 "determines the exact position of the fulcrum and the exact path
of the spin axis" from a sphere measured at three or more positions of each rotary axis
(SINUMERIK 840D sl Measuring cycles, "Measure kinematics CYCLE996"); HEIDENHAIN KinematicsOpt
(cycles 451–453) does the same and refuses a result whose sphere radius deviates (contamination).
The geometry here:

- An axis is a line at the zero position of every rotary axis (point p, unit direction d); it
  turns x -> p + R(d, θ)(x − p) (the control's model; Lynch & Park, Modern Robotics §4.1).
- Per position the sphere is probed (measuring-math §13: ball centres on a sphere of radius
  R_sphere + ρ) and fitted with a free radius (``engine.fit.fit_sphere``): the centre of the
  latched AXIS positions A_c(θ) (no kinematic model in it), the radius R_fit; the sphere's
  diameter is 2·(R_fit − ρ) with ρ the probe's effective ball radius (measuring-math §5.3).
- Head axis (p relative to the tool reference point, probe vector v = ball centre − reference
  point at the zero position): A_c(θ) = S − p − R(θ)(v − p), a circle about the line S − p + s·d
  turning +θ. So: circle plane normal -> d (oriented by the turning sense), circle centre c ->
  p ≡ S − c (mod d), and S = A_c(0) + v (at θ = 0 the head is the identity, jog-measuring §6.3
  "basic position of the machine kinematics").
- Table axis: the sphere on the table turns −θ about d (DIN 66217): its centres S(θ) = A_c + v
  (head at zero) lie on a circle whose centre is on the line, whose normal is d.
- The line's reported ``point`` is the foot of the perpendicular from the nominal point (the
  along-axis position of a line is arbitrary; this makes measured − nominal the perpendicular
  offset of the axis).

Each fit states its objective and minimum point count; a failed fit raises ``MeasuringError``
(typed, as engine.fit): 61317 too few positions, 61471 positions that do not fix a circle,
61470 a sphere diameter outside the tolerance.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from engine import alarms
from engine.fit import fit_circle, fit_plane, fit_sphere
from engine.types import FloatArray, MeasuringError

MIN_POSITIONS = 3          # a circle in space needs 3 sphere centres
MIN_SPHERE_TOUCHES = 4     # a sphere with free radius needs 4 points not in one plane (engine.fit)
MIN_SPAN_DEG = 10.0        # below, the circle's centre is not fixed well enough to be worth writing
HEAD, TABLE = "head", "table"


def rotation_about(direction: npt.ArrayLike, deg: float) -> FloatArray:
    """Rodrigues: R = cosθ·I + sinθ·[d]× + (1 − cosθ)·d·dᵀ (right-handed about unit d)."""
    d = np.asarray(direction, dtype=float)
    d = d / np.linalg.norm(d)
    t = math.radians(float(deg))
    cross = np.array([[0.0, -d[2], d[1]], [d[2], 0.0, -d[0]], [-d[1], d[0], 0.0]])
    return math.cos(t) * np.eye(3) + math.sin(t) * cross + (1.0 - math.cos(t)) * np.outer(d, d)


@dataclass(frozen=True)
class SphereAtPosition:
    """One sphere measurement: the centre of the latched axis positions, the sphere's diameter."""

    angle: float              # deg, the measured axis' position
    axes_centre: FloatArray   # (3,) A_c: X/Y/Z axis position at which the ball centre is the sphere centre
    diameter: float           # 2·(R_fit − ρ)
    rms: float                # RMS of the sphere fit's residuals, mm
    n: int


def sphere_at_position(angle: float, latched_axes: npt.ArrayLike, effective_radius: float) -> SphereAtPosition:
    """Free-radius sphere through the latched X/Y/Z positions of one position (measuring-math §13.2).

    Objective: minimise Σ(|A_k − c| − R)² (engine.fit.fit_sphere); minimum 4 touches not in one
    plane. Probing radially, a uniform overtravel shortens R but leaves c."""
    fit = fit_sphere(latched_axes)
    return SphereAtPosition(angle=float(angle), axes_centre=np.asarray(fit.center, dtype=float),
                            diameter=2.0 * (float(fit.radius) - float(effective_radius)), rms=fit.rms, n=fit.n)


def check_sphere_diameter(spheres: Sequence[SphereAtPosition], nominal: float, tolerance: float) -> None:
    """KinematicsOpt's sphere check: |D_measured − D_nominal| > tolerance at any position -> 61470
    (a chip or coolant on the sphere or the ball, or the wrong diameter entered)."""
    for s in spheres:
        if abs(s.diameter - nominal) > tolerance:
            raise MeasuringError(alarms.KINEMATICS_SPHERE,
                                 f"sphere diameter {s.diameter:.4f} mm at {s.angle:g}° differs from the nominal "
                                 f"{nominal:.4f} mm by more than {tolerance:g} mm: the sphere or the probe ball "
                                 "may be dirty")


@dataclass(frozen=True)
class CircleInSpace:
    """Circle through points in space: ``center``, unit ``normal``, ``radius``; residuals per point
    (in-plane radial, out-of-plane), ``rms`` of their 3D distances to the circle."""

    center: FloatArray
    normal: FloatArray
    radius: float
    radial: FloatArray
    axial: FloatArray

    @property
    def rms(self) -> float:
        d = np.hypot(self.radial, self.axial)
        return float(np.sqrt(np.mean(d * d)))


def fit_circle_3d(points: npt.ArrayLike) -> CircleInSpace:
    """Circle through n ≥ 3 points in space.

    Objective (two stages, exact for points on a circle): the plane minimising Σ distance²
    (jog-measuring §2.9, engine.fit.fit_plane), then the circle in that plane minimising
    Σ(|q_i − u| − R)² (measuring-math §6, engine.fit.fit_circle). Fewer than 3 points -> 61317;
    collinear points -> 61471."""
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise ValueError(f"points must have shape (n, 3), got {pts.shape}")
    if len(pts) < MIN_POSITIONS:
        raise MeasuringError(alarms.CIRCLE_PARAMETERS, f"a rotary axis needs {MIN_POSITIONS} or more positions, "
                             f"got {len(pts)}")
    try:
        plane = fit_plane(pts)
        assert plane.axes is not None, "fit_plane always returns the in-plane axes"
        u, v = plane.axes
        local = np.column_stack([(pts - plane.point) @ u, (pts - plane.point) @ v])
        circle = fit_circle(local)
    except MeasuringError as exc:
        raise MeasuringError(alarms.KINEMATICS_AXIS, f"the sphere centres do not fix a circle: {exc}") from None
    centre = plane.point + circle.center[0] * u + circle.center[1] * v
    return CircleInSpace(center=centre, normal=np.asarray(plane.normal, dtype=float), radius=float(circle.radius),
                         radial=np.asarray(circle.residuals, dtype=float),
                         axial=np.asarray(plane.residuals, dtype=float))


@dataclass(frozen=True)
class AxisLine:
    """A fitted rotary axis: ``point`` (foot of the perpendicular from the nominal point),
    unit ``direction``; ``residual`` = RMS distance of the sphere centres to the fitted circle,
    ``angle_residual`` = RMS of the turned angles against the commanded ones (deg)."""

    point: FloatArray
    direction: FloatArray
    residual: float
    angle_residual: float
    radius: float
    n: int

    def to_api(self) -> dict[str, object]:
        return {"point": [float(x) for x in self.point], "direction": [float(x) for x in self.direction],
                "residual": float(self.residual), "angle_residual": float(self.angle_residual),
                "radius": float(self.radius), "positions": int(self.n)}


def _turn_sense(circle: CircleInSpace, points: FloatArray, angles: FloatArray) -> float:
    """+1 when the points turn right-handed about ``circle.normal`` as the angle grows, else −1."""
    rel = points - circle.center
    total = 0.0
    for i in range(len(points)):
        for j in range(i + 1, len(points)):
            # (r_i × r_j)·n = r²·sin(turn about n); the same sign as sin(θ_j − θ_i) when it turns +θ
            total += float(np.cross(rel[i], rel[j]) @ circle.normal) * math.sin(math.radians(angles[j] - angles[i]))
    return 1.0 if total >= 0.0 else -1.0


def _line_near(point: FloatArray, direction: FloatArray, nominal_point: FloatArray) -> FloatArray:
    """The point of the line (point, direction) nearest to ``nominal_point``."""
    return point + float((nominal_point - point) @ direction) * direction


def _angles_checked(angles: npt.ArrayLike, n: int) -> FloatArray:
    a = np.asarray(angles, dtype=float)
    if a.shape != (n,) or not np.all(np.isfinite(a)):
        raise ValueError(f"angles must be {n} finite numbers, got {angles!r}")
    if n < MIN_POSITIONS:
        raise MeasuringError(alarms.CIRCLE_PARAMETERS, f"a rotary axis needs {MIN_POSITIONS} or more positions, "
                             f"got {n}")
    if len(set(np.round(a, 9))) < MIN_POSITIONS:
        raise MeasuringError(alarms.KINEMATICS_AXIS, f"{MIN_POSITIONS} or more different positions are needed")
    if float(a.max() - a.min()) < MIN_SPAN_DEG:
        raise MeasuringError(alarms.KINEMATICS_AXIS, f"the positions span {float(a.max() - a.min()):g}°: spread "
                             f"them over at least {MIN_SPAN_DEG:g}°")
    return a


def fit_axis(kind: str, centres: npt.ArrayLike, angles: npt.ArrayLike, probe_vector: npt.ArrayLike,
             nominal: tuple[npt.ArrayLike, npt.ArrayLike], zero_centre: npt.ArrayLike | None = None) -> AxisLine:
    """One rotary axis from the sphere centres A_c(θ_i) (``centres``: X/Y/Z axis positions) at
    ``angles`` (deg). ``kind`` "head" or "table"; ``probe_vector`` v = ball centre − tool reference
    point at the zero position (skew − L·ẑ); ``nominal`` (point, direction) the control's data, for
    orienting d and choosing the reported point. Minimum 3 positions spread over ≥ 10°.

    ``zero_centre``: A_c measured with every rotary axis at 0, so S = zero_centre + v exactly; needed
    when another head axis was held off zero while this one turned (the circle's own zero position
    is then not the machine's; ``probe_vector`` stays the zero-position v)."""
    pts = np.asarray(centres, dtype=float)
    a = _angles_checked(angles, len(pts))
    v = np.asarray(probe_vector, dtype=float)
    nominal_point = np.asarray(nominal[0], dtype=float)
    traced = pts if kind == HEAD else pts + v                # the table: the sphere's own centres in MCS
    circle = fit_circle_3d(traced)
    sense = 1.0 if kind == HEAD else -1.0                   # head: +θ; table: the part turns −θ
    d = circle.normal * sense * _turn_sense(circle, traced, a)
    # the turned angles against the commanded ones (a wrong axis, a slipping clamp)
    rel = traced - circle.center
    ref = rel[0]
    turned = np.array([math.degrees(math.atan2(float(np.cross(ref, r) @ d), float(ref @ r))) for r in rel])
    commanded = sense * (a - a[0])
    wrapped = (turned - commanded + 180.0) % 360.0 - 180.0
    angle_residual = float(np.sqrt(np.mean((wrapped - wrapped.mean()) ** 2)))
    if kind == HEAD:
        # A_c(0): each centre turned back to the zero position about the fitted line, averaged
        at_zero = np.mean([circle.center + rotation_about(d, -t) @ r for t, r in zip(a, rel, strict=True)], axis=0)
        sphere = (at_zero if zero_centre is None else np.asarray(zero_centre, dtype=float)) + v
        point = sphere - circle.center                        # p ≡ S − c, S = A_c(0) + v
    else:
        point = circle.center
    return AxisLine(point=_line_near(point, d, nominal_point), direction=d, residual=circle.rms,
                    angle_residual=angle_residual, radius=circle.radius, n=len(pts))


def line_deviation(measured: AxisLine, nominal: tuple[npt.ArrayLike, npt.ArrayLike]) -> dict[str, object]:
    """Measured − nominal: ``point`` (mm, vector), ``offset`` its length (the distance of the
    nominal point from the measured line), ``direction`` (unit vector difference) and ``angle_urad``
    (the angle between the directions, µrad)."""
    p0 = np.asarray(nominal[0], dtype=float)
    d0 = np.asarray(nominal[1], dtype=float)
    d0 = d0 / np.linalg.norm(d0)
    dp = measured.point - p0
    cos = float(np.clip(measured.direction @ d0, -1.0, 1.0))
    angle = math.atan2(float(np.linalg.norm(np.cross(measured.direction, d0))), cos)
    return {"point": [float(x) for x in dp], "offset": float(np.linalg.norm(dp)),
            "direction": [float(x) for x in measured.direction - d0], "angle_urad": angle * 1e6}
