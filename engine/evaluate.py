"""Evaluation of the stored points of every workpiece task (spec/jog-measuring.md §2.5-jog-measuring §2.9).

``evaluate(task: str, params: dict[str, Any], points: Sequence[StoredPoint], plane: Plane,
        probe: ProbeRecord)`` -> ``TaskResult``: ``values`` carries the
design.md §4 result keys (points as objects keyed by the plane's axis names, angles in deg),
``fix`` tells engine.correction what was measured, in the measuring WCS.

Conventions (the product's decisions; see the docstrings of the task functions):
- Surfaces: edge positions are the touch's surface coordinate (measuring-math §5.3, measuring-math §9.1).
- Straight edges probed for an intersection (corners): the line through the ball centres,
  shifted by ρ_dir = touch_radius (the touch's compensation) along its normal towards the material
  (measuring-math §5.3 [I], measuring-math §12.3); exact for inclined edges.
- Circles from 4 touches: the CYCLE977 chord rule in the probing directions' basis
  (measuring-math §8.3): centre from the mid-points of both chords, diameter from the second
  chord (which runs through the found centre). Exact for any chord offset of the first pair.
- Angles: right-hand rotation about the axis named in ``fix.angle_axis`` from the reference
  axis (measuring-math §0.1). Straight edges (align edge, corners) are lines without a
  direction: their angle is folded into (−90°, 90°]. Hole patterns use the directed line
  (2 holes P1→P2, 3 holes P0→P1, 4 holes P1→P2; jog-measuring §11 Q6) in (−180°, 180°].
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
import numpy.typing as npt

from engine import alarms, checks
from engine.compensation import trigger_radius
from engine.correction import alpha_beta_from_normal
from engine.fit import CircleFit, LineFit, fit_circle, fit_line, fit_plane, intersect_lines
from engine.planes import Plane, axis_index
from engine.types import (
    CirclePoint,
    EdgePoint,
    FeatureFix,
    FloatArray,
    MeasuringError,
    ProbeRecord,
    RectPoint,
    StoredPoint,
    TaskResult,
    Touch,
    probe_record,
)

_AXES = ("X", "Y", "Z")
_COINCIDENT_TOL = 1e-9   # mm: points closer than this are "identical" (alarm 61367)

# Which line the angle of a hole pattern measures (jog-measuring §11 Q6): indices into [P0, P1, P2, ...].
HOLE_ANGLE_LINE = {2: (1, 2), 3: (0, 1), 4: (1, 2)}


# --- small helpers ------------------------------------------------------------------------

def _ao(plane: Plane, xyz: npt.ArrayLike) -> FloatArray:
    """(a, o) plane coordinates of a WCS vector."""
    return plane.to_aop(xyz)[:2]


def _plane_point(plane: Plane, ao: FloatArray | Sequence[float]) -> dict[str, float]:
    """{first: a, second: o} (design.md §4: a point keyed by the plane's axis names)."""
    return {plane.first: float(ao[0]), plane.second: float(ao[1])}


def _point3(plane: Plane, xyz: npt.ArrayLike) -> dict[str, float]:
    aop = plane.to_aop(xyz)
    return {name: float(v) for name, v in zip(plane.axes, aop, strict=True)}


def _xyz(plane: Plane, ao: FloatArray | Sequence[float], p: float) -> FloatArray:
    return plane.to_xyz(np.array([ao[0], ao[1], p], dtype=float))


def _fold90(deg: float) -> float:
    """Angle of an undirected line in (−90°, 90°]."""
    while deg > 90.0:
        deg -= 180.0
    while deg <= -90.0:
        deg += 180.0
    return deg


def _angle_ao(vec_ao: FloatArray | Sequence[float]) -> float:
    """Angle of a plane vector from the 1st plane axis, right-hand about the infeed (jog-measuring §0.1)."""
    return float(np.degrees(np.arctan2(vec_ao[1], vec_ao[0])))


def _wants_angle(params: dict[str, Any], default: str) -> bool:
    value = params.get("angle_correction", default)
    return value not in (None, "", "none")


def _edge_points(task: str, points: Sequence[StoredPoint], n: int) -> list[Touch]:
    if len(points) != n:
        raise ValueError(f"{task} needs {n} stored points, got {len(points)}")
    touches = []
    for i, p in enumerate(points, start=1):
        if not isinstance(p, EdgePoint):
            raise ValueError(f"{task}: P{i} must be an EdgePoint, got {type(p).__name__}")
        touches.append(p.touch)
    return touches


def _measuring_axis(params: dict[str, Any], touch: Touch) -> str:
    axis = params.get("axis")
    if axis:
        axis_index(axis)
        return str(axis)
    return _AXES[int(np.argmax(np.abs(touch.direction)))]


def _touch_values(plane: Plane, touches: Sequence[Touch]) -> list[dict[str, float]]:
    return [_point3(plane, t.surface) for t in touches]


# --- circles and rectangles from their 4 touches -------------------------------------------

def touch_radius(touch: Touch, probe: ProbeRecord | None, plane: Plane) -> float:
    """ρ of the touch's direction (measuring-math §5.3): the record's axis-parallel trigger value
    |t|, or with a lobing map (engine.lobing) the ρ(θ) make_touch applied, (s − c)·d̂."""
    probe = probe_record(probe, "the touch radius")
    if probe.lobing is None:
        return trigger_radius(probe, touch.direction, plane)
    return float((np.asarray(touch.surface, float) - np.asarray(touch.ball_centre, float)) @ touch.direction)


def circle_from_touches(touches: Sequence[Touch], plane: Plane, kind: str,
                        probe: ProbeRecord | None = None) -> tuple[FloatArray, float]:
    centre, diameter, _fit = circle_fit_of_touches(touches, plane, kind, probe)
    return centre, diameter


def _opposite(d: FloatArray, u: FloatArray) -> bool:
    """``np.allclose(d, -u, atol=1e-9)`` for finite unit vectors (``checks.unit_vector``'s), the
    same comparison (|d − (−u)| <= atol + rtol·|−u|, rtol 1e-5) without its cost: called twice per
    circle fit."""
    return bool(np.all(np.abs(d + u) <= 1e-9 + 1e-05 * np.abs(u)))


def circle_fit_of_touches(touches: Sequence[Touch], plane: Plane, kind: str, probe: ProbeRecord | None = None
                          ) -> tuple[FloatArray, float, CircleFit | None]:
    """(centre (3,), diameter) of a bore (``kind`` "hole") or shaft ("spigot").

    4 touches P1 +u, P2 −u, P3 +v, P4 −v (u ⟂ v, any probing angle; travel directions):
    CYCLE977 (measuring-math §8.3) in the (u, v) basis with the surface points s_i:
    centre_u = ((s1 + s2)/2)·u, centre_v = ((s3 + s4)/2)·v, bore D = (s3 − s4)·v,
    shaft D = (s4 − s3)·v (only the v chord runs through the found centre [M]).
    Other layouts (>= 3 touches): circle fit of the ball centres, R = R_c + ρ (bore) or
    R_c − ρ (shaft) (measuring-math §5.3 [I], CYCLE116). Infeed coordinate: mean of the touches.
    """
    if kind not in ("hole", "spigot"):
        raise ValueError(f"kind must be 'hole' or 'spigot', got {kind!r}")
    if len(touches) < 3:
        raise MeasuringError(alarms.CIRCLE_PARAMETERS, f"a circle needs 3 or more touches, got {len(touches)}")
    height = float(np.mean([plane.to_aop(t.surface)[2] for t in touches]))
    if len(touches) == 4:
        u = checks.unit_vector(_ao(plane, touches[0].direction))
        v = checks.unit_vector(_ao(plane, touches[2].direction))
        d1 = checks.unit_vector(_ao(plane, touches[1].direction))
        d3 = checks.unit_vector(_ao(plane, touches[3].direction))
        if abs(u @ v) < 1e-9 and _opposite(d1, u) and _opposite(d3, v):
            s = [_ao(plane, t.surface) for t in touches]
            centre_u = 0.5 * (s[0] + s[1]) @ u          # jog-measuring §8.3 centre_a = (s1 + s2)/2
            centre_v = 0.5 * (s[2] + s[3]) @ v          # jog-measuring §8.3 centre_o = (s3 + s4)/2
            chord = (s[2] - s[3]) @ v                   # jog-measuring §8.3 bore D = s3 − s4
            diameter = chord if kind == "hole" else -chord   # shaft D = s4 − s3
            if diameter <= 0.0:
                raise MeasuringError(alarms.CIRCLE_UNDETERMINED, f"{kind}: non-positive diameter {diameter:.6f}")
            return _xyz(plane, centre_u * u + centre_v * v, height), float(diameter), None
    centres = np.array([_ao(plane, t.ball_centre) for t in touches])
    circle = fit_circle(centres)                        # CYCLE116 on the ball centres
    rho = float(np.mean([touch_radius(t, probe, plane) for t in touches]))
    radius = circle.radius + rho if kind == "hole" else circle.radius - rho   # jog-measuring §5.3 [I]
    if radius <= 0.0:
        raise MeasuringError(alarms.CIRCLE_UNDETERMINED, f"{kind}: non-positive radius {radius:.6f}")
    return _xyz(plane, circle.center, height), 2.0 * radius, circle


def rect_from_touches(touches: Sequence[Touch], plane: Plane, kind: str
                      ) -> tuple[FloatArray, float, float]:
    """(centre (3,), length along the 1st plane axis, width along the 2nd) of a rectangle.

    4 touches: a pair of opposite travels along one plane axis and a pair along the other
    (measuring-math §8.3): inner La = s1 − s2, outer La = s2 − s1 along the pair's travel
    direction of P1; centre = mid-points of both pairs. ``kind`` "pocket" or "spigot".
    """
    if kind not in ("pocket", "spigot"):
        raise ValueError(f"kind must be 'pocket' or 'spigot', got {kind!r}")
    if len(touches) != 4:
        raise ValueError(f"a rectangle needs 4 touches, got {len(touches)}")
    s = [_ao(plane, t.surface) for t in touches]
    pairs = []
    for i, j in ((0, 1), (2, 3)):
        u = checks.unit_vector(_ao(plane, touches[i].direction))
        span = (s[i] - s[j]) @ u                           # jog-measuring §8.3 inner: s1 − s2
        span = span if kind == "pocket" else -span         # outer: s2 − s1
        if span <= 0.0:
            raise MeasuringError(alarms.CIRCLE_UNDETERMINED, f"{kind}: non-positive span {span:.6f}")
        pairs.append((u, 0.5 * (s[i] + s[j]) @ u, span))
    (u1, c1, span1), (u2, c2, span2) = pairs
    if abs(u1 @ u2) > 1e-9:
        raise ValueError("rectangle touches must be probed along two perpendicular axes")
    centre = c1 * u1 + c2 * u2
    if abs(u1[0]) >= abs(u1[1]):
        length, width = span1, span2
    else:
        length, width = span2, span1
    height = float(np.mean([plane.to_aop(t.surface)[2] for t in touches]))
    return _xyz(plane, centre, height), float(length), float(width)


def _circle_of(point: StoredPoint, plane: Plane, kind: str, probe: ProbeRecord
               ) -> tuple[FloatArray, float]:
    centre, diameter, _fit = _circle_fit_of(point, plane, kind, probe)
    return centre, diameter


def _circle_fit_of(point: StoredPoint, plane: Plane, kind: str, probe: ProbeRecord
                   ) -> tuple[FloatArray, float, CircleFit | None]:
    if not isinstance(point, CirclePoint):
        raise ValueError(f"expected a CirclePoint, got {type(point).__name__}")
    if len(point.touches) >= 3:
        return circle_fit_of_touches(point.touches, plane, kind, probe)
    return np.asarray(point.center, dtype=float), float(point.diameter), None


def _fit_values(fits: Sequence[CircleFit | None]) -> dict[str, Any]:
    """``residuals`` and ``form_error`` of N-point circle fits (design.md §9.8, §10.2): one circle
    its residuals (mm, + outside), several the worst form error of them; none: no keys."""
    found = [f for f in fits if f is not None]
    if not found:
        return {}
    if len(fits) == 1:
        return {"residuals": [float(r) for r in found[0].residuals], "form_error": float(found[0].form_error),
                "touches": int(found[0].n)}
    return {"form_errors": [None if f is None else float(f.form_error) for f in fits],
            "form_error": max(float(f.form_error) for f in found)}


# --- edges ------------------------------------------------------------------------------------

def evaluate_edge_set(task: str, params: dict[str, Any], points: Sequence[StoredPoint], plane: Plane,
        probe: ProbeRecord) -> TaskResult:
    """Set edge (jog-measuring §2.5.1): edge position = the touch's surface coordinate on the axis."""
    (touch,) = _edge_points(task, points, 1)
    axis = _measuring_axis(params, touch)
    pos = float(touch.surface[axis_index(axis)])                       # jog-measuring §5.3 s_j = c_j − t
    values = {"position": {axis: pos}, "axis": axis, "points": _touch_values(plane, [touch])}
    return TaskResult(task, values, FeatureFix(position={axis: pos}, point=np.array(touch.surface)))


def evaluate_edge_align(task: str, params: dict[str, Any], points: Sequence[StoredPoint], plane: Plane,
        probe: ProbeRecord) -> TaskResult:
    """Align edge (jog-measuring §2.5.2): angle of the edge P1→P2 against the reference axis r.

    alpha = atan2(Δm, Δr) of the surface points (spec [I]), signed as the right-hand rotation
    about the third axis k that turns +r onto the edge (measuring-math §11.1: σ = +1 when
    (r, m, k) is cyclic, else −1), folded into (−90°, 90°] because an edge has no direction.
    """
    touches = _edge_points(task, points, max(2, len(points)))
    t1, t2 = touches[0], touches[-1]
    m = _measuring_axis(params, t1)
    r = params.get("reference_axis") or (plane.second if m == plane.first else plane.first)
    im, ir = axis_index(m), axis_index(r)
    if im == ir:
        raise ValueError(f"reference axis {r} must differ from the measuring axis {m}")
    k = _AXES[3 - im - ir]
    sigma = 1.0 if (im - ir) % 3 == 1 else -1.0                          # measuring-math §11.1 cyclic pairs
    delta = np.asarray(t2.surface, float) - np.asarray(t1.surface, float)
    if abs(delta[ir]) < _COINCIDENT_TOL:
        raise MeasuringError(alarms.POINTS_IDENTICAL, "P1 and P2 coincide along the reference axis")
    quality = {}
    if len(touches) > 2:       # n points: the least-squares line of the surface points (design.md §9.8)
        line = fit_line(np.array([[t.surface[ir], t.surface[im]] for t in touches], dtype=float))
        delta = np.zeros(3)
        delta[ir], delta[im] = line.direction
        quality = {"residuals": [float(v) for v in line.residuals], "form_error": float(line.form_error)}
    alpha = _fold90(float(np.degrees(np.arctan2(sigma * delta[im], delta[ir]))))   # jog-measuring §2.5.2
    values = {"angle": alpha, "measuring_axis": m, "reference_axis": r, "angle_axis": k,
              "points": _touch_values(plane, touches), **quality}
    fix = FeatureFix(point=np.array(t1.surface))
    if _wants_angle(params, "rotation"):
        fix = FeatureFix(angle=alpha, angle_axis=k, reference_axis=r, point=np.array(t1.surface))
    return TaskResult(task, values, fix)


def evaluate_edge_distance(task: str, params: dict[str, Any], points: Sequence[StoredPoint], plane: Plane,
        probe: ProbeRecord) -> TaskResult:
    """Distance 2 edges (jog-measuring §2.5.3): L = |e2 − e1|, centre (e1 + e2)/2 on the axis;
    with ``line_angle`` along that line instead (``distance_along_line``)."""
    t1, t2 = _edge_points(task, points, 2)
    if params.get("line_angle") is not None:
        return distance_along_line(task, params, t1, t2, plane)
    axis = _measuring_axis(params, t1)
    j = axis_index(axis)
    e1, e2 = float(t1.surface[j]), float(t2.surface[j])
    centre = 0.5 * (e1 + e2)
    point = 0.5 * (np.asarray(t1.surface, float) + np.asarray(t2.surface, float))
    values = {"distance": abs(e2 - e1), "center": {axis: centre}, "axis": axis,
              "points": _touch_values(plane, [t1, t2])}
    return TaskResult(task, values, FeatureFix(position={axis: centre}, point=point))


def line_unit(plane: Plane, angle_deg: float) -> FloatArray:
    """û = (cos θ, sin θ) in the plane's (abscissa, ordinate), as a WCS vector (measuring-math §10.2)."""
    t = float(np.radians(angle_deg))
    unit: FloatArray = np.cos(t) * plane.unit(plane.first) + np.sin(t) * plane.unit(plane.second)
    return unit


def distance_along_line(task: str, params: dict[str, Any], t1: Touch, t2: Touch, plane: Plane) -> TaskResult:
    """Slot or web at an angle (CYCLE979 _MVAR 3/4/103/104; manual §5.6.1, measuring-math §10.2).

    û = (cos θ, sin θ), θ = ``line_angle`` (_STA1); s_i = the touches' surface points
    (c_i + ρ·d̂_i, measuring-math §5.3); W = |(s1 − s2)·û|, mid = (s1 + s2)/2. Only the centre's
    component along the line is known (measuring-math §10.2): centre = CP + ((mid − CP)·û)·û,
    CP = ``setpoint`` (a, o). §10.2 prints slot W = (s1 − s2)·û, web W = (s2 − s1)·û; with its own
    travels (web P1 from the +û side, as the slot's P1) both touch the +û wall first, so the web's
    printed sign gives −W: the magnitude is what both mean (as distance 2 edges, jog-measuring §2.5.3).
    """
    u = line_unit(plane, float(params["line_angle"]))
    s1, s2 = np.asarray(t1.surface, float), np.asarray(t2.surface, float)
    width = abs(float((s1 - s2) @ u))                                           # measuring-math §10.2
    mid = 0.5 * (s1 + s2)
    setpoint = params["setpoint"]
    height = float(plane.to_aop(mid)[2])
    cp = plane.to_xyz(np.array([float(setpoint[plane.first]), float(setpoint[plane.second]), height]))
    centre = cp + float((mid - cp) @ u) * u                                     # measuring-math §10.2 d = ((mid − CP)·û)·û
    centre_ao = {plane.first: float(centre @ plane.unit(plane.first)),
                 plane.second: float(centre @ plane.unit(plane.second))}
    values = {"distance": width, "center": centre_ao, "axis": params.get("axis", plane.first),
              "line_angle": float(params["line_angle"]), "points": _touch_values(plane, [t1, t2])}
    return TaskResult(task, values, FeatureFix(position=dict(centre_ao), point=centre))


# --- corners ----------------------------------------------------------------------------------

def _normal_shift(plane: Plane, probe: ProbeRecord, touch: Touch, normal: FloatArray) -> float:
    """Ball-centre-to-surface distance along the edge normal n̂ for an axis-parallel touch.

    The overtravel δ = r − |t| (pre-travel + latency path) runs along the probing direction d̂,
    so only δ·cosθ of it (θ = angle between d̂ and n̂) brings the centre nearer the edge:
    shift = r − δ·cosθ (measuring-math §5.3 / measuring-math §12.3; equals |t| for θ = 0).
    """
    rho = touch_radius(touch, probe, plane)
    cos_theta = abs(float(_ao(plane, touch.direction) @ normal))
    r_nominal = probe.ball_diameter / 2.0
    return r_nominal - (r_nominal - rho) * cos_theta


def _surface_line(plane: Plane, probe: ProbeRecord, touches: Sequence[Touch]) -> tuple[LineFit, list[FloatArray]]:
    """Edge line: fit through the ball centres, shifted by ρ_dir along n̂ (n̂·d̂ > 0) (jog-measuring §5.3 [I])."""
    centres = [_ao(plane, t.ball_centre) for t in touches]
    for i in range(len(centres) - 1):
        if np.linalg.norm(centres[i + 1] - centres[i]) < _COINCIDENT_TOL:
            raise MeasuringError(alarms.POINTS_IDENTICAL, "points P1/P2 or P3/P4 are identical")
    line = fit_line(np.array(centres))
    normal = np.array([-line.direction[1], line.direction[0]])
    travel = np.sum([_ao(plane, t.direction) for t in touches], axis=0)
    if normal @ travel < 0.0:
        normal = -normal
    shifted = [c + _normal_shift(plane, probe, t, normal) * normal     # jog-measuring §5.3 ρ_dir·n̂
               for c, t in zip(centres, touches, strict=True)]
    return fit_line(np.array(shifted)), shifted


def _check_outside(line: LineFit, q_first: FloatArray, q_last: FloatArray, corner: FloatArray, which: str) -> None:
    """61369 when the corner lies strictly between the points of one edge (measuring-math §12.3 [M/I])."""
    length = float(np.linalg.norm(np.asarray(q_last) - np.asarray(q_first)))
    t = float((corner - q_first) @ line.direction) / length
    if 1e-9 < t < 1.0 - 1e-9:
        raise MeasuringError(alarms.CORNER_NOT_UNIQUE, f"corner position not unique: it lies between {which}")


def evaluate_corner(task: str, params: dict[str, Any], points: Sequence[StoredPoint], plane: Plane,
        probe: ProbeRecord) -> TaskResult:
    """Right-angled / any corner (jog-measuring §2.6, measuring-math §12.3).

    Reference edge L1 through P1, P2; second edge: the perpendicular through P3 (right-angled)
    or the line P3P4 (any). Both from ball centres shifted by ρ_dir towards the material.
    P0 = L1 ∩ L2 (parallel -> 61368, identical points -> 61367, P0 between the points of one
    edge -> 61369). Angle = direction of L1 against the 1st plane axis about the infeed,
    folded into (−90°, 90°].
    """
    right = len(points) == 3             # right-angled corner: 3 points, any corner: 4
    touches = _edge_points(task, points, 3 if right else 4)
    line1, q12 = _surface_line(plane, probe, touches[:2])
    if right:
        perp = np.array([-line1.direction[1], line1.direction[0]])
        c3 = _ao(plane, touches[2].ball_centre)
        n2 = line1.direction if line1.direction @ _ao(plane, touches[2].direction) > 0 \
            else -line1.direction
        q3 = c3 + _normal_shift(plane, probe, touches[2], n2) * n2             # jog-measuring §5.3 shift
        line2 = LineFit(point=q3, direction=perp)
        corner = intersect_lines(line1, line2)                                 # measuring-math §12.3
        _check_outside(line1, q12[0], q12[1], corner, "P1 and P2")
    else:
        line2, q34 = _surface_line(plane, probe, touches[2:])
        corner = intersect_lines(line1, line2)                                 # measuring-math §12.3
        _check_outside(line1, q12[0], q12[1], corner, "P1 and P2")
        _check_outside(line2, q34[0], q34[1], corner, "P3 and P4")
    angle = _fold90(_angle_ao(line1.direction))                                # measuring-math §12.3 φ_W
    height = float(np.mean([plane.to_aop(t.surface)[2] for t in touches]))
    corner_xyz = _xyz(plane, corner, height)
    values = {"corner": _plane_point(plane, corner), "angle": angle,
              "points": _touch_values(plane, touches)}
    if not right:
        values["angle_2"] = _angle_ao(line2.direction)
        # the angle between the two edges as they leave the corner towards their points
        # (jog-measuring §2.6.2): e.g. 105° for a 105° corner, not its supplement
        u1 = checks.unit_vector(np.mean(q12, axis=0) - corner)
        u2 = checks.unit_vector(np.mean(q34, axis=0) - corner)
        values["corner_angle"] = float(np.degrees(np.arccos(np.clip(u1 @ u2, -1.0, 1.0))))
    fix = FeatureFix(position=_plane_point(plane, corner), angle=angle, angle_axis=plane.infeed,
                     reference_axis=plane.first, point=corner_xyz)
    return TaskResult(task, values, fix)


# --- pockets, holes, spigots -------------------------------------------------------------

def evaluate_rect(task: str, params: dict[str, Any], points: Sequence[StoredPoint], plane: Plane,
        probe: ProbeRecord, *, kind: str) -> TaskResult:
    """Rectangular pocket / spigot (jog-measuring §2.7.1, jog-measuring §2.8; measuring-math §8.3)."""
    if len(points) != 1:
        raise ValueError(f"{task} needs 1 stored point, got {len(points)}")
    (point,) = points
    if not isinstance(point, RectPoint):
        raise ValueError(f"{task}: expected a RectPoint, got {type(point).__name__}")
    if len(point.touches) == 4:
        centre, length, width = rect_from_touches(point.touches, plane, kind)
    else:
        centre, length, width = np.asarray(point.center, float), point.length, point.width
    ao = _ao(plane, centre)
    values = {"center": _plane_point(plane, ao), "length": float(length), "width": float(width)}
    return TaskResult(task, values, FeatureFix(position=_plane_point(plane, ao), point=centre))


def evaluate_circle1(task: str, params: dict[str, Any], points: Sequence[StoredPoint], plane: Plane,
        probe: ProbeRecord, *, kind: str) -> TaskResult:
    """1 hole / 1 circular spigot (jog-measuring §2.7.1, jog-measuring §2.8): centre P0 and diameter."""
    if len(points) != 1:
        raise ValueError(f"{task} needs 1 stored point, got {len(points)}")
    centre, diameter, fit = _circle_fit_of(points[0], plane, kind, probe)
    ao = _ao(plane, centre)
    values = {"center": _plane_point(plane, ao), "diameter": diameter, **_fit_values([fit])}
    return TaskResult(task, values, FeatureFix(position=_plane_point(plane, ao), point=centre))


def _centres(task: str, points: Sequence[StoredPoint], n: int, plane: Plane, probe: ProbeRecord, kind: str
             ) -> tuple[list[FloatArray], list[float], float, dict[str, Any]]:
    if len(points) != n:
        raise ValueError(f"{task} needs {n} stored points, got {len(points)}")
    circles = [_circle_fit_of(p, plane, kind, probe) for p in points]
    centres = [_ao(plane, c) for c, _, _ in circles]
    height = float(np.mean([plane.to_aop(c)[2] for c, _, _ in circles]))
    return centres, [d for _, d, _ in circles], height, _fit_values([f for _, _, f in circles])


def _directed_angle(a: FloatArray, b: FloatArray, what: str) -> float:
    if np.linalg.norm(b - a) < _COINCIDENT_TOL:
        raise MeasuringError(alarms.POINTS_IDENTICAL, f"{what}: the points are identical")
    return _angle_ao(b - a)


def evaluate_circles2(task: str, params: dict[str, Any], points: Sequence[StoredPoint], plane: Plane,
        probe: ProbeRecord, *, kind: str) -> TaskResult:
    """2 holes / spigots (jog-measuring §2.7.2): alpha of the line P1→P2 against the 1st plane axis.

    fix: the angle when an angle correction is asked (default "rotation"); with ``set_p1``
    and coordinate rotation also the translation of P1.
    """
    (p1, p2), diameters, height, fits = _centres(task, points, 2, plane, probe, kind)
    alpha = _directed_angle(p1, p2, "P1→P2")                                   # jog-measuring §2.7.2
    values = {"angle": alpha, "p1": _plane_point(plane, p1), "p2": _plane_point(plane, p2),
              "distance": float(np.linalg.norm(p2 - p1)), "diameters": diameters, **fits}
    correction = params.get("angle_correction", "rotation")
    position = _plane_point(plane, p1) if params.get("set_p1") and correction == "rotation" else {}
    fix = FeatureFix(position=position, point=_xyz(plane, p1, height))
    if _wants_angle(params, "rotation"):
        fix = FeatureFix(position=position, angle=alpha, angle_axis=plane.infeed,
                         reference_axis=plane.first, point=_xyz(plane, p1, height))
    return TaskResult(task, values, fix)


def evaluate_circles34(task: str, params: dict[str, Any], points: Sequence[StoredPoint], plane: Plane,
        probe: ProbeRecord, *, kind: str, n: int) -> TaskResult:
    """3 / 4 holes or spigots (jog-measuring §2.7.3, jog-measuring §2.7.4).

    3: P0 = circumcentre of P1..P3 (CYCLE116; collinear -> 61316), alpha of P0→P1.
    4: P0 = intersection of the diagonals P1P3 and P2P4 (parallel -> 61368), alpha of P1→P2.
    fix: translation of P0; the angle only when ``angle_correction`` is not "none" (default).
    """
    centres, diameters, height, fits = _centres(task, points, n, plane, probe, kind)
    if n == 3:
        circle = fit_circle(np.array(centres))                                 # jog-measuring §6 circumcircle
        p0 = circle.center
        extra = {"pitch_diameter": 2.0 * circle.radius}
    else:
        for i, j in ((0, 2), (1, 3)):
            if np.linalg.norm(centres[j] - centres[i]) < _COINCIDENT_TOL:
                raise MeasuringError(alarms.POINTS_IDENTICAL, f"P{i + 1} and P{j + 1} are identical")
        p0 = intersect_lines(fit_line(np.array([centres[0], centres[2]])),
                             fit_line(np.array([centres[1], centres[3]])))
        extra = {}
    pts = [p0, *centres]
    i, j = HOLE_ANGLE_LINE[n]
    alpha = _directed_angle(pts[i], pts[j], f"P{i}→P{j}")                     # jog-measuring §11 Q6
    values = {"center": _plane_point(plane, p0), "angle": alpha,
              "points": [_plane_point(plane, c) for c in centres], "diameters": diameters, **extra, **fits}
    p0_xyz = _xyz(plane, p0, height)
    fix = FeatureFix(position=_plane_point(plane, p0), point=p0_xyz)
    if _wants_angle(params, "none"):
        fix = FeatureFix(position=_plane_point(plane, p0), angle=alpha, angle_axis=plane.infeed,
                         reference_axis=plane.first, point=p0_xyz)
    return TaskResult(task, values, fix)


# --- orient plane ---------------------------------------------------------------------------

def evaluate_plane_align(task: str, params: dict[str, Any], points: Sequence[StoredPoint], plane: Plane,
        probe: ProbeRecord) -> TaskResult:
    """Orient plane (jog-measuring §2.9): normal of the plane through the 3 surface points.

    n̂ oriented to +infeed; with R = Rot_o(beta)·Rot_a(alpha), R·ê_p = n̂:
    alpha = asin(−n_o), beta = atan2(n_a, n_p) (G17: asin(−n_y), atan2(n_x, n_z)).
    Collinear points -> 61411.
    """
    touches = _edge_points(task, points, max(3, len(points)))      # n >= 3 points: least squares
    fit = fit_plane(np.array([t.surface for t in touches], dtype=float))
    normal = fit.normal if fit.normal @ plane.infeed_unit > 0.0 else -fit.normal
    if abs(normal @ plane.infeed_unit) < 1e-12:
        raise MeasuringError(alarms.FRAME_IMPOSSIBLE, "frame calculation impossible: plane parallel to the infeed")
    alpha, beta = alpha_beta_from_normal(normal, plane)                          # jog-measuring §2.9
    values = {"alpha": alpha, "beta": beta,
              "normal": {a: float(v) for a, v in zip(_AXES, normal, strict=True)},
              "points": _touch_values(plane, touches),
              "residuals": [float(v) for v in fit.residuals], "form_error": float(fit.form_error)}
    return TaskResult(task, values, FeatureFix(normal=normal, point=fit.point))
