"""The ring calibration measures what it can instead of trusting it (issue [probe-health] item 5).

Truth: tests/engine/ringsim.py (analytic touches, independent of engine). The probe record holds
a *nominal* ball (what the operator typed in); the true ball is ringsim's ``r``.

- the ball radius: chords at different offsets within one direction class observe it through
  the sagitta, so the stored values must not depend on the nominal at all, and match the truth;
- the pre-travel frame: the 0° and 180° passes with off-centre chords tell whether the pre-travel
  turns with the spindle; chords through the centre or a symmetric pre-travel cannot tell (and
  need not: both models then store the same values).
"""

from __future__ import annotations

import numpy as np
import pytest
from ringsim import RingTruth, quadrant_pretravel
from test_ring_estimator import ASYM, AXES, EXACT, G17, SYM, as_touches, got, needed

from engine.calibration import choose_pretravel_frame, estimate_ring
from engine.types import ProbeRecord


def chord_truth(frame: str = "probe", pretravel=ASYM, sigma: float = 0.0, seed: int = 0) -> RingTruth:
    return RingTruth(delta=quadrant_pretravel(pretravel), frame=frame, latency_path=0.02, sigma=sigma, seed=seed)


def chords(truth: RingTruth):
    """The cal_chords program: chords half-way out, h = (R − r)/2 (engine.plan_workpiece)."""
    return as_touches(truth.oblique_program(4, 0.5 * (truth.big_r - truth.r)))


@pytest.mark.parametrize("nominal", [3.9, 4.0, 4.1])
def test_a_wrong_nominal_ball_changes_nothing(nominal):
    truth = chord_truth()
    est = estimate_ring(chords(truth), truth.diameter, ProbeRecord(ball_diameter=nominal), G17,
                        first_harmonic="estimate")
    assert est.ball_diameter_estimated
    assert est.ball_diameter == pytest.approx(2.0 * truth.r, abs=EXACT)
    for key, (_dx, _dy, theta) in AXES.items():
        sign = -1.0 if key.endswith("+") else 1.0
        assert est.trigger[key] == pytest.approx(sign * truth.rho(theta), abs=EXACT), key
    np.testing.assert_allclose(est.skew, truth.e, atol=EXACT)


def test_with_noise_the_nominal_is_only_a_start_value():
    """Noise 0.3 µm: the estimates with a nominal 0.1 mm small and with the true ball agree to
    rounding (the nominal does not enter the solution), and the ball is found to its std."""
    truth = chord_truth(sigma=0.0003, seed=4)
    touches = chords(truth)
    small = estimate_ring(touches, truth.diameter, ProbeRecord(ball_diameter=3.9), G17, first_harmonic="estimate")
    right = estimate_ring(touches, truth.diameter, ProbeRecord(ball_diameter=4.0), G17, first_harmonic="estimate")
    for key in AXES:
        assert small.trigger[key] == pytest.approx(right.trigger[key], abs=1e-9)
    assert abs(small.ball_diameter - 2.0 * truth.r) < 4.0 * small.ball_diameter_std
    assert small.ball_diameter_std < 0.003                 # ≈ 2·3.6σ: well observed


def test_chords_through_the_centre_keep_the_nominal():
    """The JOG program without off-centre chords cannot see the ball: the nominal is kept, and
    a wrong one costs almost nothing there (h ≤ the start's miss)."""
    truth = chord_truth()
    touches = as_touches(truth.jog_program())
    est = estimate_ring(touches, truth.diameter, ProbeRecord(ball_diameter=3.9), G17)
    assert not est.ball_diameter_estimated and est.ball_diameter == pytest.approx(3.9)
    right = estimate_ring(touches, truth.diameter, ProbeRecord(ball_diameter=4.0), G17)
    a = truth.big_r - truth.r
    bound = est.max_chord_offset ** 2 * 0.05 / (2.0 * a * a)       # h²Δr/2(R−r)², Δr = 0.05 mm
    assert bound < 3e-5
    for key in AXES:
        assert est.trigger[key] == pytest.approx(right.trigger[key], abs=bound)


@pytest.mark.parametrize("frame", ["probe", "machine"])
@pytest.mark.parametrize("seed", range(6))
def test_the_passes_tell_whether_the_pretravel_turns(frame, seed):
    """The example probe's asymmetric pre-travel (k = −0.5/−1.5 µm), 0.3 µm noise: the
    decision names the simulator's frame, whatever the fallback."""
    truth = chord_truth(frame, sigma=0.0003, seed=seed)
    fallback = "machine" if frame == "probe" else "probe"
    est, decision = choose_pretravel_frame(chords(truth), truth.diameter, ProbeRecord(ball_diameter=4.0), G17,
                                           fallback=fallback, first_harmonic="estimate")
    assert decision.decided and decision.frame == frame and est.frame == frame
    assert decision.rss[fallback] > decision.rss[frame]
    np.testing.assert_allclose(est.skew, truth.e, atol=0.0015)


@pytest.mark.parametrize("program", ["centre chords", "symmetric pre-travel"])
def test_when_the_data_cannot_tell_the_fallback_is_used_and_said(program):
    if program == "centre chords":
        truth = chord_truth("machine")
        touches, harmonic = as_touches(truth.jog_program()), "convention"
    else:
        truth = chord_truth("machine", pretravel=SYM)
        touches, harmonic = chords(truth), "estimate"
    est, decision = choose_pretravel_frame(touches, truth.diameter, ProbeRecord(ball_diameter=4.0), G17,
                                           fallback="probe", first_harmonic=harmonic)
    assert not decision.decided and decision.frame == "probe" and est.frame == "probe"
    # and it does not matter: the other model stores the same corrections for a later touch at
    # SPOS 0, right up to the k of centre chords that neither model can see (k_x = −0.5 µm)
    other = estimate_ring(touches, truth.diameter, ProbeRecord(ball_diameter=4.0), G17, frame="machine",
                          first_harmonic=harmonic)
    k = 0.0 if program == "symmetric pre-travel" else 0.0015
    for key in AXES:
        assert got(est, key) == pytest.approx(got(other, key), abs=1e-6), key
        assert got(est, key) == pytest.approx(needed(truth, key), abs=k + 1e-6), key
