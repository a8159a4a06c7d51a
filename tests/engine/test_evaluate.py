"""engine.evaluate: every workpiece task recovers an analytic truth from ideal touches.

Ideal touches: the ball centre is where a ball of radius ρ_dir (= |t(dir)| of the probe record,
i.e. compensation.trigger_radius) first touches the true feature while travelling along the
probing direction; the surface point is the true contact point. The truth is built here from
the geometry (lines, circles, planes), independently of the engine's formulas.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from engine.planes import PLANES, Plane
from engine.tasks import evaluate
from engine.types import CirclePoint, EdgePoint, MeasuringError, ProbeRecord, RectPoint, Touch

SETTINGS = settings(max_examples=40, deadline=None)
TOL = 1e-9

planes = st.sampled_from(list(PLANES.values()))
coord = st.floats(-300.0, 300.0, allow_nan=False)
TRIGGERS = {"X-": 2.990, "X+": -2.994, "Y-": 2.992, "Y+": -2.996, "Z-": 2.989, "Z+": -2.993}
PROBE = ProbeRecord(ball_diameter=6.0, effective_diameter=5.984, trigger=dict(TRIGGERS),
                    calibrated_radius=True)


def rho(axis: str, sign: float) -> float:
    """Trigger radius of an axis-parallel travel (independent of the engine's lookup)."""
    return abs(TRIGGERS[f"{axis}{'+' if sign > 0 else '-'}"])


def unit2(deg: float) -> np.ndarray:
    return np.array([np.cos(np.radians(deg)), np.sin(np.radians(deg))])


def touch_aop(plane: Plane, c, d, s) -> Touch:
    return Touch(ball_centre=plane.to_xyz(np.asarray(c, float)),
                 direction=plane.to_xyz(np.asarray(d, float)),
                 surface=plane.to_xyz(np.asarray(s, float)))


BALL_RADIUS = PROBE.ball_diameter / 2.0


def edge_touch_2d(p0, u, travel_axis: int, sign: float, w: float, radius: float):
    """Ball travelling along plane axis ``travel_axis`` (0 = a, 1 = o) with ``sign`` at the
    other coordinate ``w`` onto the line p0 + λ·u: (latched ball centre, direction, contact).

    Physics as the simulator's (design.md §5): first contact at the ball radius from the line,
    then the overtravel δ = ball radius − ``radius`` (the trigger radius) along the travel.
    """
    d = np.zeros(2)
    d[travel_axis] = sign
    n_free = np.array([-u[1], u[0]])
    if n_free @ d > 0:
        n_free = -n_free                          # the ball stays on the side it comes from
    other = 1 - travel_axis
    base = p0 + BALL_RADIUS * n_free
    lam = (w - base[other]) / u[other]
    first_contact = base + lam * u
    return first_contact + (BALL_RADIUS - radius) * d, d, first_contact - BALL_RADIUS * n_free


def lift(plane: Plane, v2, p: float) -> np.ndarray:
    return np.array([v2[0], v2[1], p])


# --- edges ---------------------------------------------------------------------------------

@SETTINGS
@given(axis=st.sampled_from("XYZ"), sign=st.sampled_from([1.0, -1.0]), e=coord,
       others=st.tuples(coord, coord), plane=planes)
def test_edge_set(axis, sign, e, others, plane):
    j = "XYZ".index(axis)
    surface = np.insert(np.array(others), j, e)
    centre = surface.copy()
    centre[j] = e - sign * rho(axis, sign)
    d = np.zeros(3)
    d[j] = sign
    res = evaluate("edge.set", {"axis": axis, "direction": "+" if sign > 0 else "-", "setpoint": 0},
                   [EdgePoint(Touch(centre, d, surface))], plane, PROBE)
    assert res.values["position"][axis] == pytest.approx(e, abs=TOL)
    assert res.fix.position == pytest.approx({axis: e}, abs=TOL)


@SETTINGS
@given(axis=st.sampled_from("XYZ"), s1=st.sampled_from([1.0, -1.0]), s2=st.sampled_from([1.0, -1.0]),
       e1=coord, e2=coord, plane=planes)
def test_edge_distance(axis, s1, s2, e1, e2, plane):
    j = "XYZ".index(axis)
    pts = []
    for e, s in ((e1, s1), (e2, s2)):
        surface = np.array([11.0, -7.0, 3.0])
        surface[j] = e
        centre = surface.copy()
        centre[j] = e - s * rho(axis, s)
        d = np.zeros(3)
        d[j] = s
        pts.append(EdgePoint(Touch(centre, d, surface)))
    res = evaluate("edge.distance", {"axis": axis, "direction": "+", "direction_p2": "-"}, pts,
                   plane, PROBE)
    assert res.values["distance"] == pytest.approx(abs(e2 - e1), abs=TOL)
    assert res.values["center"][axis] == pytest.approx((e1 + e2) / 2, abs=TOL)
    assert res.fix.position[axis] == pytest.approx((e1 + e2) / 2, abs=TOL)


@SETTINGS
@given(m_r=st.sampled_from([("Y", "X"), ("X", "Y"), ("Z", "X"), ("X", "Z"), ("Z", "Y"), ("Y", "Z")]),
       theta=st.floats(-40.0, 40.0), sign=st.sampled_from([1.0, -1.0]), p0=st.tuples(coord, coord),
       w1=st.floats(-100, 100), dw=st.floats(5, 150), backwards=st.booleans(), plane=planes)
def test_edge_align_any_axes(m_r, theta, sign, p0, w1, dw, backwards, plane):
    """The edge is +r turned by theta right-handed about the third axis k (measuring-math §0.1)."""
    m, r = m_r
    im, ir = "XYZ".index(m), "XYZ".index(r)
    k = 3 - im - ir
    e_r, e_m, e_k = np.eye(3)[ir], np.eye(3)[im], np.eye(3)[k]
    edge_dir = np.cos(np.radians(theta)) * e_r + np.sin(np.radians(theta)) * np.cross(e_k, e_r)
    u = np.array([edge_dir @ e_r, edge_dir @ e_m])          # (r, m) coordinates
    touches = []
    ws = (w1, w1 + dw) if not backwards else (w1 + dw, w1)
    for w in ws:
        c2, _, s2 = edge_touch_2d(np.array(p0), u, 1, sign, w, rho(m, sign))
        c3 = c2[0] * e_r + c2[1] * e_m + 17.0 * e_k
        s3 = s2[0] * e_r + s2[1] * e_m + 17.0 * e_k
        touches.append(EdgePoint(Touch(c3, sign * e_m, s3)))
    res = evaluate("edge.align", {"axis": m, "direction": "+" if sign > 0 else "-",
                                  "reference_axis": r, "angle_correction": "rotation"},
                   touches, plane, PROBE)
    assert res.values["angle"] == pytest.approx(theta, abs=TOL)
    assert res.fix.angle == pytest.approx(theta, abs=TOL)
    assert res.fix.angle_axis == "XYZ"[k] and res.fix.reference_axis == r


# --- corners -------------------------------------------------------------------------------

CORNER_SIGNS = {1: (-1.0, -1.0), 2: (1.0, -1.0), 3: (1.0, 1.0), 4: (-1.0, 1.0)}


def corner_points(plane, k, phi1, phi2, pos, kind, dists, height):
    """Ideal touches of a corner at ``k`` with edges at phi1 (reference) and phi2."""
    sa, so = CORNER_SIGNS[pos]
    sig_o, sig_a = (-so, -sa) if kind == "outside" else (so, sa)   # towards material / wall
    u1, u2 = unit2(phi1), unit2(phi2)
    if u2[1] < 0:
        u2 = -u2
    pts = []
    for i, dist in enumerate(dists):
        if i < 2:       # reference edge, extends from K in −sa along a; probed along o
            w = (k + (-sa) * dist * u1)[0]
            c, d, s = edge_touch_2d(k, u1, 1, sig_o, w, rho(plane.second, sig_o))
        else:           # second edge, extends in −so along o; probed along a
            w = (k + (-so) * dist * u2)[1]
            c, d, s = edge_touch_2d(k, u2, 0, sig_a, w, rho(plane.first, sig_a))
        pts.append(EdgePoint(touch_aop(plane, lift(plane, c, height), lift(plane, d, 0.0),
                                       lift(plane, s, height))))
    return pts


def fold90(deg):
    return (deg + 90.0) % 180.0 - 90.0 if (deg + 90.0) % 180.0 != 0.0 else 90.0


@SETTINGS
@given(plane=planes, k=st.tuples(coord, coord), phi1=st.floats(-30.0, 30.0),
       pos=st.sampled_from([1, 2, 3, 4]), kind=st.sampled_from(["outside", "inside"]),
       d1=st.floats(6.0, 30.0), dd=st.floats(5.0, 80.0), d3=st.floats(6.0, 50.0),
       height=st.floats(-50, 50))
def test_corner_right(plane, k, phi1, pos, kind, d1, dd, d3, height):
    k = np.array(k)
    pts = corner_points(plane, k, phi1, phi1 + 90.0, pos, kind, [d1, d1 + dd, d3], height)
    res = evaluate("corner.right", {"kind": kind, "position": pos}, pts, plane, PROBE)
    got = res.values["corner"]
    assert got[plane.first] == pytest.approx(k[0], abs=TOL)
    assert got[plane.second] == pytest.approx(k[1], abs=TOL)
    assert res.values["angle"] == pytest.approx(phi1, abs=TOL)
    assert res.fix.angle == pytest.approx(phi1, abs=TOL)
    assert res.fix.angle_axis == plane.infeed and res.fix.reference_axis == plane.first
    assert res.fix.point[PLANES[plane.name].index[2]] == pytest.approx(height, abs=TOL)


@SETTINGS
@given(plane=planes, k=st.tuples(coord, coord), phi1=st.floats(-30.0, 30.0),
       delta=st.floats(-40.0, 40.0), pos=st.sampled_from([1, 2, 3, 4]),
       kind=st.sampled_from(["outside", "inside"]), d1=st.floats(10.0, 30.0), dd=st.floats(5.0, 80.0),
       d3=st.floats(10.0, 30.0), dd3=st.floats(5.0, 80.0), swap=st.booleans())
def test_corner_any(plane, k, phi1, delta, pos, kind, d1, dd, d3, dd3, swap):
    """Points at least 10 mm from the corner: with ρ ≈ 3 and walls up to 70° inclined to the
    probing axis the contact point moves up to ρ·tan70° ≈ 8 mm along the edge."""
    k = np.array(k)
    dists = [d1, d1 + dd, d3, d3 + dd3]
    if swap:                                   # probing order along an edge does not matter
        dists = [d1 + dd, d1, d3 + dd3, d3]
    pts = corner_points(plane, k, phi1, phi1 + 90.0 + delta, pos, kind, dists, 0.0)
    res = evaluate("corner.any", {"kind": kind, "position": pos}, pts, plane, PROBE)
    got = res.values["corner"]
    assert got[plane.first] == pytest.approx(k[0], abs=TOL)
    assert got[plane.second] == pytest.approx(k[1], abs=TOL)
    assert res.values["angle"] == pytest.approx(phi1, abs=TOL)
    # the corner's own angle: between the edges as they leave K (−sa·u1 and −so·u2, corner_points)
    sa, so = CORNER_SIGNS[pos]
    u1, u2 = unit2(phi1), unit2(phi1 + 90.0 + delta)
    u2 = -u2 if u2[1] < 0 else u2
    expected = math.degrees(math.acos(max(-1.0, min(1.0, sa * so * float(u1 @ u2)))))
    assert res.values["corner_angle"] == pytest.approx(expected, abs=1e-8)


def test_corner_errors():
    plane = PLANES["G17"]
    k = np.array([20.0, 30.0])
    pts = corner_points(plane, k, 2.0, 92.0, 1, "outside", [10, 40, 10, 40], 0.0)
    with pytest.raises(MeasuringError) as err:                       # P1 = P2
        evaluate("corner.any", {}, [pts[0], pts[0], pts[2], pts[3]], plane, PROBE)
    assert err.value.alarm == 61367
    par = corner_points(plane, k, 2.0, 2.0 + 1e-14, 1, "outside", [10, 40, 10, 40], 0.0)
    with pytest.raises(MeasuringError) as err:                       # parallel edges
        evaluate("corner.any", {}, [pts[0], pts[1], par[0], par[1]], plane, PROBE)
    assert err.value.alarm in (61367, 61368)
    straddle = corner_points(plane, k, 2.0, 92.0, 1, "outside", [10, 40, 10, 40], 0.0)
    other = corner_points(plane, k, 2.0, 92.0, 2, "outside", [10, 40, 10, 40], 0.0)
    with pytest.raises(MeasuringError) as err:                       # K between P1 and P2
        evaluate("corner.right", {}, [straddle[0], other[0], straddle[2]], plane, PROBE)
    assert err.value.alarm == 61369


# --- circles and rectangles ----------------------------------------------------------------

def circle_touches(plane, m, radius, kind, theta=0.0, h=0.0, ball=2.0, height=0.0):
    """CYCLE977 layout: P1 +u, P2 −u on the chord offset h, then P3 +v, P4 −v through M."""
    u, v = unit2(theta), unit2(theta + 90.0)
    m = np.asarray(m, float)
    out = []
    reach = radius - ball if kind == "hole" else radius + ball
    for d, off, side in ((u, h, 1.0), (-u, h, -1.0), (v, 0.0, 1.0), (-v, 0.0, -1.0)):
        axis = d if side > 0 else -d                     # +u / +v of the chord
        other = v if abs(axis @ u) > 0.5 else u
        x = np.sqrt(reach**2 - off**2)
        if kind == "hole":
            c = m + off * other + x * (d)                # travelling d reaches the wall ahead
        else:
            c = m + off * other - x * (d)                # comes from the far side
        s = m + radius * (c - m) / np.linalg.norm(c - m)
        out.append(touch_aop(plane, lift(plane, c, height), lift(plane, d, 0.0),
                             lift(plane, s, height)))
    return out


@SETTINGS
@given(plane=planes, m=st.tuples(coord, coord), radius=st.floats(4.0, 80.0),
       theta=st.floats(-45.0, 45.0), hf=st.floats(-0.3, 0.3), kind=st.sampled_from(["hole", "spigot"]))
def test_circle_one(plane, m, radius, theta, hf, kind):
    touches = circle_touches(plane, m, radius, kind, theta, hf * radius, height=-5.0)
    point = CirclePoint(center=np.zeros(3), diameter=0.0, touches=tuple(touches))
    task = "hole.1" if kind == "hole" else "spigot.1"
    res = evaluate(task, {"diameter": 2 * radius, "probe_angle": theta}, [point], plane, PROBE)
    assert res.values["center"][plane.first] == pytest.approx(m[0], abs=TOL)
    assert res.values["center"][plane.second] == pytest.approx(m[1], abs=TOL)
    assert res.values["diameter"] == pytest.approx(2 * radius, abs=TOL)
    assert res.fix.position == pytest.approx({plane.first: m[0], plane.second: m[1]}, abs=TOL)


@SETTINGS
@given(plane=planes, m=st.tuples(coord, coord), length=st.floats(10.0, 200.0),
       width=st.floats(10.0, 200.0), h=st.floats(-3.0, 3.0), kind=st.sampled_from(["pocket", "spigot"]))
def test_rect(plane, m, length, width, h, kind):
    m = np.array(m)
    half = np.array([length / 2, width / 2])
    touches = []
    for j, sign in ((0, 1.0), (0, -1.0), (1, 1.0), (1, -1.0)):
        d = np.zeros(2)
        d[j] = sign
        axis = plane.axes[j]
        s = m.copy()
        s[1 - j] += h
        if kind == "pocket":
            s[j] += sign * half[j]
            c = s - d * rho(axis, sign)
        else:
            s[j] -= sign * half[j]
            c = s - d * rho(axis, sign)
        touches.append(touch_aop(plane, lift(plane, c, 1.0), lift(plane, d, 0.0), lift(plane, s, 1.0)))
    point = RectPoint(center=np.zeros(3), length=0.0, width=0.0, touches=tuple(touches))
    task = "pocket.rect" if kind == "pocket" else "spigot.rect"
    res = evaluate(task, {"length": length, "width": width}, [point], plane, PROBE)
    assert res.values["center"][plane.first] == pytest.approx(m[0], abs=TOL)
    assert res.values["center"][plane.second] == pytest.approx(m[1], abs=TOL)
    assert res.values["length"] == pytest.approx(length, abs=TOL)
    assert res.values["width"] == pytest.approx(width, abs=TOL)


def circle_point(plane, m, radius, kind, theta=0.0, h=0.0):
    return CirclePoint(center=np.zeros(3), diameter=0.0,
                       touches=tuple(circle_touches(plane, m, radius, kind, theta, h)))


def wrap180(deg):
    w = (deg + 180.0) % 360.0 - 180.0
    return 180.0 if w == -180.0 else w


@SETTINGS
@given(plane=planes, p1=st.tuples(coord, coord), dist=st.floats(10.0, 300.0), phi=st.floats(-179.0, 179.0),
       kind=st.sampled_from(["hole", "spigot"]), set_p1=st.booleans())
def test_circles_two(plane, p1, dist, phi, kind, set_p1):
    p1 = np.array(p1)
    p2 = p1 + dist * unit2(phi)
    pts = [circle_point(plane, p, 6.0, kind, h=0.7) for p in (p1, p2)]
    res = evaluate(f"{kind}.2", {"angle_correction": "rotation", "set_p1": set_p1}, pts, plane, PROBE)
    assert res.values["angle"] == pytest.approx(phi, abs=TOL)
    assert res.values["p1"][plane.first] == pytest.approx(p1[0], abs=TOL)
    assert res.values["p1"][plane.second] == pytest.approx(p1[1], abs=TOL)
    assert res.fix.angle == pytest.approx(phi, abs=TOL)
    assert bool(res.fix.position) == set_p1


@SETTINGS
@given(plane=planes, p0=st.tuples(coord, coord), pitch=st.floats(20.0, 200.0), a1=st.floats(-180.0, 180.0),
       g1=st.floats(60.0, 150.0), g2=st.floats(60.0, 150.0), kind=st.sampled_from(["hole", "spigot"]),
       corr=st.sampled_from(["none", "rotation", "C"]))
def test_circles_three(plane, p0, pitch, a1, g1, g2, kind, corr):
    p0 = np.array(p0)
    angles = [a1, a1 + g1, a1 + g1 + g2]
    pts = [circle_point(plane, p0 + pitch * unit2(a), 5.0, kind, h=-0.4) for a in angles]
    res = evaluate(f"{kind}.3", {"angle_correction": corr}, pts, plane, PROBE)
    assert res.values["center"][plane.first] == pytest.approx(p0[0], abs=TOL)
    assert res.values["center"][plane.second] == pytest.approx(p0[1], abs=TOL)
    assert abs(wrap180(res.values["angle"] - a1)) < TOL                  # line P0 -> P1
    assert (res.fix.angle is None) == (corr == "none")
    assert res.fix.position[plane.first] == pytest.approx(p0[0], abs=TOL)


@SETTINGS
@given(plane=planes, p0=st.tuples(coord, coord), r=st.lists(st.floats(15.0, 150.0), min_size=4, max_size=4),
       b1=st.floats(-180.0, 180.0), b2=st.floats(40.0, 140.0), kind=st.sampled_from(["hole", "spigot"]))
def test_circles_four(plane, p0, r, b1, b2, kind):
    p0 = np.array(p0)
    bs = [b1, b1 + b2, b1 + 180.0, b1 + b2 + 180.0]               # P1/P3 and P2/P4 opposite
    centres = [p0 + ri * unit2(b) for ri, b in zip(r, bs, strict=True)]
    pts = [circle_point(plane, c, 5.0, kind, theta=10.0, h=0.3) for c in centres]
    res = evaluate(f"{kind}.4", {"angle_correction": "rotation"}, pts, plane, PROBE)
    assert res.values["center"][plane.first] == pytest.approx(p0[0], abs=TOL)
    assert res.values["center"][plane.second] == pytest.approx(p0[1], abs=TOL)
    d12 = centres[1] - centres[0]
    assert abs(wrap180(res.values["angle"] - np.degrees(np.arctan2(d12[1], d12[0])))) < TOL


def test_hole_pattern_errors():
    plane = PLANES["G17"]
    line = [circle_point(plane, (10.0 * i, 5.0 * i), 5.0, "hole") for i in range(3)]
    with pytest.raises(MeasuringError) as err:
        evaluate("hole.3", {}, line, plane, PROBE)
    assert err.value.alarm == 61316
    par = [circle_point(plane, c, 5.0, "hole") for c in ((0, 0), (0, 50), (100, 0), (100, 50))]
    with pytest.raises(MeasuringError) as err:                  # diagonals P1P3 ∥ P2P4
        evaluate("hole.4", {}, par, plane, PROBE)
    assert err.value.alarm == 61368
    same = [circle_point(plane, (3.0, 4.0), 5.0, "hole")] * 2
    with pytest.raises(MeasuringError) as err:
        evaluate("hole.2", {}, same, plane, PROBE)
    assert err.value.alarm == 61367


def test_circle_point_without_touches_uses_stored_centre():
    plane = PLANES["G17"]
    pts = [CirclePoint(center=np.array([1.0, 2.0, 0.0]), diameter=10.0),
           CirclePoint(center=np.array([11.0, 12.0, 0.0]), diameter=10.0)]
    res = evaluate("hole.2", {}, pts, plane, PROBE)
    assert res.values["angle"] == pytest.approx(45.0, abs=TOL)


# --- orient plane -------------------------------------------------------------------------

def rx(deg):
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])


def ry(deg):
    c, s = np.cos(np.radians(deg)), np.sin(np.radians(deg))
    return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])


@SETTINGS
@given(plane=planes, alpha=st.floats(-30.0, 30.0), beta=st.floats(-30.0, 30.0),
       q=st.tuples(coord, coord, coord),
       ao=st.lists(st.tuples(st.floats(-80, 80), st.floats(-80, 80)), min_size=3, max_size=3))
def test_plane_align(plane, alpha, beta, q, ao):
    ao = np.array(ao)
    area = abs(np.cross(np.append(ao[1] - ao[0], 0), np.append(ao[2] - ao[0], 0))[2])
    assume(area > 50.0)
    n = ry(beta) @ rx(alpha) @ np.array([0.0, 0.0, 1.0])     # in (a, o, p), jog §2.9
    q = np.array(q)
    ball = rho(plane.infeed, -1.0)
    pts = []
    for a, o in ao:
        base = q + ball * n                                 # ball centres' offset plane
        p = (n @ base - n[0] * a - n[1] * o) / n[2]
        c = np.array([a, o, p])
        pts.append(EdgePoint(touch_aop(plane, c, [0, 0, -1.0], c - ball * n)))
    res = evaluate("plane.align", {}, pts, plane, PROBE)
    assert res.values["alpha"] == pytest.approx(alpha, abs=TOL)
    assert res.values["beta"] == pytest.approx(beta, abs=TOL)
    assert np.allclose(plane.to_aop(res.fix.normal), n, atol=1e-12)


def test_plane_align_collinear():
    plane = PLANES["G17"]
    pts = [EdgePoint(Touch(np.array([x, x, 3.0]), np.array([0, 0, -1.0]), np.array([x, x, 0.0])))
           for x in (0.0, 10.0, 20.0)]
    with pytest.raises(MeasuringError) as err:
        evaluate("plane.align", {}, pts, plane, PROBE)
    assert err.value.alarm == 61411


def test_unknown_task_and_wrong_count():
    with pytest.raises(ValueError):
        evaluate("edge.bogus", {}, [], PLANES["G17"], PROBE)
    with pytest.raises(ValueError):
        evaluate("edge.set", {}, [], PLANES["G17"], PROBE)
