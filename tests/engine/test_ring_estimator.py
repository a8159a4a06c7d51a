"""engine.calibration.estimate_ring / calibrate_ring: the least-squares ring calibration.

Truth: tests/engine/ringsim.py (analytic touches: ring, ball, eccentricity turning with SPOS,
pre-travel in the probe's frame or in the machine frame, latency along the direction, Gaussian
noise), driven like the JOG program (search at 0°, passes at 180° and 0°). What can be expected
(module comment of engine.calibration):

- probe frame: centre M exact; only e·d̂ + ρ(θ) is observable per direction (the correction a
  later touch needs), skew = e − k, trigger magnitudes per axis equal;
- machine frame: skew = e exact; with an unknown centre the centre is M + k (flagged), with a
  known centre X+ and X− come out apart;
- exact to rounding when k = 0 (or the centre is known, machine frame); otherwise the chord
  offsets h let k leak in by at most |k|·max|h|/(R − r) — the tolerance used below.

Noise: the variances against the linear theory of docs/noise-bound.md (17/48, 1/6, 3/16 σ²;
calibrate_radius 3/4 σ²), Monte Carlo with fixed seeds.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from ringsim import RingTruth, quadrant_pretravel

from engine import alarms
from engine.calibration import (
    RingTouch,
    calibrate_radius,
    calibrate_ring,
    calibration_variances,
    estimate_ring,
    ring_touches,
)
from engine.compensation import make_touch, skew_in_wcs
from engine.frames import Frame
from engine.plan_base import RingCalibrationPoint, RingPass
from engine.planes import PLANES
from engine.types import MeasuringError, ProbeRecord

G17 = PLANES["G17"]
PROBE = ProbeRecord(ball_diameter=4.0)
Z = -158.0
ASYM = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006}       # flowkit CAL_SCENARIO
SYM = {"X+": 0.004, "X-": 0.004, "Y+": 0.006, "Y-": 0.006}        # k = 0, X ≠ Y
AXES = {"X+": (1.0, 0.0, 0.0), "X-": (-1.0, 0.0, 180.0), "Y+": (0.0, 1.0, 90.0), "Y-": (0.0, -1.0, 270.0)}
EXACT = 1e-9


def as_touches(passes, truth: RingTruth | None = None):
    out = []
    for phi, ts in passes:
        for key, rec, u in ts:
            if truth is not None:
                rec, u = truth.to_wcs(rec), truth.dir_wcs(u)
            out.append(RingTouch(np.array([rec[0], rec[1], Z]), np.array([u[0], u[1], 0.0]), phi, key))
    return out


def as_point(passes, diameter=25.0) -> RingCalibrationPoint:
    ps = [RingPass(phi, {k: np.array([r[0], r[1], Z]) for k, r, _u in ts}) for phi, ts in passes]
    return RingCalibrationPoint(diameter, ps[0], (ps[1], ps[2]))


def needed(truth: RingTruth, key: str) -> float:
    """What a later touch along ``key`` at SPOS 0° needs added to rec·d̂: e·d̂ + ρ_true(θ)."""
    dx, dy, theta = AXES[key]
    return float(truth.e @ np.array([dx, dy])) + truth.rho(theta)


def got(est, key: str) -> float:
    dx, dy, _ = AXES[key]
    rho = -est.trigger[key] if key.endswith("+") else est.trigger[key]
    return float(est.skew @ np.array([dx, dy])) + rho


def k_of(table) -> np.ndarray:
    return np.array([(table["X+"] - table["X-"]) / 2.0, (table["Y+"] - table["Y-"]) / 2.0])


def leak_bound(truth: RingTruth, k, miss) -> float:
    """|k|·max|h|/(R − r): h ≤ |miss| + 2|e| (search off-centre, 180° pass 2e off-centre)."""
    h_max = math.hypot(*miss) + 2.0 * float(np.linalg.norm(truth.e)) + 1e-3
    return float(np.linalg.norm(k)) * h_max / (truth.big_r - truth.r)


# --- noise-free truth -----------------------------------------------------------------------

@pytest.mark.parametrize("frame", ["probe", "machine"])
def test_symmetric_pretravel_is_recovered_exactly(frame):
    truth = RingTruth(delta=quadrant_pretravel(SYM), frame=frame)
    est = estimate_ring(as_touches(truth.jog_program()), truth.diameter, PROBE, G17, frame=frame)
    np.testing.assert_allclose(est.center, truth.m, atol=EXACT)
    np.testing.assert_allclose(est.skew, truth.e, atol=EXACT)
    for key in AXES:
        assert got(est, key) == pytest.approx(needed(truth, key), abs=EXACT)
    assert est.trigger["X+"] == pytest.approx(-truth.rho(0.0), abs=EXACT)
    assert est.trigger["Y-"] == pytest.approx(truth.rho(270.0), abs=EXACT)
    assert est.trigger["X-"] != pytest.approx(est.trigger["Y-"], abs=1e-4)       # X and Y differ
    assert est.effective_diameter == pytest.approx(2 * np.mean([truth.rho(a) for a in (0, 90, 180, 270)]),
                                                   abs=EXACT)
    assert est.n == 12 and est.dof == 6 and est.rms < 1e-12


def test_probe_frame_observes_the_centre_and_every_direction():
    """Asymmetric pre-travel turning with the spindle: the 180° pass sees k — centre and every
    per-direction correction are right; the asymmetry goes into the (effective) skew."""
    miss = (0.3, -0.2)
    truth = RingTruth(delta=quadrant_pretravel(ASYM), frame="probe")
    est = estimate_ring(as_touches(truth.jog_program(miss)), truth.diameter, PROBE, G17, frame="probe")
    tol = leak_bound(truth, k_of(ASYM), miss)
    assert 1e-6 < tol < 1e-4                                    # 0.05 µm: the documented leak
    np.testing.assert_allclose(est.center, truth.m, atol=tol)
    for key in AXES:
        assert got(est, key) == pytest.approx(needed(truth, key), abs=tol), key
    np.testing.assert_allclose(est.skew, truth.e - k_of(ASYM), atol=tol)        # e − k
    assert est.trigger["X+"] == pytest.approx(-est.trigger["X-"], abs=EXACT)   # equal magnitudes
    assert est.center_observable and est.skew_effective
    assert any("eccentricity - k" in n or "skew = eccentricity" in n for n in est.notes)
    # without the chord offsets (start on the centre) the leak shrinks with h
    exact = estimate_ring(as_touches(truth.jog_program((0.0, 0.0))), truth.diameter, PROBE, G17)
    assert abs(got(exact, "Y+") - needed(truth, "Y+")) < leak_bound(truth, k_of(ASYM), (0.0, 0.0))


def test_machine_frame_unknown_centre_says_what_it_cannot_see():
    miss = (0.3, -0.2)
    truth = RingTruth(delta=quadrant_pretravel(ASYM), frame="machine")
    est = estimate_ring(as_touches(truth.jog_program(miss)), truth.diameter, PROBE, G17, frame="machine")
    tol = leak_bound(truth, k_of(ASYM), miss)
    np.testing.assert_allclose(est.skew, truth.e, atol=tol)                     # e observable
    np.testing.assert_allclose(est.center, truth.m + k_of(ASYM), atol=tol)      # M + k
    assert not est.center_observable and not est.skew_effective
    assert any("M + k" in n for n in est.notes)
    for key in AXES:        # a later touch along ±j puts the surface k_j off on axis j (both signs)
        dx, dy, _ = AXES[key]
        k_j = float(k_of(ASYM) @ np.array([abs(dx), abs(dy)]))
        sign = 1.0 if key.endswith("+") else -1.0
        assert sign * (got(est, key) - needed(truth, key)) == pytest.approx(k_j, abs=tol), key


def test_machine_frame_known_centre_stores_every_trigger_value_apart():
    truth = RingTruth(delta=quadrant_pretravel(ASYM), frame="machine")
    est = estimate_ring(as_touches(truth.jog_program()), truth.diameter, PROBE, G17, frame="machine",
                        center=[truth.m[0], truth.m[1], Z])
    np.testing.assert_allclose(est.skew, truth.e, atol=EXACT)
    assert est.trigger["X+"] == pytest.approx(-truth.rho(0.0), abs=EXACT)
    assert est.trigger["X-"] == pytest.approx(truth.rho(180.0), abs=EXACT)
    assert est.trigger["Y+"] == pytest.approx(-truth.rho(90.0), abs=EXACT)
    assert est.trigger["Y-"] == pytest.approx(truth.rho(270.0), abs=EXACT)
    assert abs(est.trigger["X+"] + est.trigger["X-"]) > 5e-4                     # X+ ≠ X−
    assert est.center_observable


def test_rotated_wcs_and_four_spindle_orientations():
    """Measuring WCS turned 12.5° against the machine, passes at 0/90/180/270°: the skew is stored
    in machine X/Y, the centre in the WCS, the direction classes in the probe frame."""
    gamma = 12.5
    truth = RingTruth(delta=quadrant_pretravel(SYM), frame="probe", wcs_rot=gamma)
    passes = truth.jog_program()
    extra = [(phi, truth._pass(truth.m + np.array([0.01, -0.02]), phi)[0]) for phi in (90.0, 270.0)]
    # the touches were made along machine axes; in the WCS they are oblique
    touches = as_touches(passes + extra, truth)
    wcs2bcs = Frame(coarse=np.array([0.0, 0.0, 0.0]), rot=np.array([0.0, 0.0, gamma]))
    est = estimate_ring(touches, truth.diameter, PROBE, G17, frame="probe", wcs2bcs=wcs2bcs)
    np.testing.assert_allclose(est.skew, truth.e, atol=EXACT)
    np.testing.assert_allclose(est.center, truth.to_wcs(truth.m), atol=EXACT)
    assert sorted(np.round(est.angles, 6)) == [0.0, 90.0, 180.0, 270.0]
    for theta, rho in zip(est.angles, est.radii, strict=True):
        assert rho == pytest.approx(truth.rho(theta), abs=EXACT)


def test_one_spindle_orientation_needs_spos_unless_the_centre_is_known():
    truth = RingTruth(delta=quadrant_pretravel(SYM), frame="probe")
    search = truth.jog_program()[:1]
    touches = as_touches(search + [(0.0, truth._pass(truth.m, 0.0)[0])])
    with pytest.raises(MeasuringError) as err:
        estimate_ring(touches, truth.diameter, PROBE, G17)
    assert err.value.definition is alarms.NEEDS_SPOS
    est = estimate_ring(touches, truth.diameter, PROBE, G17, center=[*truth.m, Z], skew=truth.e)
    for key in AXES:
        assert got(est, key) == pytest.approx(needed(truth, key), abs=EXACT)


def test_bad_input():
    truth = RingTruth(delta=quadrant_pretravel(SYM))
    touches = as_touches(truth.jog_program())
    with pytest.raises(ValueError):
        estimate_ring(touches, truth.diameter, PROBE, G17, frame="spindle")
    with pytest.raises(ValueError):
        estimate_ring(touches, 3.0, PROBE, G17)                  # ring smaller than the ball
    tilted = [RingTouch(t.rec, np.array([0.6, 0.0, 0.8]), t.spindle_angle) for t in touches]
    with pytest.raises(ValueError):
        estimate_ring(tilted, truth.diameter, PROBE, G17)
    with pytest.raises(MeasuringError) as err:
        estimate_ring(touches[:3], truth.diameter, PROBE, G17)
    assert err.value.definition is alarms.CIRCLE_PARAMETERS
    one_axis = [t for t in touches if abs(t.direction[1]) < 0.5]
    with pytest.raises(MeasuringError) as err:
        estimate_ring(one_axis, truth.diameter, PROBE, G17)
    assert err.value.definition is alarms.CIRCLE_UNDETERMINED


# --- calibrate_ring: the record ----------------------------------------------------------------

def test_calibrate_ring_record_and_remeasuring_an_edge():
    """The stored record (skew + trigger values) measures other surfaces right: edges along ±X/±Y
    and a bore of another diameter, probe-frame asymmetric pre-travel, at SPOS 0°."""
    miss = (0.3, -0.2)
    truth = RingTruth(delta=quadrant_pretravel(ASYM), frame="probe", latency_path=0.02)
    point = as_point(truth.jog_program(miss))
    record, values = calibrate_ring(point, PROBE, G17)
    tol = leak_bound(truth, k_of(ASYM), miss)
    for key in ("center", "skew", "trigger", "trigger_difference", "effective_diameter",
                "effective_diameter_difference", "std", "residuals", "form_error", "observable", "lobing"):
        assert key in values
    assert values["observable"] == {"center": True, "skew": "eccentricity - k"}
    assert record.calibrated_radius and record.trigger["X+"] == values["trigger"]["X+"]
    assert record.skew == pytest.approx(tuple(truth.e - k_of(ASYM)), abs=tol)
    skew = skew_in_wcs(record, Frame(), 0.0)
    for key, (dx, dy, theta) in AXES.items():
        d = np.array([dx, dy, 0.0])
        edge = 40.0
        # ball centre at the latch: first contact (edge − r along d) + δ + v·τ; rec = ball − e
        ball = np.array([0.0, 0.0, Z]) + (edge - truth.rho(theta)) * d
        rec = ball - np.array([truth.e[0], truth.e[1], 0.0])
        touch = make_touch(rec, d, record, G17, skew_wcs=skew)
        assert touch.surface @ d == pytest.approx(edge, abs=tol), key


def test_calibrate_ring_matches_calibrate_radius_where_both_are_exact():
    truth = RingTruth(delta=quadrant_pretravel(SYM), frame="probe")
    point = as_point(truth.jog_program((0.0, 0.0)))
    rec_old, old = calibrate_radius(point, PROBE, G17)
    rec_new, new = calibrate_ring(point, PROBE, G17)
    for key in AXES:
        assert new["trigger"][key] == pytest.approx(old["trigger"][key], abs=1e-7)
    assert new["skew"]["X"] == pytest.approx(old["skew"]["X"], abs=1e-9)
    assert new["effective_diameter"] == pytest.approx(old["effective_diameter"], abs=1e-7)
    assert len(ring_touches(point, G17)) == 12


def test_calibrate_ring_refuses_a_wrong_ring_diameter():
    truth = RingTruth(delta=quadrant_pretravel(SYM))
    point = as_point(truth.jog_program(), diameter=15.0)
    with pytest.raises(MeasuringError) as err:
        calibrate_ring(point, PROBE, G17)
    assert err.value.definition is alarms.SAFE_AREA


# --- noise: variances against the theory --------------------------------------------------------

def test_design_variances_are_the_closed_forms():
    """The linear theory of docs/noise-bound.md §2 for the JOG program (12 touches)."""
    var = calibration_variances(frame="probe")
    for key in AXES:
        assert var["surface"][key] == pytest.approx(17.0 / 48.0, rel=1e-9)
        assert var["trigger"][key] == pytest.approx(1.0 / 6.0, rel=1e-9)
    assert var["center"]["X"] == pytest.approx(3.0 / 16.0, rel=1e-9)
    assert var["skew"]["Y"] == pytest.approx(3.0 / 16.0, rel=1e-9)
    assert var["effective_diameter"] == pytest.approx(1.0 / 3.0, rel=1e-9)


def test_variances_match_monte_carlo_and_beat_calibrate_radius():
    """400 noisy calibrations (σ = 0.3 µm, probe frame, asymmetric pre-travel): the LS estimator's
    per-direction correction has variance 17/48·σ² = 0.354σ², calibrate_radius's 3/4·σ²."""
    sigma, draws = 0.0003, 400
    tol = 3.0 * math.sqrt(2.0 / draws)
    new, old, centre, skew, trig, hats = [], [], [], [], [], []
    for seed in range(draws):
        truth = RingTruth(delta=quadrant_pretravel(ASYM), frame="probe", sigma=sigma, seed=seed)
        passes = truth.jog_program()
        est = estimate_ring(as_touches(passes), truth.diameter, PROBE, G17, sigma=sigma)
        record, _ = calibrate_radius(as_point(passes), PROBE, G17)
        new.append([got(est, k) - needed(truth, k) for k in AXES])
        old_row = []
        for key, (dx, dy, _theta) in AXES.items():
            rho = -record.trigger[key] if key.endswith("+") else record.trigger[key]
            old_row.append(float(np.array(record.skew) @ np.array([dx, dy])) + rho - needed(truth, key))
        old.append(old_row)
        centre.append(est.center - truth.m)
        skew.append(est.skew - (truth.e - k_of(ASYM)))
        trig.append([est.trigger["X+"], est.trigger["Y+"]])
        hats.append(est.sigma_hat ** 2)
    new, old = np.array(new) / sigma, np.array(old) / sigma
    for j in range(4):
        assert new[:, j].var() == pytest.approx(17.0 / 48.0, rel=tol)
        assert old[:, j].var() == pytest.approx(0.75, rel=tol)
    assert np.abs(new.mean(axis=0)).max() < 4.0 * math.sqrt(17.0 / 48.0 / draws)     # unbiased
    assert (np.array(centre) / sigma).var(axis=0) == pytest.approx([3 / 16, 3 / 16], rel=tol)
    assert (np.array(skew) / sigma).var(axis=0) == pytest.approx([3 / 16, 3 / 16], rel=tol)
    assert (np.array(trig) / sigma).var(axis=0) == pytest.approx([1 / 6, 1 / 6], rel=tol)
    assert est.surface_std["X+"] == pytest.approx(sigma * math.sqrt(17.0 / 48.0), rel=1e-3)
    assert np.mean(hats) == pytest.approx(sigma ** 2, rel=tol)                       # σ̂² unbiased


# --- oblique chords: the first harmonic apart from skew and centre ------------------------------

@pytest.mark.parametrize("frame", ["probe", "machine"])
def test_oblique_chords_separate_the_first_harmonic(frame):
    """Chords half-way off the centre: the eccentricity moves the ball across the travel, the
    pre-travel only along it, so the chord offsets tell them apart — skew = e, centre = M and
    X+ ≠ X− exactly, in both frames (under the simulator's model: pre-travel along the travel)."""
    truth = RingTruth(delta=quadrant_pretravel(ASYM), frame=frame, latency_path=0.02)
    offset = 0.5 * (truth.big_r - truth.r)
    touches = as_touches(truth.oblique_program(4, offset))
    est = estimate_ring(touches, truth.diameter, PROBE, G17, frame=frame, first_harmonic="estimate")
    np.testing.assert_allclose(est.skew, truth.e, atol=EXACT)
    np.testing.assert_allclose(est.center, truth.m, atol=EXACT)
    for key, (_dx, _dy, theta) in AXES.items():
        sign = -1.0 if key.endswith("+") else 1.0
        assert est.trigger[key] == pytest.approx(sign * truth.rho(theta), abs=EXACT), key
        assert got(est, key) == pytest.approx(needed(truth, key), abs=EXACT)
    assert abs(est.trigger["X+"] + est.trigger["X-"]) > 5e-4                      # stored apart
    assert est.center_observable and not est.skew_effective
    # noise: well conditioned (std of the skew ≈ 0.6σ for 4 directions, h = (R − r)/2)
    noisy = estimate_ring(touches, truth.diameter, PROBE, G17, frame=frame, first_harmonic="estimate",
                          sigma=0.0003)
    assert noisy.std["skew_X"] < 0.0003 and noisy.std["center_a"] < 0.0003


def test_chords_through_the_centre_cannot_separate_it():
    truth = RingTruth(delta=quadrant_pretravel(ASYM))
    with pytest.raises(MeasuringError) as err:
        estimate_ring(as_touches(truth.jog_program()), truth.diameter, PROBE, G17, first_harmonic="estimate")
    assert err.value.definition is alarms.CIRCLE_UNDETERMINED


def test_evaluate_probe_task_switches_to_the_ls_estimator_on_request():
    from engine.calibration import evaluate_probe_task

    truth = RingTruth(delta=quadrant_pretravel(SYM))
    point = as_point(truth.jog_program())
    old_record, old = evaluate_probe_task("probe.radius", {}, point, PROBE, G17)
    new_record, new = evaluate_probe_task("probe.radius", {}, point, PROBE, G17, pretravel_frame="probe")
    assert "std" not in old and "std" in new and new["probe"]["calibrated_radius"]
    assert old_record == calibrate_radius(point, PROBE, G17)[0]
    assert new_record.skew == pytest.approx(tuple(truth.e), abs=EXACT)
