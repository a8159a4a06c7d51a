"""Sphere features (design.md §9.8): exact contact against the analytic ray–sphere intersection."""

import math

import numpy as np
import pytest
from sim_helpers import plane_contact, rotation, scenario

from app.machine.scene import build_scene, outline
from app.machine.sim import SimulatedMachine

R_BALL = 2.0
TOL = 1e-9
POSE = {"trans": [300.0, 200.0, -150.0], "rot": [1.5, -2.0, 30.0]}
CENTRE = np.array([60.0, 40.0, 30.0])           # part coordinates
DIAMETER = 25.0


def _sphere_scenario(*features, pose=POSE, **overrides):
    return scenario(workpiece={"pose": pose, "features": list(features)}, **overrides)


def _ball_hits_sphere(c0, d, centre, reach) -> float | None:
    """Smallest s >= 0 with |c0 + s·d − centre| = reach (start outside)."""
    p = np.asarray(c0, float) - centre
    b, c = p @ d, p @ p - reach * reach
    disc = b * b - c
    if disc < 0.0:
        return None
    s = -b - math.sqrt(disc)
    return s if s >= 0.0 else None


def _mcs(p_part) -> np.ndarray:
    return rotation(POSE["rot"]) @ np.asarray(p_part, float) + np.asarray(POSE["trans"], float)


def test_a_sphere_alone_from_every_side_and_at_random():
    sc = _sphere_scenario({"type": "sphere", "center": list(CENTRE), "diameter": DIAMETER})
    scene = build_scene(sc)
    centre = _mcs(CENTRE)
    reach = DIAMETER / 2 + R_BALL
    for d in ([1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, -1], [0, 0, 1]):
        d = np.asarray(d, float)
        c0 = centre - 30.0 * d
        assert scene.first_contact(c0, d, 40.0, R_BALL) == pytest.approx(30.0 - reach, abs=TOL)
    rng = np.random.default_rng(9)
    hits = 0
    for _ in range(200):
        c0 = centre + rng.uniform(-40, 40, 3)
        if np.linalg.norm(c0 - centre) <= reach + 0.01:
            continue
        d = (centre - c0) / np.linalg.norm(centre - c0) + rng.normal(scale=0.4, size=3)   # near it or past it
        d /= np.linalg.norm(d)
        expected = _ball_hits_sphere(c0, d, centre, reach)
        if expected is not None and expected > 80.0:
            expected = None
        got = scene.first_contact(c0, d, 80.0, R_BALL)
        if expected is None:
            assert got is None
        else:
            hits += 1
            assert got == pytest.approx(expected, abs=TOL)
    assert hits > 60


def test_a_sphere_standing_on_a_block():
    """A ball resting on the top face (centre z = R): beside it the top face, the ball itself,
    and the ball between the two (a union: the first of the two exact contacts)."""
    r_s = DIAMETER / 2
    on_top = [60.0, 40.0, r_s]
    sc = _sphere_scenario({"type": "block", "size": [150, 90, 40]},
                          {"type": "sphere", "center": on_top, "diameter": DIAMETER})
    scene = build_scene(sc)
    rot = rotation(POSE["rot"])
    centre = _mcs(on_top)
    up = rot[:, 2]
    # the equator from four sides (part x/y)
    for u in ([1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0]):
        d = rot @ np.asarray(u, float)
        c0 = centre - 30.0 * d
        assert scene.first_contact(c0, d, 40.0, R_BALL) == pytest.approx(30.0 - r_s - R_BALL, abs=TOL)
    # the sphere's top along −part z
    assert scene.first_contact(centre + 40.0 * up, -up, 60.0, R_BALL) == pytest.approx(40.0 - r_s - R_BALL, abs=TOL)
    # going down beside the ball at horizontal distance h from its centre
    top_point = _mcs([60.0, 40.0, 0.0])
    for h in (5.0, 12.0, 14.0, 16.0, 30.0):
        start = _mcs([60.0 + h, 40.0, 40.0])
        candidates = [plane_contact(start, -up, top_point, up, R_BALL),
                      _ball_hits_sphere(start, -up, centre, r_s + R_BALL)]
        expected = min(s for s in candidates if s is not None)
        assert scene.first_contact(start, -up, 60.0, R_BALL) == pytest.approx(expected, abs=TOL)


def test_probing_a_sphere_like_cycle997_with_the_machine():
    pre = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006, "Z-": 0.002}
    ecc = np.array([0.008, -0.003])
    pose = {"trans": [300.0, 200.0, -150.0], "rot": [0.0, 0.0, 0.0]}
    sc = _sphere_scenario({"type": "sphere", "center": list(CENTRE), "diameter": DIAMETER}, pose=pose,
                          probe={"t": 9, "ball_diameter": 4.0, "length": 100.0, "max_deflection": 5.0,
                                 "pretravel": pre, "eccentricity": list(ecc)})
    centre = CENTRE + np.array(pose["trans"])
    reach = DIAMETER / 2 + R_BALL
    e = np.array([*ecc, 0.0])
    moves = [([1, 0, 0], "X+"), ([-1, 0, 0], "X-"), ([0, 1, 0], "Y+"), ([0, -1, 0], "Y-"), ([0, 0, -1], "Z-")]
    for d, key in moves:
        d = np.asarray(d, float)
        m = SimulatedMachine(sc)
        ball0 = centre - (reach + 5.0) * d
        axes0 = ball0 - e + np.array([0.0, 0.0, 100.0])
        m.goto({"Z": 50.0})
        m.goto({"X": float(axes0[0]), "Y": float(axes0[1])})
        m.goto({"Z": float(axes0[2])})
        r = m.probe(d, 10.0, 300.0)
        assert np.array([r.latched_mcs[a] for a in "XYZ"]) == pytest.approx(axes0 + (5.0 + pre[key]) * d, abs=1e-12)


def test_outline_and_machine_view_have_the_spheres():
    sc = _sphere_scenario({"type": "block", "size": [150, 90, 40]},
                          {"type": "sphere", "center": [60, 40, 12.5], "diameter": DIAMETER},
                          {"type": "sphere", "center": [120, 60, 20], "diameter": 10})
    view = outline(sc)
    assert [s["kind"] for s in view["spheres"]] == ["sphere", "sphere"]
    assert view["spheres"][0]["center"] == pytest.approx(_mcs([60, 40, 12.5]), abs=1e-12)
    assert [s["diameter"] for s in view["spheres"]] == [DIAMETER, 10.0]
    assert view["block"] is not None and view["prism"] is None
    assert SimulatedMachine(sc).scene_geometry()["spheres"] == view["spheres"]
    alone = outline(_sphere_scenario({"type": "sphere", "center": [0, 0, 0], "diameter": 20}))
    assert alone["block"] is None and len(alone["spheres"]) == 1


@pytest.mark.parametrize("feature, field", [
    ({"type": "sphere", "center": [0, 0, 0], "diameter": 0}, "sphere.diameter"),
    ({"type": "sphere", "center": [0, 0, 0], "diameter": -5}, "sphere.diameter"),
    ({"type": "sphere", "center": [0, 0], "diameter": 5}, "sphere.center"),
    ({"type": "sphere", "center": [0, 0, float("nan")], "diameter": 5}, "sphere.center"),
    ({"type": "sphere", "center": [0, 0, 0]}, "sphere.diameter"),
    ({"type": "sphere", "center": [0, 0, 0], "diameter": 5, "radius": 2}, "sphere.radius"),
])
def test_bad_spheres_are_refused_naming_the_field(feature, field):
    with pytest.raises(ValueError) as err:
        _sphere_scenario(feature)
    assert f"workpiece.features.0.{field}" in str(err.value)


def test_spheres_need_no_block_but_holes_do():
    sc = _sphere_scenario({"type": "sphere", "center": [0, 0, 0], "diameter": 20})
    assert sc.workpiece.base is None and len(sc.workpiece.spheres) == 1
    with pytest.raises(ValueError, match="need a block or prism"):
        _sphere_scenario({"type": "sphere", "center": [0, 0, 0], "diameter": 20},
                         {"type": "hole", "center": [0, 0], "diameter": 5, "depth": 5})
