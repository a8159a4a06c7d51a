"""Geometric fits: circle, line, plane; line intersection (measuring-math §5.3, §6, §12.3, §2.9).

Pure numpy. Every failure raises ``MeasuringError`` with the manual's alarm number:
61316 "centre and radius cannot be determined" (CYCLE116), 61317 "check parameters CYCLE116"
(too few points), 61367 "points identical", 61368 "lines have no intersection" (CYCLE961),
61411 "frame calculation impossible" (collinear plane points, spec/jog-measuring.md §10).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from engine.types import MeasuringError

# Relative tolerance for degeneracy: a singular value below REL_EPS * (largest extent) counts as 0.
REL_EPS = 1e-10


def _as_points(points, dim: int, name: str) -> np.ndarray:
    arr = np.asarray(points, dtype=float)
    if arr.ndim != 2 or arr.shape[1] != dim:
        raise ValueError(f"{name} must have shape (n, {dim}), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite")
    return arr


def _extent(centred: np.ndarray) -> float:
    return float(np.max(np.linalg.norm(centred, axis=1))) if len(centred) else 0.0


# --- circle -------------------------------------------------------------------------------

@dataclass(frozen=True)
class CircleFit:
    center: np.ndarray   # (2,)
    radius: float
    residual: float      # RMS of the geometric residuals |p - center| - radius


def fit_circle(points_2d) -> CircleFit:
    """Circle through >= 3 points in the plane (measuring-math §6, CYCLE116).

    Objective: minimise sum_i (|p_i - u| - R)^2 (geometric least squares). 3 points: the exact
    circumcircle (§6 formula). >= 4 points: algebraic Kåsa start ``[2x 2y 1]·[ua ub c] = x²+y²``
    (§6 [I]), then Gauss-Newton on the geometric distances; both exact for points on a circle.
    Fewer than 3 points -> 61317; collinear or coincident points -> 61316.
    """
    pts = _as_points(points_2d, 2, "points_2d")
    if len(pts) < 3:
        raise MeasuringError(61317, f"circle needs 3 or more points, got {len(pts)}")
    mean = pts.mean(axis=0)
    q = pts - mean                      # centred for numerical conditioning
    scale = _extent(q)
    sv = np.linalg.svd(q, compute_uv=False)
    if scale == 0.0 or sv[-1] <= REL_EPS * scale:
        raise MeasuringError(61316, "centre and radius cannot be determined (points collinear)")
    if len(pts) == 3:
        # circumcircle, §6: d = 2·(Ax(By−Cy) + Bx(Cy−Ay) + Cx(Ay−By)) in centred coordinates
        (ax, ay), (bx, by), (cx, cy) = q
        d = 2.0 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
        if abs(d) <= REL_EPS * scale * scale:
            raise MeasuringError(61316, "centre and radius cannot be determined (points collinear)")
        a2, b2, c2 = ax * ax + ay * ay, bx * bx + by * by, cx * cx + cy * cy
        ux = (a2 * (by - cy) + b2 * (cy - ay) + c2 * (ay - by)) / d
        uy = (a2 * (cx - bx) + b2 * (ax - cx) + c2 * (bx - ax)) / d
        u = np.array([ux, uy])
    else:
        # Kåsa start (§6 [I])
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
    dist = np.linalg.norm(q - u, axis=1)
    radius = float(dist.mean())
    if not np.isfinite(radius) or radius > 1e6 * scale:
        raise MeasuringError(61316, "centre and radius cannot be determined")
    residual = float(np.sqrt(np.mean((dist - radius) ** 2)))
    return CircleFit(center=u + mean, radius=radius, residual=residual)


# --- line ---------------------------------------------------------------------------------

@dataclass(frozen=True)
class LineFit:
    point: np.ndarray       # (2,) a point on the line (centroid of the fitted points)
    direction: np.ndarray   # (2,) unit direction, oriented from the first towards the last point


def fit_line(points_2d) -> LineFit:
    """Straight line through >= 2 points (total least squares; measuring-math §5.3, §12.3).

    Objective: minimise the sum of squared perpendicular distances (principal axis of the
    centred points). Exact through 2 points. The direction is oriented P_first -> P_last, so
    for two points it is the unit vector of P1 -> P2. Fewer than 2 points or all points
    coincident -> 61367 ("points identical").
    """
    pts = _as_points(points_2d, 2, "points_2d")
    if len(pts) < 2:
        raise MeasuringError(61367, f"a line needs 2 or more points, got {len(pts)}")
    mean = pts.mean(axis=0)
    q = pts - mean
    span = float(np.linalg.norm(pts[-1] - pts[0]))
    scale = max(_extent(q), float(np.max(np.abs(pts))), 1.0)
    if _extent(q) <= REL_EPS * scale:
        raise MeasuringError(61367, "points identical: the line cannot be determined")
    if len(pts) == 2:
        direction = (pts[1] - pts[0]) / span
    else:
        _, _, vt = np.linalg.svd(q)
        direction = vt[0]
        if np.dot(direction, pts[-1] - pts[0]) < 0.0:
            direction = -direction
    return LineFit(point=mean, direction=direction / np.linalg.norm(direction))


def cross2(p, q) -> float:
    """cross(p, q) = p_a·q_o − p_o·q_a (measuring-math §12.3)."""
    return float(p[0] * q[1] - p[1] * q[0])


def intersect_lines(a: LineFit, b: LineFit) -> np.ndarray:
    """Intersection of two lines (measuring-math §12.3).

    K = A + t·d_a with t = cross(B − A, d_b)/cross(d_a, d_b). Parallel lines
    (|cross(d_a, d_b)| below 1e-12 for unit directions) -> 61368.
    """
    den = cross2(a.direction, b.direction)
    if abs(den) < 1e-12:
        raise MeasuringError(61368, "lines have no intersection (parallel)")
    t = cross2(b.point - a.point, b.direction) / den
    return a.point + t * a.direction


# --- plane --------------------------------------------------------------------------------

@dataclass(frozen=True)
class PlaneFit:
    point: np.ndarray    # (3,) centroid of the points
    normal: np.ndarray   # (3,) unit normal, oriented along (P2 − P1) × (P3 − P1)


def fit_plane(points_3d) -> PlaneFit:
    """Plane through >= 3 points in space (spec/jog-measuring.md §2.9).

    Objective: minimise the sum of squared distances to the plane (normal = smallest principal
    axis of the centred points); exact through 3 points, where n ∥ (P2 − P1) × (P3 − P1).
    Orientation: n·((P2 − P1) × (P3 − P1)) >= 0 for the first three points (callers orient it,
    e.g. to +infeed). Fewer than 3 points, or collinear/coincident points -> 61411.
    """
    pts = _as_points(points_3d, 3, "points_3d")
    if len(pts) < 3:
        raise MeasuringError(61411, f"a plane needs 3 or more points, got {len(pts)}")
    mean = pts.mean(axis=0)
    q = pts - mean
    scale = _extent(q)
    _, sv, vt = np.linalg.svd(q)
    if scale == 0.0 or sv[1] <= REL_EPS * scale:
        raise MeasuringError(61411, "frame calculation impossible: plane points are collinear")
    if len(pts) == 3:
        normal = np.cross(pts[1] - pts[0], pts[2] - pts[0])
    else:
        normal = vt[2]
        if np.dot(normal, np.cross(pts[1] - pts[0], pts[2] - pts[0])) < 0.0:
            normal = -normal
    return PlaneFit(point=mean, normal=normal / np.linalg.norm(normal))
