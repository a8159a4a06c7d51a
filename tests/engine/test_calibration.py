"""engine.calibration: length and ring calibration, proven by re-measuring other features.

Latches are synthesised from a hidden truth (ring centre, true ball radius, eccentricity
turning with SPOS, pre-travel per direction, latency), the way the simulator defines them
(design.md §5: switch after pre-travel along d, latch v·latency later; rec = true ball centre
− e(φ)). After calibration, compensation (engine.compensation: c = rec + skew, s = c − t)
must give the true surfaces of a different edge and bores/spigots of other diameters.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.calibration import calibrate_length, calibrate_length_point, calibrate_radius
from engine.compensation import make_touch, skew_in_wcs
from engine.frames import Frame, rot_z
from engine.plan_base import RingCalibrationPoint, RingPass
from engine.planes import PLANES
from engine.tasks import evaluate
from engine.types import CirclePoint, EdgePoint, MeasuringError, ProbeRecord, Touch

G17 = PLANES["G17"]
SETTINGS = settings(max_examples=40, deadline=None)
KEYS = ("X+", "X-", "Y+", "Y-")


class Truth:
    """Hidden probe truth, G17, measuring WCS = frame (rotation gamma about Z, translation)."""

    def __init__(self, r_true, e_mcs, delta, lat, gamma, trans=(250.0, 150.0, -120.0)):
        self.r = r_true
        self.e_mcs = np.array([e_mcs[0], e_mcs[1], 0.0])
        self.delta = dict(delta)          # travel past first contact before the switch, per key
        self.lat = lat                    # v·latency, along d
        self.frame = Frame(coarse=np.array(trans), rot=np.array([0.0, 0.0, gamma]))

    def e_wcs(self, spindle_deg):
        return self.frame.dir_parent2child(rot_z(spindle_deg) @ self.e_mcs)

    def rec(self, key, contact_centre_j, spindle_deg=0.0, other=(0.0, 0.0, -5.0)):
        """rec (WCS) of a touch along ``key`` whose ball centre first touches at coordinate
        ``contact_centre_j`` on that axis."""
        j = "XYZ".index(key[0])
        sign = 1.0 if key[1] == "+" else -1.0
        b = np.array(other, dtype=float)
        b[j] = contact_centre_j + sign * (self.delta[key] + self.lat)
        return b - self.e_wcs(spindle_deg)

    def ring_point(self, m, diameter):
        passes = []
        for angle in (180.0, 0.0):
            recs = {}
            for key in KEYS:
                j = "XYZ".index(key[0])
                sign = 1.0 if key[1] == "+" else -1.0
                other = np.array([m[0], m[1], -5.0])
                recs[key] = self.rec(key, m[j] + sign * (diameter / 2 - self.r), angle, other)
            passes.append(RingPass(angle, recs))
        return RingCalibrationPoint(diameter=diameter, search=passes[1], passes=tuple(passes))

    def touch(self, probe, key, contact_centre_j, other):
        j = "XYZ".index(key[0])
        d = np.zeros(3)
        d[j] = 1.0 if key[1] == "+" else -1.0
        rec = self.rec(key, contact_centre_j, 0.0, other)
        return make_touch(rec, d, probe, G17, skew_wcs=skew_in_wcs(probe, self.frame, 0.0))

    def circle(self, probe, m, diameter, kind):
        touches = []
        for key in KEYS:
            j = "XYZ".index(key[0])
            sign = 1.0 if key[1] == "+" else -1.0
            if kind == "hole":
                contact = m[j] + sign * (diameter / 2 - self.r)
            else:
                contact = m[j] - sign * (diameter / 2 + self.r)
            touches.append(self.touch(probe, key, contact, (m[0], m[1], -5.0)))
        return CirclePoint(center=np.zeros(3), diameter=0.0, touches=tuple(touches))


truths = st.builds(
    lambda r, ex, ey, dx, dy, ax, ay, lat, gamma: (r, (ex, ey), (dx, dy), (ax, ay), lat, gamma),
    st.floats(1.9, 3.1), st.floats(-0.05, 0.05), st.floats(-0.05, 0.05),
    st.floats(0.0, 0.01), st.floats(0.0, 0.01), st.floats(-0.003, 0.003), st.floats(-0.003, 0.003),
    st.floats(0.0, 0.03), st.floats(-30.0, 30.0))


def make_truth(params, symmetric: bool) -> Truth:
    r, e, (dx, dy), (ax, ay), lat, gamma = params
    if symmetric:
        ax = ay = 0.0
    delta = {"X+": dx + ax, "X-": dx - ax, "Y+": dy + ay, "Y-": dy - ay}
    return Truth(r, e, delta, lat, gamma)


@SETTINGS
@given(params=truths, ring_m=st.tuples(st.floats(-200, 200), st.floats(-200, 200)),
       ring_d=st.floats(20.0, 120.0), edge=st.floats(-300, 300), bore_m=st.tuples(st.floats(-200, 200),
       st.floats(-200, 200)), bore_d=st.floats(12.0, 200.0))
def test_ring_calibration_recovers_other_features_exactly(params, ring_m, ring_d, edge, bore_m, bore_d):
    """Pre-travel symmetric per axis (different between X and Y), latency, eccentricity, a
    rotated WCS and a wrong nominal ball: the calibrated probe measures exactly."""
    truth = make_truth(params, symmetric=True)
    nominal = ProbeRecord(ball_diameter=6.0)            # DP6 = 3, the true ball differs
    probe, shown = calibrate_radius(truth.ring_point(ring_m, ring_d), nominal, G17, truth.frame)
    assert probe.calibrated_radius
    assert shown["center"]["X"] == pytest.approx(ring_m[0], abs=1e-9)
    assert shown["center"]["Y"] == pytest.approx(ring_m[1], abs=1e-9)
    assert np.allclose(probe.skew, truth.e_mcs[:2], atol=1e-12)
    # a different edge, probed in all four directions
    for key in KEYS:
        sign = 1.0 if key[1] == "+" else -1.0
        j = "XYZ".index(key[0])
        t = truth.touch(probe, key, edge - sign * truth.r, (7.0, -3.0, -5.0))
        assert t.surface[j] == pytest.approx(edge, abs=1e-9)
    # a bore and a spigot of other diameters
    for kind in ("hole", "spigot"):
        res = evaluate(f"{kind}.1", {}, [truth.circle(probe, bore_m, bore_d, kind)], G17, probe)
        assert res.values["center"]["X"] == pytest.approx(bore_m[0], abs=1e-9)
        assert res.values["center"]["Y"] == pytest.approx(bore_m[1], abs=1e-9)
        assert res.values["diameter"] == pytest.approx(bore_d, abs=1e-9)


@SETTINGS
@given(params=truths, ring_d=st.floats(20.0, 120.0), e1=st.floats(-300, 300), e2=st.floats(-300, 300),
       bore_d=st.floats(12.0, 200.0))
def test_ring_calibration_asymmetric_pretravel_limit(params, ring_d, e1, e2, bore_d):
    """δ(+j) ≠ δ(−j): sizes and distances stay exact; every position on axis j is shifted by
    the same k_j = (δ(+j) − δ(−j))/2, which a ring of unknown centre cannot observe."""
    truth = make_truth(params, symmetric=False)
    probe, _ = calibrate_radius(truth.ring_point((10.0, 20.0), ring_d), ProbeRecord(ball_diameter=6.0),
                                G17, truth.frame)
    for axis in "XY":
        k = 0.5 * (truth.delta[f"{axis}+"] - truth.delta[f"{axis}-"])
        j = "XYZ".index(axis)
        s1 = truth.touch(probe, f"{axis}+", e1 - truth.r, (1.0, 2.0, -5.0)).surface[j]
        s2 = truth.touch(probe, f"{axis}-", e2 + truth.r, (1.0, 2.0, -5.0)).surface[j]
        assert s1 == pytest.approx(e1 + k, abs=1e-9)
        assert s2 == pytest.approx(e2 + k, abs=1e-9)
        assert s2 - s1 == pytest.approx(e2 - e1, abs=1e-9)
    res = evaluate("hole.1", {}, [truth.circle(probe, (40.0, -30.0), bore_d, "hole")], G17, probe)
    assert res.values["diameter"] == pytest.approx(bore_d, abs=1e-9)


def test_7_3_A_unknown_centre_example():
    """measuring-math §7.3-A: D = 110.246 -> MP (100.030, 79.980), e (0.012, −0.008), ∓2.990."""
    def v(x):
        return np.array([x, 0.0, 0.0])

    def w(y):
        return np.array([0.0, y, 0.0])

    p180 = RingPass(180.0, {"X+": v(152.175), "X-": v(47.909), "Y+": w(132.105), "Y-": w(27.839)})
    p0 = RingPass(0.0, {"X+": v(152.151), "X-": v(47.885), "Y+": w(132.121), "Y-": w(27.855)})
    point = RingCalibrationPoint(diameter=110.246, search=p0, passes=(p180, p0))
    probe, shown = calibrate_radius(point, ProbeRecord(ball_diameter=6.0), G17)
    assert shown["center"] == pytest.approx({"X": 100.030, "Y": 79.980}, abs=1e-9)
    assert probe.skew == pytest.approx((0.012, -0.008), abs=1e-9)
    assert probe.trigger == pytest.approx({"X+": -2.990, "X-": 2.990, "Y+": -2.990, "Y-": 2.990}, abs=1e-9)
    assert probe.effective_diameter == pytest.approx(5.980, abs=1e-9)


def test_ring_wrong_diameter_alarm():
    p = RingPass(0.0, {"X+": np.array([5.0, 0, 0]), "X-": np.array([-5.0, 0, 0]),
                       "Y+": np.array([0, 5.0, 0]), "Y-": np.array([0, -5.0, 0])})
    point = RingCalibrationPoint(diameter=4.0, search=p, passes=(RingPass(180.0, p.rec), p))
    with pytest.raises(MeasuringError) as err:
        calibrate_radius(point, ProbeRecord(), G17)
    assert err.value.alarm == 61303


def test_7_5_A_length_example():
    """measuring-math §7.5-A: L1_old 50, r 3, _SETVAL 20, rec_z 23.105 -> L1 50.105, t(−Z) = 3."""
    probe, shown = calibrate_length(23.105, 20.0, ProbeRecord(ball_diameter=6.0), 50.0, G17)
    assert shown["length"] == pytest.approx(50.105, abs=1e-12)
    assert probe.trigger["Z-"] == 3.0 and probe.calibrated_length
    tip, shown_tip = calibrate_length(23.105, 20.0, ProbeRecord(ball_diameter=6.0, length_to_tip=True),
                                      50.0, G17)
    assert shown_tip["length"] == pytest.approx(53.105, abs=1e-12)
    assert tip.trigger["Z-"] == 0.0


@SETTINGS
@given(l_true=st.floats(80, 150), l_old=st.floats(80, 150), r_true=st.floats(1.5, 3.5),
       delta=st.floats(0.0, 0.01), z_cal=st.floats(-200, 100), z_other=st.floats(-200, 100),
       plane=st.sampled_from(list(PLANES.values())), tip=st.booleans())
def test_length_calibration_then_measure_other_surface(l_true, l_old, r_true, delta, z_cal, z_other,
                                                       plane, tip):
    """Spindle nose F at the latch: F = z_surface + r_true + L_true + δ (L_true to the ball
    centre). The NC's reference (with L1) is F − L1 (−r more with L1 to the tip)."""
    nominal = ProbeRecord(ball_diameter=6.0, length_to_tip=tip)
    p_hat = plane.infeed_unit

    def point_for(z_surface, length_nc, probe):
        f = z_surface + r_true + l_true + delta
        rec = f - length_nc                                  # the NC's reference point
        centre = rec + (probe.ball_diameter / 2.0 if tip else 0.0)
        c = np.array([3.0, 4.0, 5.0])
        c = c - (c @ p_hat) * p_hat + centre * p_hat
        return EdgePoint(Touch(ball_centre=c, direction=-p_hat, surface=c)), rec

    point, _ = point_for(z_cal, l_old, nominal)
    probe, shown = calibrate_length_point(point, z_cal, nominal, l_old, plane)
    l_new = shown["length"]
    _, rec2 = point_for(z_other, l_new, probe)
    rec_wcs = np.zeros(3) + rec2 * p_hat
    touch = make_touch(rec_wcs, -p_hat, probe, plane)
    assert float(touch.surface @ p_hat) == pytest.approx(z_other, abs=1e-9)


def test_evaluate_probe_task_wrappers():
    from engine.calibration import evaluate_probe_task
    point = EdgePoint(Touch(np.array([1.0, 2.0, 23.105]), np.array([0.0, 0.0, -1.0]),
                            np.array([1.0, 2.0, 20.105])))
    probe, values = evaluate_probe_task("probe.length", {"setpoint": 20.0}, point,
                                        ProbeRecord(ball_diameter=6.0), G17, length_old=50.0)
    assert values["length"] == pytest.approx(50.105, abs=1e-12)
    assert values["probe"]["trigger"]["Z-"] == 3.0 and values["probe"]["calibrated_length"]
