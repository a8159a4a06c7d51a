"""The start guard's signed distances in plain floats (engine.guard ``distance``, issue 30 item 3)
against analytic geometry, and equal to the vectorised ``sdf`` they stand in for."""

from __future__ import annotations

import math

import numpy as np
import pytest

from engine.guard import Body, ProtectionModel, Solid, first_contact

BLOCK = Solid("workpiece", centre=np.array([100.0, 60.0, -30.0]),
              polygon=np.array([[-100.0, -60.0], [100.0, -60.0], [100.0, 60.0], [-100.0, 60.0]]),
              half_height=30.0)
# a cut-out reaches beyond the top face, as the machine's model has it (no lid of material left)
HOLE = Solid("hole", centre=np.array([30.0, 25.0, 0.0]), radius=6.0, half_height=25.0)
BALL = Solid("sphere", centre=np.array([300.0, 0.0, 10.0]), radius=5.0, sphere=True)
MODEL = ProtectionModel((Body(BLOCK, (HOLE,)), Body(BALL)), {})


@pytest.mark.parametrize(("point", "expected", "name"), [
    ((100.0, 60.0, 5.0), 5.0, "workpiece"),            # 5 above the top face
    ((30.0, 25.0, -10.0), 6.0, "workpiece"),           # on the hole's axis, 10 deep: its wall 6 away
    ((33.0, 25.0, -10.0), 3.0, "workpiece"),           # 3 off the axis
    ((-3.0, -4.0, 0.0), 5.0, "workpiece"),             # beyond the corner edge (0, 0, 0): 3-4-5
    ((100.0, 60.0, -40.0), -20.0, "workpiece"),        # inside: the bottom face 20 away, the top 40
    ((300.0, 0.0, 25.0), 10.0, "sphere"),              # 15 above the sphere's centre, radius 5
])
def test_distance_is_the_geometry(point, expected, name):
    value, body = MODEL.distance(*point)
    assert value == pytest.approx(expected, abs=1e-9)
    assert body == name


def test_plain_floats_equal_the_vectorised_sdf():
    rng = np.random.default_rng(7)
    rotation = np.array([[math.cos(0.3), -math.sin(0.3), 0.0], [math.sin(0.3), math.cos(0.3), 0.0], [0, 0, 1]])
    turned = Solid("prism", centre=np.array([10.0, -5.0, 2.0]), rotation=rotation,
                   polygon=np.array([[0.0, 0.0], [20.0, 0.0], [25.0, 15.0], [5.0, 10.0]]), half_height=4.0)
    points = rng.uniform([-40, -40, -70], [340, 140, 40], size=(400, 3))
    for solid in (BLOCK, HOLE, BALL, turned):
        vector = solid.sdf(points)
        plain = [solid.distance(*p) for p in points]
        assert np.allclose(plain, vector, atol=1e-9)
    body = MODEL.bodies[0]
    assert np.allclose([body.distance(*p) for p in points], body.sdf(points), atol=1e-9)


def test_first_contact_of_a_ball_moving_down_onto_the_top_face():
    # a ball of radius 2 from 20 above the top face straight down: it touches when its centre is 2 above
    hit = first_contact(MODEL, (150.0, 90.0, 20.0), (150.0, 90.0, -5.0), 2.0)
    assert hit is not None
    assert hit[0] == pytest.approx(18.0, abs=1e-6) and hit[1] == "workpiece"
    # down the hole's axis the way is free (wall 6 away, ball radius 2)
    assert first_contact(MODEL, (30.0, 25.0, 20.0), (30.0, 25.0, -10.0), 2.0) is None
