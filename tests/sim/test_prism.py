"""Prism parts (design.md §9.8): contact on a vertical-walled polygon part against analytic geometry.

Expected values come from plane/line/point geometry in part coordinates (mapped to the MCS with
the independent scipy rotation), never from the simulator's SDF.
"""

import math

import numpy as np
import pytest
from sim_helpers import plane_contact, rotation, scenario

from app.machine.polygon import convex_pieces, polygon_area
from app.machine.scene import build_scene, outline
from app.machine.sim import SimulatedMachine

R_BALL = 2.0
TOL = 1e-9
HEIGHT = 50.0
POSE = {"trans": [250.0, 180.0, -140.0], "rot": [2.0, -3.0, 20.0]}


def _quad() -> list[tuple[float, float]]:
    """A convex quadrilateral with interior angles 60°, 120°, 75°, 105° (counter-clockwise)."""
    interior = [60.0, 120.0, 75.0, 105.0]
    headings = [0.0]
    for k in (1, 2, 3):
        headings.append(headings[-1] + 180.0 - interior[k])
    u = [np.array([math.cos(math.radians(h)), math.sin(math.radians(h))]) for h in headings]
    l0, l1 = 120.0, 50.0                                # choose two sides, close with the other two
    l2, l3 = np.linalg.solve(np.column_stack([u[2], u[3]]), -(l0 * u[0] + l1 * u[1]))
    assert l2 > 0 and l3 > 0
    pts = [np.zeros(2)]
    for length, ui in zip((l0, l1, l2), u[:3], strict=True):
        pts.append(pts[-1] + length * ui)
    return [tuple(map(float, p)) for p in pts]


def _notched() -> tuple[list[tuple[float, float]], list[tuple[np.ndarray, float]]]:
    """A bar 400 x 100 with V-notches of opening 60°, 75°, 105°, 120° cut into its top edge
    (counter-clockwise); returns the polygon and the notches' (apex, opening angle)."""
    notches = [(40.0, 60.0, 40.0), (120.0, 75.0, 40.0), (215.0, 105.0, 30.0), (320.0, 120.0, 25.0)]
    top = []
    for x, alpha, depth in reversed(notches):          # walk the top edge from right to left
        half = depth * math.tan(math.radians(alpha / 2))
        top += [(x + half, 100.0), (x, 100.0 - depth), (x - half, 100.0)]
    polygon = [(0.0, 0.0), (400.0, 0.0), (400.0, 100.0), *top, (0.0, 100.0)]
    return polygon, [(np.array([x, 100.0 - depth]), alpha) for x, alpha, depth in notches]


def _prism_scenario(polygon, *extra, pose=POSE):
    return scenario(workpiece={"pose": pose, "features": [{"type": "prism", "polygon": [list(p) for p in polygon],
                                                           "height": HEIGHT}, *extra]})


class Part:
    def __init__(self, sc):
        self.rot = rotation(sc.workpiece.pose.rot)
        self.trans = np.asarray(sc.workpiece.pose.trans, float)

    def point(self, p) -> np.ndarray:
        return self.rot @ np.asarray(p, float) + self.trans

    def vector(self, v) -> np.ndarray:
        return self.rot @ np.asarray(v, float)


def _edges(polygon):
    """(start, end, unit direction, outward normal) of each edge of a counter-clockwise polygon."""
    out = []
    for i, a in enumerate(polygon):
        a, b = np.asarray(a, float), np.asarray(polygon[(i + 1) % len(polygon)], float)
        u = (b - a) / np.linalg.norm(b - a)
        out.append((a, b, u, np.array([u[1], -u[0]])))
    return out


def _interior_angle(polygon, k) -> float:
    a, b, c = (np.asarray(polygon[i % len(polygon)], float) for i in (k - 1, k, k + 1))
    u, v = a - b, c - b
    ang = math.degrees(math.atan2(u[0] * v[1] - u[1] * v[0], u @ v)) % 360.0
    return 360.0 - ang


def test_the_quad_has_the_corner_angles():
    quad = _quad()
    assert polygon_area(quad) > 0
    assert [round(_interior_angle(quad, k), 9) for k in range(4)] == [60.0, 120.0, 75.0, 105.0]


@pytest.mark.parametrize("orientation", ["ccw", "cw"])
def test_faces_next_to_every_corner_of_a_convex_quad(orientation):
    quad = _quad()
    sc = _prism_scenario(quad if orientation == "ccw" else quad[::-1])
    scene, part = build_scene(sc), Part(sc)
    rng = np.random.default_rng(5)
    for a, b, u, n in _edges(quad):
        length = float(np.linalg.norm(b - a))
        for t in (3.0, 8.0, length / 2, length - 8.0, length - 3.0):   # beside both corners
            for z in (-1.0, -HEIGHT / 2, -HEIGHT + 1.0):
                p2 = a + t * u
                p_face = np.array([*p2, z])
                nz = np.array([*n, 0.0])
                c0 = p_face + (R_BALL + 4.0) * nz
                expected = plane_contact(c0, -nz, p_face, nz, R_BALL)
                got = scene.first_contact(part.point(c0), part.vector(-nz), 20.0, R_BALL)
                assert got == pytest.approx(expected, abs=TOL)
        # oblique approaches that meet the face inside its ends
        for _ in range(10):
            d = np.array([*(-n + rng.uniform(-0.5, 0.5) * u), rng.uniform(-0.3, 0.3)])
            d /= np.linalg.norm(d)
            p_face = np.array([*(a + (length / 2) * u), -HEIGHT / 2])
            nz = np.array([*n, 0.0])
            c0 = p_face + 6.0 * nz - 3.0 * d
            expected = plane_contact(c0, d, p_face, nz, R_BALL)
            got = scene.first_contact(part.point(c0), part.vector(d), 30.0, R_BALL)
            assert got == pytest.approx(expected, abs=TOL)


def test_vertical_corner_edges_and_top_rim_of_a_convex_quad():
    quad = _quad()
    sc = _prism_scenario(quad)
    scene, part = build_scene(sc), Part(sc)
    edges = _edges(quad)
    for k, v in enumerate(quad):
        v = np.asarray(v, float)
        n_in, n_out = edges[k - 1][3], edges[k][3]       # normals of the two faces at vertex k
        bisector = (n_in + n_out) / np.linalg.norm(n_in + n_out)
        c0 = np.array([*(v + 10.0 * bisector), -20.0])
        d = np.array([*(-bisector), 0.0])
        got = scene.first_contact(part.point(c0), part.vector(d), 20.0, R_BALL)
        assert got == pytest.approx(10.0 - R_BALL, abs=TOL)            # the ball meets the edge line
    # down beside a face within the ball radius: the ball meets the top rim, z = sqrt(r² − h²)
    a, b, u, n = edges[0]
    for h in (0.5, 1.0, 1.9):
        c0 = np.array([*(a + 40.0 * u + h * n), 10.0])
        got = scene.first_contact(part.point(c0), part.vector([0, 0, -1]), 20.0, R_BALL)
        assert got == pytest.approx(10.0 - math.sqrt(R_BALL**2 - h**2), abs=TOL)
    # the top face, also near the acute 60° corner
    inside = np.asarray(quad[0]) + 6.0 * (edges[0][2] + edges[3][2] * -1.0) / 2
    for p2 in (inside, np.mean(np.asarray(quad), axis=0)):
        c0 = np.array([*p2, 15.0])
        got = scene.first_contact(part.point(c0), part.vector([0, 0, -1]), 30.0, R_BALL)
        assert got == pytest.approx(15.0 - R_BALL, abs=TOL)


def test_inside_corners_of_a_non_convex_prism():
    polygon, notches = _notched()
    sc = _prism_scenario(polygon[::-1])                 # given clockwise: normalised
    scene, part = build_scene(sc), Part(sc)
    for apex, alpha in notches:
        # down the notch's bisector (−y) towards the apex: both walls at r when the centre is
        # r / sin(α/2) from the apex
        c0 = np.array([apex[0], apex[1] + 20.0, -10.0])
        got = scene.first_contact(part.point(c0), part.vector([0, -1, 0]), 30.0, R_BALL)
        assert got == pytest.approx(20.0 - R_BALL / math.sin(math.radians(alpha / 2)), abs=TOL)
        assert _interior_angle(polygon, polygon.index(tuple(apex))) == pytest.approx(360.0 - alpha, abs=1e-9)
    # each notch wall head-on at its middle and towards both of its ends
    for k, (a, b, u, n) in enumerate(_edges(polygon)):
        length = float(np.linalg.norm(b - a))
        if not 2 < k < len(polygon) - 2:               # the bar's own sides are ordinary faces
            continue
        for t in (length / 2, length / 2 - 5.0, length / 2 + 5.0):
            p_face = np.array([*(a + t * u), -20.0])
            nz = np.array([*n, 0.0])
            c0 = p_face + (R_BALL + 1.5) * nz
            expected = plane_contact(c0, -nz, p_face, nz, R_BALL)
            got = scene.first_contact(part.point(c0), part.vector(-nz), 10.0, R_BALL)
            assert got == pytest.approx(expected, abs=TOL)


def _distance_to_polygon(p2, polygon) -> float:
    best = math.inf
    for a, b, _u, _n in _edges(polygon):
        t = min(max((p2 - a) @ (b - a) / ((b - a) @ (b - a)), 0.0), 1.0)
        best = min(best, float(np.linalg.norm(p2 - a - t * (b - a))))
    return best


def _inside(p2, polygon) -> bool:
    inside = False
    for i, a in enumerate(polygon):
        b = polygon[(i + 1) % len(polygon)]
        if (a[1] > p2[1]) != (b[1] > p2[1]):
            x = a[0] + (p2[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1])
            inside ^= p2[0] < x
    return inside


@pytest.mark.parametrize("which", ["quad", "notched"])
def test_distance_outside_is_exact(which):
    polygon = _quad() if which == "quad" else _notched()[0]
    sc = _prism_scenario(polygon)
    scene, part = build_scene(sc), Part(sc)
    rng = np.random.default_rng(11)
    lo, hi = np.min(polygon, axis=0) - 15.0, np.max(polygon, axis=0) + 15.0
    checked = 0
    while checked < 200:
        p2 = rng.uniform(lo, hi)
        z = rng.choice([-HEIGHT / 2, rng.uniform(0.0, 10.0), rng.uniform(-HEIGHT - 10.0, -HEIGHT)])
        inside = _inside(p2, polygon)
        w = -1.0 if inside else _distance_to_polygon(p2, polygon)
        dz = max(z, -HEIGHT - z)                         # above the top or below the bottom (> 0)
        if inside and dz <= 0.0:
            assert scene.sdf(part.point([*p2, z])) < 0.0
            continue
        expected = math.hypot(max(w, 0.0), max(dz, 0.0))
        assert scene.sdf(part.point([*p2, z])) == pytest.approx(expected, abs=1e-12)
        checked += 1


def _first_touch_2d(c0, d, polygon, r) -> float | None:
    """First s >= 0 where a disc of radius r at c0 + s·d (outside the polygon) touches it: the
    disc centre meets an edge offset by r (within the edge) or a circle of r about a vertex."""
    best = math.inf
    for a, b, u, n in _edges(polygon):
        denom = n @ d
        if denom < 0.0:                                  # moving towards the edge's outer side
            s = (r - n @ (c0 - a)) / denom
            t = (c0 + s * d - a) @ u
            if s >= 0.0 and 0.0 <= t <= np.linalg.norm(b - a):
                best = min(best, s)
        p = c0 - a                                       # the vertex a
        bq, cq = p @ d, p @ p - r * r
        disc = bq * bq - cq
        if disc >= 0.0 and -bq - math.sqrt(disc) >= 0.0:
            best = min(best, -bq - math.sqrt(disc))
    return None if best == math.inf else best


def test_random_sweeps_past_a_non_convex_prism():
    """Moves in the plane from outside in any direction, across notches and past corners."""
    polygon, _ = _notched()
    sc = _prism_scenario(polygon)
    scene, part = build_scene(sc), Part(sc)
    rng = np.random.default_rng(8)
    hits = 0
    for _ in range(600):
        c2 = rng.uniform([-30.0, 30.0], [430.0, 130.0])
        if _inside(c2, polygon) or _distance_to_polygon(c2, polygon) < R_BALL + 0.05:
            continue
        ang = rng.uniform(0, 2 * np.pi)
        d2 = np.array([math.cos(ang), math.sin(ang)])
        expected = _first_touch_2d(c2, d2, polygon, R_BALL)
        if expected is not None and expected > 150.0:
            expected = None
        got = scene.first_contact(part.point([*c2, -25.0]), part.vector([*d2, 0.0]), 150.0, R_BALL)
        if expected is None:
            assert got is None
        else:
            hits += 1
            assert got == pytest.approx(expected, abs=TOL)
    assert hits > 80


def test_clockwise_and_counter_clockwise_are_the_same_part():
    polygon, _ = _notched()
    sc = _prism_scenario(polygon)
    ccw, cw, part = build_scene(sc), build_scene(_prism_scenario(polygon[::-1])), Part(sc)
    rng = np.random.default_rng(3)
    for _ in range(100):
        p = part.point([*rng.uniform([-20, -20], [420, 120]), rng.uniform(-60, 10)])
        assert ccw.sdf(p) == cw.sdf(p)


@pytest.mark.parametrize("polygon", [_quad(), _notched()[0], [(0, 0), (10, 0), (10, 10), (5, 3), (0, 10)],
                                     [(0, 0), (50, 0), (50, 50), (25, 50), (0, 50)]])   # a straight vertex
def test_convex_pieces_cover_the_polygon(polygon):
    pieces = convex_pieces(polygon)
    assert sum(polygon_area(p) for p in pieces) == pytest.approx(abs(polygon_area(polygon)), rel=1e-12)
    for piece in pieces:
        assert polygon_area(piece) > 0
        for k in range(len(piece)):
            a, b, c = (np.asarray(piece[i % len(piece)]) for i in (k - 1, k, k + 1))
            assert (b - a)[0] * (c - b)[1] - (b - a)[1] * (c - b)[0] >= -1e-9     # convex
    assert len(convex_pieces(_quad())) == 1


def test_holes_pockets_and_bosses_in_a_prism():
    quad = _quad()
    sc = _prism_scenario(quad, {"type": "hole", "center": [50, 20], "diameter": 12, "depth": 20},
                         {"type": "hole", "center": [90, 30], "diameter": 10, "depth": 80},
                         {"type": "boss", "center": [60, 45], "size": [10, 8], "height": 6})
    scene, part = build_scene(sc), Part(sc)
    axis = np.array([50.0, 20.0, -10.0])
    for ang in np.linspace(0, 2 * np.pi, 9)[:-1]:
        d = np.array([math.cos(ang), math.sin(ang), 0.0])
        assert scene.first_contact(part.point(axis), part.vector(d), 20.0, R_BALL) == pytest.approx(6.0 - R_BALL,
                                                                                                     abs=TOL)
    assert scene.first_contact(part.point([50, 20, 10]), part.vector([0, 0, -1]), 60.0, R_BALL) == pytest.approx(
        30.0 - R_BALL, abs=TOL)                                                          # the hole bottom
    assert scene.first_contact(part.point([90, 30, 10]), part.vector([0, 0, -1]), 100.0, R_BALL) is None  # through
    assert scene.first_contact(part.point([60, 45, 20]), part.vector([0, 0, -1]), 30.0, R_BALL) == pytest.approx(
        14.0 - R_BALL, abs=TOL)                                                          # the boss top


def test_probing_a_prism_face_with_the_machine():
    quad = _quad()
    pre = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006, "Z-": 0.002}
    pose = {"trans": [250.0, 180.0, -140.0], "rot": [0.0, 0.0, 0.0]}
    sc = scenario(probe={"t": 9, "ball_diameter": 4.0, "length": 100.0, "max_deflection": 5.0,
                         "pretravel": pre, "eccentricity": [0.01, -0.004]},
                  workpiece={"pose": pose, "features": [{"type": "prism", "polygon": [list(p) for p in quad],
                                                         "height": HEIGHT}]})
    part = Part(sc)
    a, b, u, n = _edges(quad)[1]                        # the face between the 120° and 75° corners
    p_face = part.point([*(a + 0.5 * (b - a)), -20.0])
    nz = part.vector([*n, 0.0])
    m = SimulatedMachine(sc)
    m.spindle_position(90.0)
    e = np.array([0.004, 0.01, 0.0])                     # Rz(90°)·(0.01, −0.004)
    centre0 = p_face + (R_BALL + 5.0) * nz
    axes0 = centre0 - e + np.array([0.0, 0.0, 100.0])
    m.goto({"X": float(axes0[0]), "Y": float(axes0[1])})
    m.goto({"Z": float(axes0[2])})
    d = -nz
    r = m.probe(d, 10.0, 300.0)
    dp = np.array([d[1], -d[0]])                         # d in the probe frame at SPOS 90: Rz(−90°)·d
    p = dp[0] ** 2 * pre["X+" if dp[0] > 0 else "X-"] + dp[1] ** 2 * pre["Y+" if dp[1] > 0 else "Y-"]
    expected = axes0 + (plane_contact(centre0, d, p_face, nz, R_BALL) + p) * d
    assert np.array([r.latched_mcs[k] for k in "XYZ"]) == pytest.approx(expected, abs=1e-12)


def test_outline_has_the_prism_polygon():
    polygon, _ = _notched()
    sc = _prism_scenario(polygon[::-1])
    part = Part(sc)
    view = outline(sc)
    assert view["block"] is None
    prism = view["prism"]
    assert prism["kind"] == "prism" and prism["height"] == HEIGHT
    assert np.array(prism["top"]) == pytest.approx(np.array([part.point([x, y, 0.0]) for x, y in polygon]), abs=1e-12)
    assert np.array(prism["bottom"]) == pytest.approx(np.array([part.point([x, y, -HEIGHT]) for x, y in polygon]),
                                                      abs=1e-12)
    assert prism["axis"] == pytest.approx(part.vector([0, 0, 1]), abs=1e-15)
    geometry = SimulatedMachine(sc).scene_geometry()
    assert geometry["prism"]["top"] == prism["top"] and geometry["spheres"] == []


@pytest.mark.parametrize("polygon, message", [
    ([[0, 0], [10, 0]], "at least 3 vertices"),
    ([[math.cos(k / 20), math.sin(k / 20)] for k in range(101)], "at most 100 vertices"),
    ([[0, 0], [10, 0], [0, 10], [10, 10]], "intersect"),                         # a bow tie
    ([[0, 0], [20, 0], [20, 20], [10, -5], [0, 20]], "intersect"),
    ([[0, 0], [10, 0], [10, 0], [0, 10]], "coincide"),
    ([[0, 0], [10, 0], [5, 0], [0, 10]], "fold back"),                            # a spike
    ([[0, 0], [10, 0], [20, 0]], "fold back|no area"),
    ([[0, 0], [10, 0], [10, 10], [10, 5], [0, 10]], "fold back|intersect"),
    ([[0, 0], [10, 0], [10, 10], [5, 0], [0, 10]], "intersect"),                  # a vertex on an edge
])
def test_bad_polygons_are_refused_naming_the_field(polygon, message):
    with pytest.raises(ValueError, match=message) as err:
        _prism_scenario(polygon)
    assert "workpiece.features.0.prism.polygon" in str(err.value)


def test_one_base_per_part_and_features_need_one():
    quad = [list(p) for p in _quad()]
    with pytest.raises(ValueError, match="at most one block or prism"):
        scenario(workpiece={"features": [{"type": "block", "size": [10, 10, 10]},
                                         {"type": "prism", "polygon": quad, "height": 5}]})
    with pytest.raises(ValueError, match="need a block or prism"):
        scenario(workpiece={"features": [{"type": "hole", "center": [1, 1], "diameter": 1, "depth": 1}]})
    with pytest.raises(ValueError, match="prism.height"):
        scenario(workpiece={"features": [{"type": "prism", "polygon": quad, "height": 0}]})
    with pytest.raises(ValueError, match="prism.side"):
        scenario(workpiece={"features": [{"type": "prism", "polygon": quad, "height": 5, "side": 1}]})
