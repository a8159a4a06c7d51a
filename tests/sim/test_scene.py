"""Contact geometry against analytic truth (numbers computed from geometry here)."""

import numpy as np
import pytest
from sim_helpers import circle_contact_inside, circle_contact_outside, plane_contact, rotation, scenario

from app.machine.scene import build_scene

R_BALL = 2.0
TOL = 1e-9


def _pose(sc):
    pose = sc.workpiece.pose
    rot = rotation(pose.rot)
    return rot, np.asarray(pose.trans, float)


def test_axis_parallel_faces_of_rotated_block():
    sc = scenario()
    scene = build_scene(sc)
    rot, trans = _pose(sc)
    lx, ly = 200.0, 120.0
    # (point on face in part coords, outward normal in part coords)
    faces = [((0, 60, -30), (-1, 0, 0)), ((lx, 60, -30), (1, 0, 0)), ((100, 0, -30), (0, -1, 0)),
             ((100, ly, -30), (0, 1, 0)), ((100, 90, 0), (0, 0, 1))]
    for p_part, n_part in faces:
        n = rot @ np.asarray(n_part, float)
        p_face = rot @ np.asarray(p_part, float) + trans
        c0 = p_face + 20.0 * n
        d = -n                                   # straight onto the face (oblique in MCS)
        expected = plane_contact(c0, d, p_face, n, R_BALL)
        assert expected == pytest.approx(18.0)
        assert scene.first_contact(c0, d, 40.0, R_BALL) == pytest.approx(expected, abs=TOL)


def test_oblique_directions_onto_faces():
    sc = scenario()
    scene = build_scene(sc)
    rot, trans = _pose(sc)
    rng = np.random.default_rng(1)
    n = rot @ np.array([0.0, -1.0, 0.0])              # front face y = 0
    p_face = rot @ np.array([100.0, 0.0, -30.0]) + trans
    for _ in range(30):
        d = -n + rng.uniform(-0.6, 0.6, 3)
        d /= np.linalg.norm(d)
        c0 = p_face + 10.0 * n - 5.0 * d             # contact point stays well inside the face
        expected = plane_contact(c0, d, p_face, n, R_BALL)
        assert scene.first_contact(c0, d, 60.0, R_BALL) == pytest.approx(expected, abs=TOL)


def test_tilted_top_face():
    sc = scenario(workpiece={"pose": {"trans": [200.0, 150.0, -150.0], "rot": [3.0, -2.0, 10.0]},
                             "features": [{"type": "block", "size": [200, 120, 60]}]})
    scene = build_scene(sc)
    rot, trans = _pose(sc)
    n = rot @ np.array([0.0, 0.0, 1.0])
    for x, y in [(20, 20), (100, 60), (180, 100)]:
        p_top = rot @ np.array([x, y, 0.0]) + trans
        c0 = p_top + np.array([0.0, 0.0, 30.0])
        d = np.array([0.0, 0.0, -1.0])
        expected = plane_contact(c0, d, p_top, n, R_BALL)
        assert scene.first_contact(c0, d, 60.0, R_BALL) == pytest.approx(expected, abs=TOL)


def test_inside_ring_bore_random_angles():
    sc = scenario()
    scene = build_scene(sc)
    centre = np.array([700.0, 100.0])
    rng = np.random.default_rng(2)
    for _ in range(40):
        c0 = np.array([*centre + rng.uniform(-3, 3, 2), -210.0])
        ang = rng.uniform(0, 2 * np.pi)
        d = np.array([np.cos(ang), np.sin(ang), 0.0])
        expected = circle_contact_inside(c0[:2], d[:2], centre, 12.5 - R_BALL)
        assert scene.first_contact(c0, d, 30.0, R_BALL) == pytest.approx(expected, abs=TOL)


def test_inside_hole_of_rotated_block():
    sc = scenario()
    scene = build_scene(sc)
    rot, trans = _pose(sc)
    axis_point = rot @ np.array([40.0, 30.0, -12.0]) + trans
    for ang in np.linspace(0, 2 * np.pi, 13)[:-1]:
        d = rot @ np.array([np.cos(ang), np.sin(ang), 0.0])
        assert scene.first_contact(axis_point, d, 30.0, R_BALL) == pytest.approx(10.0 - R_BALL, abs=TOL)
    # hole bottom from above (depth 25)
    above = rot @ np.array([40.0, 30.0, 20.0]) + trans
    assert scene.first_contact(above, [0, 0, -1], 80.0, R_BALL) == pytest.approx(20 + 25 - R_BALL, abs=TOL)


def test_spigot_from_four_sides():
    sc = scenario()
    scene = build_scene(sc)
    rot, trans = _pose(sc)
    centre_part = np.array([150.0, 60.0])
    for ang in (0.0, 90.0, 180.0, 270.0):
        u = np.array([np.cos(np.radians(ang)), np.sin(np.radians(ang))])
        start_part = np.array([*(centre_part + 30.0 * u), 8.0])        # beside the spigot, 8 mm up
        c0 = rot @ start_part + trans
        d = rot @ np.array([-u[0], -u[1], 0.0])
        expected = circle_contact_outside((c0 - trans) @ rot[:, :2], (rot.T @ d)[:2], centre_part, 15 + R_BALL)
        assert expected == pytest.approx(30 - 17)
        assert scene.first_contact(c0, d, 40.0, R_BALL) == pytest.approx(expected, abs=TOL)


def test_free_air_and_grazing_parallel_move():
    sc = scenario()
    scene = build_scene(sc)
    rot, trans = _pose(sc)
    assert scene.first_contact([0, 0, 50], [1, 0, 0], 300, R_BALL) is None
    # parallel to the top face, 1e-6 above touching height, across the whole block: no contact
    c0 = rot @ np.array([-10.0, 100.0, R_BALL + 1e-6]) + trans
    assert scene.first_contact(c0, rot @ np.array([1.0, 0, 0]), 220.0, R_BALL) is None
    # 1e-6 below touching height: contact where the ball reaches the front edge region
    c0 = rot @ np.array([-10.0, 100.0, R_BALL - 1e-6]) + trans
    s = scene.first_contact(c0, rot @ np.array([1.0, 0, 0]), 220.0, R_BALL)
    expected = 10.0 - np.sqrt(R_BALL**2 - (R_BALL - 1e-6) ** 2)     # ball meets the block edge
    assert s == pytest.approx(expected, abs=1e-8)


def test_start_in_contact_may_leave_but_not_press_deeper():
    sc = scenario()
    scene = build_scene(sc)
    rot, trans = _pose(sc)
    n = rot @ np.array([0.0, 0.0, 1.0])
    c0 = rot @ np.array([100.0, 90.0, R_BALL - 0.3]) + trans          # 0.3 mm deflected on the top
    assert scene.first_contact(c0, n, 20.0, R_BALL) is None           # retract
    assert scene.first_contact(c0, -n, 20.0, R_BALL) == 0.0           # deeper: contact at once
    side = rot @ np.array([0.0, -1.0, 0.0])
    assert scene.first_contact(c0, side, 20.0, R_BALL) is None        # slide along the face


def test_pocket_walls_floor_and_boss_faces():
    sc = scenario(workpiece={"pose": {"trans": [200.0, 150.0, -150.0], "rot": [0.0, 0.0, -8.0]},
                             "features": [{"type": "block", "size": [200, 120, 60]},
                                          {"type": "pocket", "center": [50, 60], "size": [40, 30], "depth": 15},
                                          {"type": "boss", "center": [150, 60], "size": [30, 20], "height": 10}]})
    scene = build_scene(sc)
    rot, trans = _pose(sc)
    inside = rot @ np.array([50.0, 60.0, -8.0]) + trans
    for u, half in (((1, 0, 0), 20.0), ((-1, 0, 0), 20.0), ((0, 1, 0), 15.0), ((0, -1, 0), 15.0)):
        d = rot @ np.asarray(u, float)
        assert scene.first_contact(inside, d, 40.0, R_BALL) == pytest.approx(half - R_BALL, abs=TOL)
    assert scene.first_contact(inside, [0, 0, -1], 40.0, R_BALL) == pytest.approx(7.0 - R_BALL, abs=TOL)
    beside = rot @ np.array([110.0, 60.0, 5.0]) + trans        # boss spans x 135..165, 10 high
    assert scene.first_contact(beside, rot @ np.array([1.0, 0, 0]), 40.0, R_BALL) == pytest.approx(
        25.0 - R_BALL, abs=TOL)
    above = rot @ np.array([150.0, 60.0, 30.0]) + trans
    assert scene.first_contact(above, [0, 0, -1], 40.0, R_BALL) == pytest.approx(20.0 - R_BALL, abs=TOL)
