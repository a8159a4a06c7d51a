"""Geometric fits: circle, line, plane, sphere; line intersection (measuring-math §5.3, measuring-math §6, measuring-math §12.3,
measuring-math §13, jog-measuring §2.9).

Pure numpy. Modelled on scikit-image ``measure/fit.py``: every fit states its objective and its
minimum number of points, and a failed fit is typed: it raises ``MeasuringError`` with the
catalogue's alarm — 61316 "centre and radius cannot be determined" (CYCLE116, also for spheres),
61317 "check parameters CYCLE116" (too few points for a circle/sphere), 61367 "points identical"
(line), 61368 "lines have no intersection" (CYCLE961), 61411 "frame calculation impossible"
(plane), 61413 "check setpoint of sphere diameter" (a fixed sphere radius ≤ 0).

Every fit accepts n ≥ its minimum number of points (design.md §9.8 ``params.points``) and returns
a frozen value object with the parameters and the quality of the fit:

- ``residuals``: signed per point, in the order given (circle/sphere: |p − c| − R, positive
  outside; line/plane: distance along the fitted normal);
- ``rms`` (``CircleFit.residual`` is the same number, kept by name), ``form_error`` = max − min
  residual: the peak-to-valley form deviation from the least-squares reference element
  (roundness LSCI, straightness LSLI, flatness LSPL, sphericity LSSP in ISO 12181/12780/12781/
  ISO 1101 terms; the minimum-zone value is never larger), ``n``, ``dof`` = n − parameters;
- ``covariance`` of ``param_names`` = σ²·(JᵀJ)⁻¹ with J the Jacobian of the residuals at the
  solution (first-order error propagation, exact for the linear cases): σ is the caller's a-priori
  probe repeatability ``sigma`` when given, else the a-posteriori σ̂ = sqrt(Σr²/dof); with
  dof = 0 and no ``sigma`` it is None. ``std`` gives the square roots by name.

Geometric least squares is used where it matters (circle, sphere: distances to the curve, not the
algebraic Kåsa residual); every fit is exact for points on the shape.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from engine import alarms, checks
from engine.types import FloatArray, MeasuringError

# Relative tolerance for degeneracy: a singular value below REL_EPS * (largest extent) counts as 0.
REL_EPS = 1e-10
_GN_ITERATIONS = 100
_ILL_CONDITIONED = 1e-6   # smallest/largest singular value of a sphere's Jacobian


def _as_points(points: npt.ArrayLike, dim: int, name: str) -> FloatArray:
    arr = np.asarray(points, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != dim:
        raise ValueError(f"{name} must have shape (n, {dim}), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite")
    return arr


def _extent(centred: FloatArray) -> float:
    return float(np.max(np.linalg.norm(centred, axis=1))) if len(centred) else 0.0


def _empty() -> FloatArray:
    return np.zeros(0)


def _quality(residuals: FloatArray, jac: FloatArray, sigma: float | None
             ) -> tuple[float, float, FloatArray | None]:
    """(form_error, σ used, covariance σ²(JᵀJ)⁻¹ or None) for residuals r and Jacobian J (n, p)."""
    r = np.asarray(residuals, dtype=float)
    form = float(r.max() - r.min()) if len(r) else 0.0
    dof = len(r) - jac.shape[1]
    if sigma is not None:
        s = float(sigma)
    elif dof > 0:
        s = float(np.sqrt(np.sum(r * r) / dof))
    else:
        return form, float("nan"), None
    jtj = jac.T @ jac
    try:
        cov = s * s * np.linalg.inv(jtj)
    except np.linalg.LinAlgError:
        return form, s, None
    return form, s, 0.5 * (cov + cov.T)


class _FitQuality:
    """Shared read-outs of the fit results (the fields live in each dataclass)."""

    residuals: FloatArray
    n: int
    covariance: FloatArray | None
    param_names: tuple[str, ...]

    @property
    def rms(self) -> float:
        """sqrt(mean r²) of the signed residuals (0 for a result built by hand)."""
        r = np.asarray(self.residuals, dtype=float)
        return float(np.sqrt(np.mean(r * r))) if len(r) else 0.0

    @property
    def dof(self) -> int:
        return int(self.n) - len(self.param_names)

    @property
    def sigma_hat(self) -> float:
        """A-posteriori σ̂ = sqrt(Σr²/dof); NaN when dof ≤ 0."""
        r = np.asarray(self.residuals, dtype=float)
        return float(np.sqrt(np.sum(r * r) / self.dof)) if self.dof > 0 else float("nan")

    @property
    def std(self) -> dict[str, float]:
        """Standard deviation of each parameter (NaN when the covariance is unknown)."""
        if self.covariance is None:
            return {name: float("nan") for name in self.param_names}
        d = np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))
        return {name: float(v) for name, v in zip(self.param_names, d, strict=True)}


# --- circle -------------------------------------------------------------------------------

@dataclass(frozen=True)
class CircleFit(_FitQuality):
    """Circle (a, o) = ``center``, ``radius``; ``residual`` = RMS of |p − center| − radius.

    ``covariance`` of (center_a, center_o, radius); ``residuals`` positive outside the circle.
    """

    center: FloatArray   # (2,)
    radius: float
    residual: float      # RMS of the geometric residuals |p - center| - radius
    residuals: FloatArray = field(default_factory=_empty)
    form_error: float = 0.0
    n: int = 0
    sigma: float = float("nan")
    covariance: FloatArray | None = None
    param_names: tuple[str, ...] = ("center_a", "center_o", "radius")


def fit_circle(points_2d: npt.ArrayLike, *, sigma: float | None = None) -> CircleFit:
    """Circle through n >= 3 points in the plane (measuring-math §6, CYCLE116).

    Objective: minimise sum_i (|p_i - u| - R)^2 (geometric least squares). Minimum 3 points.
    3 points: the exact circumcircle (measuring-math §6 formula). >= 4 points: algebraic Kåsa start
    ``[2x 2y 1]·[ua ub c] = x²+y²`` (measuring-math §6 [I]), then Gauss-Newton on the geometric distances;
    both exact for points on a circle. Fewer than 3 points -> 61317; collinear or coincident
    points -> 61316. ``sigma``: a-priori σ per point for the covariance (module docstring).
    """
    if sigma is not None:
        checks.real("sigma", sigma, minimum=0.0)
    pts = _as_points(points_2d, 2, "points_2d")
    if len(pts) < 3:
        raise MeasuringError(alarms.CIRCLE_PARAMETERS, f"circle needs 3 or more points, got {len(pts)}")
    mean = pts.mean(axis=0)
    q = pts - mean                      # centred for numerical conditioning
    scale = _extent(q)
    sv = np.linalg.svd(q, compute_uv=False)
    if scale == 0.0 or sv[-1] <= REL_EPS * scale:
        raise MeasuringError(alarms.CIRCLE_UNDETERMINED, "centre and radius cannot be determined (points collinear)")
    if len(pts) == 3:
        # circumcircle, measuring-math §6: d = 2·(Ax(By−Cy) + Bx(Cy−Ay) + Cx(Ay−By)) in centred coordinates
        (ax, ay), (bx, by), (cx, cy) = q
        d = 2.0 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
        if abs(d) <= REL_EPS * scale * scale:
            raise MeasuringError(alarms.CIRCLE_UNDETERMINED, "centre and radius cannot be determined (points collinear)")
        a2, b2, c2 = ax * ax + ay * ay, bx * bx + by * by, cx * cx + cy * cy
        ux = (a2 * (by - cy) + b2 * (cy - ay) + c2 * (ay - by)) / d
        uy = (a2 * (cx - bx) + b2 * (ax - cx) + c2 * (bx - ax)) / d
        u = np.array([ux, uy])
    else:
        # Kåsa start (measuring-math §6 [I])
        a_mat = np.column_stack([2.0 * q, np.ones(len(q))])
        sol, *_ = np.linalg.lstsq(a_mat, np.sum(q * q, axis=1), rcond=None)
        u = sol[:2]
        # Gauss-Newton on r_i = |q_i - u| - R (geometric fit)
        for _ in range(50):
            diff = q - u
            dist = np.linalg.norm(diff, axis=1)
            if np.any(dist == 0.0):
                break
            radius = dist.mean()
            jac = np.column_stack([-diff / dist[:, None], -np.ones(len(q))])
            res = dist - radius
            step, *_ = np.linalg.lstsq(jac, -res, rcond=None)
            u = u + step[:2]
            if np.linalg.norm(step[:2]) <= 1e-15 * max(scale, 1.0):
                break
    diff = q - u
    dist = np.linalg.norm(diff, axis=1)
    radius = float(dist.mean())
    if not np.isfinite(radius) or radius > 1e6 * scale or np.any(dist == 0.0):
        raise MeasuringError(alarms.CIRCLE_UNDETERMINED, "centre and radius cannot be determined")
    res = dist - radius
    residual = float(np.sqrt(np.mean(res ** 2)))
    jac = np.column_stack([-diff / dist[:, None], -np.ones(len(q))])
    form, s, cov = _quality(res, jac, sigma)
    return CircleFit(center=u + mean, radius=radius, residual=residual, residuals=res, form_error=form,
                     n=len(pts), sigma=s, covariance=cov)


# --- line ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class LineFit(_FitQuality):
    """Line through ``point`` along unit ``direction`` (plane coordinates a, o).

    ``normal`` = ``direction`` turned +90° (left of the direction); ``residuals`` are the signed
    distances along it. ``covariance`` of (angle [rad] of the direction, offset [mm] along the
    normal at ``point``); at a distance t from ``point`` along the line the position of the line
    has variance var(offset) + t²·var(angle) (``offset_std_at``).
    """

    point: FloatArray       # (2,) a point on the line (centroid of the fitted points)
    direction: FloatArray   # (2,) unit direction, oriented from the first towards the last point
    residuals: FloatArray = field(default_factory=_empty)
    form_error: float = 0.0
    n: int = 0
    sigma: float = float("nan")
    covariance: FloatArray | None = None
    param_names: tuple[str, ...] = ("angle", "offset")

    @property
    def normal(self) -> FloatArray:
        d = np.asarray(self.direction, dtype=float)
        return np.array([-d[1], d[0]])

    def offset_std_at(self, point_2d: npt.ArrayLike) -> float:
        """Std of the line's position (along ``normal``) at the foot of ``point_2d``."""
        if self.covariance is None:
            return float("nan")
        t = float((np.asarray(point_2d, dtype=float) - self.point) @ self.direction)
        c = self.covariance
        return float(np.sqrt(max(c[1, 1] + t * t * c[0, 0] + 2.0 * t * c[0, 1], 0.0)))


def fit_line(points_2d: npt.ArrayLike, *, sigma: float | None = None) -> LineFit:
    """Straight line through n >= 2 points (total least squares; measuring-math §5.3, measuring-math §12.3).

    Objective: minimise the sum of squared perpendicular distances (principal axis of the
    centred points). Minimum 2 points; exact through 2 points. The direction is oriented
    P_first -> P_last, so for two points it is the unit vector of P1 -> P2. Fewer than 2 points
    or all points coincident -> 61367 ("points identical"). ``sigma``: a-priori σ per point.
    """
    if sigma is not None:
        checks.real("sigma", sigma, minimum=0.0)
    pts = _as_points(points_2d, 2, "points_2d")
    if len(pts) < 2:
        raise MeasuringError(alarms.POINTS_IDENTICAL, f"a line needs 2 or more points, got {len(pts)}")
    mean = pts.mean(axis=0)
    q = pts - mean
    span = float(np.linalg.norm(pts[-1] - pts[0]))
    scale = max(_extent(q), float(np.max(np.abs(pts))), 1.0)
    if _extent(q) <= REL_EPS * scale:
        raise MeasuringError(alarms.POINTS_IDENTICAL, "points identical: the line cannot be determined")
    if len(pts) == 2:
        direction = (pts[1] - pts[0]) / span
    else:
        _, _, vt = np.linalg.svd(q)
        direction = vt[0]
        if np.dot(direction, pts[-1] - pts[0]) < 0.0:
            direction = -direction
    direction = direction / np.linalg.norm(direction)
    normal = np.array([-direction[1], direction[0]])
    res = q @ normal
    t = q @ direction
    # r_i = n(α)·p_i − c:  ∂r/∂α = −d·p_i = −t_i (centred), ∂r/∂c = −1
    jac = np.column_stack([-t, -np.ones(len(q))])
    form, s, cov = _quality(res, jac, sigma)
    return LineFit(point=mean, direction=direction, residuals=res, form_error=form, n=len(pts), sigma=s,
                   covariance=cov)


def cross2(p: npt.NDArray[np.floating[Any]] | Sequence[float], q: npt.NDArray[np.floating[Any]] | Sequence[float]
           ) -> float:
    """cross(p, q) = p_a·q_o − p_o·q_a (measuring-math §12.3)."""
    return float(p[0] * q[1] - p[1] * q[0])


def intersect_lines(a: LineFit, b: LineFit) -> FloatArray:
    """Intersection of two lines (measuring-math §12.3).

    K = A + t·d_a with t = cross(B − A, d_b)/cross(d_a, d_b). Parallel lines
    (|cross(d_a, d_b)| below 1e-12 for unit directions) -> 61368.
    """
    den = cross2(a.direction, b.direction)
    if abs(den) < 1e-12:
        raise MeasuringError(alarms.NO_INTERSECTION, "lines have no intersection (parallel)")
    t = cross2(b.point - a.point, b.direction) / den
    return a.point + t * a.direction


# --- plane --------------------------------------------------------------------------------

@dataclass(frozen=True)
class PlaneFit(_FitQuality):
    """Plane through ``point`` with unit ``normal``; ``residuals`` = signed distances along it.

    ``axes`` (2, 3): the in-plane principal directions u, v of the points. ``covariance`` of
    (offset [mm] along the normal at ``point``, tilt_u, tilt_v [rad]: the normal tipping towards
    u resp. v).
    """

    point: FloatArray    # (3,) centroid of the points
    normal: FloatArray   # (3,) unit normal, oriented along (P2 − P1) × (P3 − P1)
    residuals: FloatArray = field(default_factory=_empty)
    form_error: float = 0.0
    n: int = 0
    sigma: float = float("nan")
    covariance: FloatArray | None = None
    axes: FloatArray | None = None
    param_names: tuple[str, ...] = ("offset", "tilt_u", "tilt_v")


def fit_plane(points_3d: npt.ArrayLike, *, sigma: float | None = None) -> PlaneFit:
    """Plane through n >= 3 points in space (spec/jog-measuring.md §2.9).

    Objective: minimise the sum of squared distances to the plane (normal = smallest principal
    axis of the centred points). Minimum 3 points; exact through 3 points, where
    n ∥ (P2 − P1) × (P3 − P1). Orientation: n·((P2 − P1) × (P3 − P1)) >= 0 for the first three
    points (callers orient it, e.g. to +infeed). Fewer than 3 points, or collinear/coincident
    points -> 61411. ``sigma``: a-priori σ per point.
    """
    if sigma is not None:
        checks.real("sigma", sigma, minimum=0.0)
    pts = _as_points(points_3d, 3, "points_3d")
    if len(pts) < 3:
        raise MeasuringError(alarms.FRAME_IMPOSSIBLE, f"a plane needs 3 or more points, got {len(pts)}")
    mean = pts.mean(axis=0)
    q = pts - mean
    scale = _extent(q)
    _, sv, vt = np.linalg.svd(q)
    if scale == 0.0 or sv[1] <= REL_EPS * scale:
        raise MeasuringError(alarms.FRAME_IMPOSSIBLE, "frame calculation impossible: plane points are collinear")
    if len(pts) == 3:
        normal = np.cross(pts[1] - pts[0], pts[2] - pts[0])
    else:
        normal = vt[2]
        if np.dot(normal, np.cross(pts[1] - pts[0], pts[2] - pts[0])) < 0.0:
            normal = -normal
    normal = normal / np.linalg.norm(normal)
    u = vt[0] - (vt[0] @ normal) * normal
    u = u / np.linalg.norm(u)
    v = np.cross(normal, u)
    res = q @ normal
    # r_i = n·p_i − c with n → n + b·u + c·v:  ∂r/∂offset = −1, ∂r/∂b = u·q_i, ∂r/∂c = v·q_i
    jac = np.column_stack([-np.ones(len(q)), q @ u, q @ v])
    form, s, cov = _quality(res, jac, sigma)
    return PlaneFit(point=mean, normal=normal, residuals=res, form_error=form, n=len(pts), sigma=s,
                    covariance=cov, axes=np.vstack([u, v]))


# --- sphere -------------------------------------------------------------------------------

@dataclass(frozen=True)
class SphereFit(_FitQuality):
    """Sphere ``center`` (3,), ``radius``; ``residuals`` = |p − center| − radius (outside +).

    ``covariance`` of (center_x, center_y, center_z, radius), or of the centre only when the
    radius was given (``radius_fixed``).
    """

    center: FloatArray
    radius: float
    residuals: FloatArray = field(default_factory=_empty)
    form_error: float = 0.0
    n: int = 0
    sigma: float = float("nan")
    covariance: FloatArray | None = None
    radius_fixed: bool = False
    param_names: tuple[str, ...] = ("center_x", "center_y", "center_z", "radius")


_ResidualJac = Callable[[FloatArray], tuple[FloatArray, FloatArray]]   # x -> (residuals, Jacobian)


def _gauss_newton(residual_jac: _ResidualJac, x0: FloatArray, scale: float) -> FloatArray:
    """Gauss-Newton with step halving: a step is taken only when it lowers the cost; stops when
    no step does or the step is below 1e-13·scale."""
    x = np.asarray(x0, dtype=float).copy()
    r, jac = residual_jac(x)
    cost = float(r @ r)
    for _ in range(_GN_ITERATIONS):
        step, *_ = np.linalg.lstsq(jac, -r, rcond=None)
        lam = 1.0
        while lam >= 1e-6:
            trial = x + lam * step
            r_t, jac_t = residual_jac(trial)
            cost_t = float(r_t @ r_t)
            if cost_t <= cost:
                break
            lam *= 0.5
        else:
            break                                   # no descent left: x is the minimum
        x, r, jac, cost = trial, r_t, jac_t, cost_t
        if np.linalg.norm(lam * step) <= 1e-13 * max(scale, 1.0):
            break
    return x


def _sphere_points(points_3d: npt.ArrayLike, radius: float | None, has_center0: bool
                   ) -> tuple[FloatArray, FloatArray, float, bool]:
    """(points, points minus their mean, their extent, coplanar) of :func:`fit_sphere`, checked:
    a given radius > 0 (61413), enough points (61317), not collinear, not coplanar unless the radius
    and a start centre are given (61316)."""
    pts = _as_points(points_3d, 3, "points_3d")
    fixed = radius is not None
    if radius is not None and not (np.isfinite(radius) and radius > 0.0):
        raise MeasuringError(alarms.SPHERE_DIAMETER, f"sphere radius must be > 0, got {radius}")
    need = 3 if fixed else 4
    if len(pts) < need:
        raise MeasuringError(alarms.CIRCLE_PARAMETERS,
                             f"a sphere needs {need} or more points{' (radius given)' if fixed else ''}, got {len(pts)}")
    q = pts - pts.mean(axis=0)
    scale = _extent(q)
    sv = np.linalg.svd(q, compute_uv=False)
    if scale == 0.0 or sv[1] <= REL_EPS * scale:
        raise MeasuringError(alarms.CIRCLE_UNDETERMINED, "sphere cannot be determined: points collinear")
    coplanar = bool(sv[2] <= REL_EPS * scale)
    if coplanar and (not fixed or not has_center0):
        raise MeasuringError(alarms.CIRCLE_UNDETERMINED,
                             "sphere cannot be determined: points in one plane"
                             + (" (give center0 to choose the side)" if fixed else ""))
    return pts, q, scale, coplanar


def _free_sphere(q: FloatArray) -> _ResidualJac:
    """Residuals |p_i − c| − R and their Jacobian of the sphere x = (c, R) through the points ``q``."""

    def free(x: FloatArray) -> tuple[FloatArray, FloatArray]:
        diff = q - x[:3]
        dist = np.linalg.norm(diff, axis=1)
        dist = np.where(dist == 0.0, np.finfo(float).tiny, dist)
        return dist - x[3], np.column_stack([-diff / dist[:, None], -np.ones(len(q))])

    return free


def _sphere_of_radius(q: FloatArray, radius: float) -> _ResidualJac:
    """Residuals |p_i − c| − ``radius`` and their Jacobian of the centre x = c."""

    def centre_only(x: FloatArray) -> tuple[FloatArray, FloatArray]:
        diff = q - x
        dist = np.linalg.norm(diff, axis=1)
        dist = np.where(dist == 0.0, np.finfo(float).tiny, dist)
        return dist - radius, -diff / dist[:, None]

    return centre_only


def _algebraic_sphere(q: FloatArray) -> FloatArray:
    """(c, R) of ``[2x 2y 2z 1]·[c, R² − |c|²] = |p|²``: the geometric fit's start."""
    a_mat = np.column_stack([2.0 * q, np.ones(len(q))])
    sol, *_ = np.linalg.lstsq(a_mat, np.sum(q * q, axis=1), rcond=None)
    c_alg = sol[:3]
    r_alg = float(np.sqrt(max(sol[3] + c_alg @ c_alg, 0.0)))
    return np.concatenate([c_alg, [r_alg]])


def fit_sphere(points_3d: npt.ArrayLike, *, radius: float | None = None, center0: npt.ArrayLike | None = None,
               sigma: float | None = None) -> SphereFit:
    """Sphere through n points in space (measuring-math §13.2, CYCLE997).

    Objective: minimise sum_i (|p_i − c| − R)^2 (geometric least squares), exact for points on
    a sphere. Free radius: minimum 4 points not in one plane; start from the algebraic fit
    ``[2x 2y 2z 1]·[c, R² − |c|²] = |p|²``, then Gauss-Newton. Given ``radius`` (e.g. the ball-
    centre sphere R_n ± ρ of a known sphere diameter): minimum 3 points not on one line, only
    the centre is fitted; coplanar points leave two mirror solutions, so ``center0`` (an
    approximate centre, e.g. the setpoint Q) picks the side and starts the iteration — without
    it the free fit starts it (needs 4 non-coplanar points).

    CYCLE997 paraxial (5 ball centres: 4 on the equator, 1 on top) determines centre and radius.
    Failures: too few points -> 61317; coplanar (free radius) / collinear points, no ``center0``
    where one is needed, or no convergence -> 61316; ``radius`` <= 0 -> 61413.
    """
    if sigma is not None:
        checks.real("sigma", sigma, minimum=0.0)
    pts, q, scale, coplanar = _sphere_points(points_3d, radius, center0 is not None)
    fixed = radius is not None
    mean = pts.mean(axis=0)
    r_given = float("nan") if radius is None else float(radius)

    free, centre_only = _free_sphere(q), _sphere_of_radius(q, r_given)
    if not coplanar:
        x_free = _gauss_newton(free, _algebraic_sphere(q), scale)
    if fixed:
        start = (np.asarray(center0, dtype=float) - mean) if center0 is not None else x_free[:3]
        if start.shape != (3,) or not np.all(np.isfinite(start)):
            raise ValueError(f"center0 must be a finite (3,) point, got {center0!r}")
        c = _gauss_newton(centre_only, start, scale)
        r_fit = r_given
        res, jac = centre_only(c)
        names: tuple[str, ...] = ("center_x", "center_y", "center_z")
    else:
        c, r_fit = x_free[:3], float(x_free[3])
        res, jac = free(x_free)
        names = ("center_x", "center_y", "center_z", "radius")
    if not (np.all(np.isfinite(c)) and np.isfinite(r_fit)) or r_fit <= 0.0 or np.linalg.norm(c) > 1e6 * scale:
        raise MeasuringError(alarms.CIRCLE_UNDETERMINED, "sphere cannot be determined")
    sv_j = np.linalg.svd(jac, compute_uv=False)
    if sv_j[-1] <= _ILL_CONDITIONED * sv_j[0]:
        # e.g. a given radius equal to the points' circumradius: the centre lies in their plane
        # and its offset across it is fixed only to 4th order
        raise MeasuringError(alarms.CIRCLE_UNDETERMINED, "sphere cannot be determined from these points "
                             "(centre not fixed across their plane)")
    form, s, cov = _quality(res, jac, sigma)
    return SphereFit(center=c + mean, radius=r_fit, residuals=res, form_error=form, n=len(pts), sigma=s,
                     covariance=cov, radius_fixed=fixed, param_names=names)
