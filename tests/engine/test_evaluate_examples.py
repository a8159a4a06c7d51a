"""Worked examples of spec/measuring-math.md reproduced by engine.evaluate.

Latched values are the spec's (printed to 3-6 decimals); surfaces use the spec's point-wise
rule s_j = c_j − t(dir) (measuring-math §5.3), written out here, not taken from the engine.
"""

from __future__ import annotations

import numpy as np
import pytest

from engine.compensation import make_touch
from engine.planes import PLANES
from engine.tasks import evaluate
from engine.types import CirclePoint, EdgePoint, ProbeRecord, Touch

G17 = PLANES["G17"]
AXIS = {"X": 0, "Y": 1, "Z": 2}


def touch(centre, key: str, t: float) -> Touch:
    """Axis-parallel touch: travel ``key`` ("X+"...), surface s_j = c_j − t (§5.3)."""
    c = np.array(centre, dtype=float)
    j, sign = AXIS[key[0]], (1.0 if key[1] == "+" else -1.0)
    d = np.zeros(3)
    d[j] = sign
    s = c.copy()
    s[j] = c[j] - t
    return Touch(ball_centre=c, direction=d, surface=s)


def test_8_5_A_bore_with_direction_dependent_pretravel():
    """§8.5-A: t(−X)=2.990, t(+X)=−2.994, t(−Y)=2.992, t(+Y)=−2.996, e = 0."""
    probe = ProbeRecord(ball_diameter=6.0, trigger={"X-": 2.990, "X+": -2.994, "Y-": 2.992,
                                                    "Y+": -2.996})
    touches = (touch((243.056, 130.0, 0.0), "X+", -2.994), touch((117.020, 130.0, 0.0), "X-", 2.990),
               touch((180.040, 192.984, 0.0), "Y+", -2.996), touch((180.040, 66.952, 0.0), "Y-", 2.992))
    res = evaluate("hole.1", {"diameter": 132.0}, [CirclePoint(np.zeros(3), 0.0, touches)], G17, probe)
    assert res.values["center"] == pytest.approx({"X": 180.040, "Y": 129.970}, abs=1e-9)
    assert res.values["diameter"] == pytest.approx(132.020, abs=1e-9)
    # G54 translation += (0.040, −0.030) for setpoint (180, 130): the fix carries the centre
    assert res.fix.position == pytest.approx({"X": 180.040, "Y": 129.970}, abs=1e-9)


def test_8_5_A_through_make_touch():
    """Same latches compensated by engine.compensation.make_touch (integration)."""
    probe = ProbeRecord(ball_diameter=6.0, trigger={"X-": 2.990, "X+": -2.994, "Y-": 2.992,
                                                    "Y+": -2.996})
    raw = [((243.056, 130.0, 0.0), (1, 0, 0)), ((117.020, 130.0, 0.0), (-1, 0, 0)),
           ((180.040, 192.984, 0.0), (0, 1, 0)), ((180.040, 66.952, 0.0), (0, -1, 0))]
    touches = tuple(make_touch(np.array(r), np.array(d, float), probe, G17) for r, d in raw)
    res = evaluate("hole.1", {}, [CirclePoint(np.zeros(3), 0.0, touches)], G17, probe)
    assert res.values["center"] == pytest.approx({"X": 180.040, "Y": 129.970}, abs=1e-9)
    assert res.values["diameter"] == pytest.approx(132.020, abs=1e-9)


def test_10_A_three_point_bore_at_an_angle():
    """§10-A: 3 ball centres on rays at 15°, 95°, 175°, ρ = 2.990 -> (180.020, −0.015), Ø130.040."""
    probe = ProbeRecord(ball_diameter=6.0, effective_diameter=5.980)
    centres = [(239.931286, 16.058540), (174.595184, 61.777332), (118.227195, 5.404420)]
    touches = []
    for (x, y), ang in zip(centres, (15.0, 95.0, 175.0), strict=True):
        d = np.array([np.cos(np.radians(ang)), np.sin(np.radians(ang)), 0.0])
        c = np.array([x, y, 0.0])
        touches.append(Touch(ball_centre=c, direction=d, surface=c + 2.990 * d))
    res = evaluate("hole.1", {}, [CirclePoint(np.zeros(3), 0.0, tuple(touches))], G17, probe)
    assert res.values["center"] == pytest.approx({"X": 180.020, "Y": -0.015}, abs=1e-5)
    assert res.values["diameter"] == pytest.approx(130.040, abs=1e-5)


def test_11_1_A_align_edge():
    """§11.1-A: travel +Y, t(+Y) = −2.996, ball centres y1 at X−20, y2 at X20 -> alpha 1.5°."""
    probe = ProbeRecord(ball_diameter=6.0, trigger={"Y+": -2.996})
    pts = [EdgePoint(touch((-20.0, -20.997027, 0.0), "Y+", -2.996)),
           EdgePoint(touch((20.0, -19.949590, 0.0), "Y+", -2.996))]
    res = evaluate("edge.align", {"axis": "Y", "direction": "+", "reference_axis": "X",
                                  "angle_correction": "rotation"}, pts, G17, probe)
    assert res.values["angle"] == pytest.approx(1.5, abs=1e-4)
    assert res.fix.angle == pytest.approx(1.5, abs=1e-4)
    assert res.fix.angle_axis == "Z"


def test_12_A_any_corner_line_offset_rule():
    """§12-A: ball centres (ρ = 2.99, P1/P2 +Y, P3/P4 +X) -> K = (20, 30), φ = 2°.

    The point-wise rule would be 0.0018 mm off in S1_y. The example puts the ball centres at ρ
    along the normal; the engine models the overtravel along the travel (design.md §5), which
    differs from the example by δ(1 − cos 2°) ≈ 6e-6 mm.
    """
    probe = ProbeRecord(ball_diameter=6.0, trigger={"X+": -2.99, "Y+": -2.99})
    pts = [EdgePoint(touch((50.0, 28.055801, 0.0), "Y+", -2.99)),
           EdgePoint(touch((150.0, 31.547877, 0.0), "Y+", -2.99)),
           EdgePoint(touch((16.658970, 40.0, 0.0), "X+", -2.99)),
           EdgePoint(touch((15.262139, 80.0, 0.0), "X+", -2.99))]
    res = evaluate("corner.any", {"kind": "outside", "position": 1}, pts, G17, probe)
    assert res.values["corner"] == pytest.approx({"X": 20.0, "Y": 30.0}, abs=2e-5)
    assert res.values["angle"] == pytest.approx(2.0, abs=1e-5)
    assert res.fix.position == pytest.approx({"X": 20.0, "Y": 30.0}, abs=2e-5)
    assert res.fix.angle_axis == "Z" and res.fix.reference_axis == "X"


def test_12_A_right_angled_corner_with_p3():
    """§12-A geometry with the right-angled variant: the second edge is the perpendicular
    through P3; with the 92° second edge it is exact only for the true 90° corner, so build
    a true 90° corner at (20, 30), reference edge 2°, P3 at Y40."""
    probe = ProbeRecord(ball_diameter=6.0, trigger={"X+": -2.99, "Y+": -2.99})
    phi = np.radians(2.0)
    u1, u2 = np.array([np.cos(phi), np.sin(phi)]), np.array([-np.sin(phi), np.cos(phi)])
    k = np.array([20.0, 30.0])

    def ball_on(u, n_free, coord_index, value, travel):
        # first contact at the ball radius 3.0, then 0.01 overtravel along the travel (design §5)
        base = k + 3.0 * n_free
        lam = (value - base[coord_index]) / u[coord_index]
        return base + lam * u + 0.01 * travel

    c1 = ball_on(u1, -u2, 0, 50.0, np.array([0.0, 1.0]))
    c2 = ball_on(u1, -u2, 0, 150.0, np.array([0.0, 1.0]))
    c3 = ball_on(u2, -u1, 1, 40.0, np.array([1.0, 0.0]))
    pts = [EdgePoint(touch((*c1, 0.0), "Y+", -2.99)), EdgePoint(touch((*c2, 0.0), "Y+", -2.99)),
           EdgePoint(touch((*c3, 0.0), "X+", -2.99))]
    res = evaluate("corner.right", {"kind": "outside", "position": 1}, pts, G17, probe)
    assert res.values["corner"] == pytest.approx({"X": 20.0, "Y": 30.0}, abs=1e-9)
    assert res.values["angle"] == pytest.approx(2.0, abs=1e-9)
