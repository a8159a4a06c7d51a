"""engine.lobing: the direction-dependent trigger map of an n-direction ring calibration.

Truth: tests/engine/ringsim.py (pre-travel δ(θ) in the probe's frame turning with SPOS, or in
the machine frame; eccentricity; latency; the ring program). The map is the Fourier series of
engine.lobing; its stated accuracy: exact for a lobing band-limited below n/2 (three lobes, 12
directions), otherwise within the aliasing bound 2·Σ_{m ≥ n/2} A_m of the true ρ(θ) (A_m from a
dense DFT of the analytic function) plus the chord-offset leak of an unobservable first harmonic.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from ringsim import RingTruth, fourier_amplitudes, quadrant_pretravel, trilobe_pretravel
from test_plan_world import Bore, World, drive

from engine.calibration import RingTouch, estimate_ring, ring_touches
from engine.compensation import make_touch, skew_in_wcs
from engine.fit import fit_circle, fit_line
from engine.frames import Frame
from engine.lobing import fit_lobing_map
from engine.plan_base import PlanContext, RingCalibrationPoint
from engine.plan_workpiece import ring_program
from engine.planes import PLANES
from engine.types import ProbeRecord, ProbeStep, SpindleStep

G17 = PLANES["G17"]
PROBE = ProbeRecord(ball_diameter=4.0)
Z = -158.0
EXACT = 1e-9
GRID = np.arange(0.0, 360.0, 1.0)
TRILOBE = trilobe_pretravel(0.004, 0.0015, phase_deg=17.0)        # δ0 = 4 µm, A3 = 1.5 µm


def touches_of(passes):
    return [RingTouch(np.array([r[0], r[1], Z]), np.array([u[0], u[1], 0.0]), phi, key)
            for phi, ts in passes for key, r, u in ts]


def along_d_error(est, truth: RingTruth, theta_deg: float, spindle: float = 0.0) -> float:
    """(skew·d̂ + ρ_map) − (e·d̂ + ρ_true) for a travel at machine angle θ, SPOS ``spindle``."""
    t = math.radians(theta_deg - spindle)                       # direction in the probe frame
    d_p = np.array([math.cos(t), math.sin(t)])
    frame_angle = theta_deg - spindle if truth.frame == "probe" else theta_deg
    return (float(est.skew @ d_p) + est.lobing.radius(frame_angle)
            - float(truth.e @ d_p) - truth.rho(frame_angle))


def test_three_lobes_from_12_directions_exact_everywhere():
    truth = RingTruth(delta=TRILOBE, frame="probe", ecc=(0.012, -0.008), latency_path=0.02)
    est = estimate_ring(touches_of(truth.n_direction_program(12)), truth.diameter, PROBE, G17)
    assert len(est.angles) == 12 and est.lobing.frame == "probe"
    np.testing.assert_allclose(est.center, truth.m, atol=EXACT)
    np.testing.assert_allclose(est.skew, truth.e, atol=EXACT)          # no first harmonic: e itself
    assert max(abs(along_d_error(est, truth, th)) for th in GRID) < EXACT
    amp = est.lobing.amplitudes
    assert amp[3] == pytest.approx(0.0015, abs=EXACT)
    assert all(v < EXACT for order, v in amp.items() if order != 3)
    assert est.lobing.mean_radius == pytest.approx(2.0 - 0.004 - 0.02, abs=EXACT)
    assert np.max(np.abs(est.lobing.fit_residuals)) < 1e-12            # interpolating


def test_the_simulators_quadrant_model_within_the_aliasing_bound():
    table = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006}
    delta = quadrant_pretravel(table)
    truth = RingTruth(delta=delta, frame="probe", latency_path=0.02)
    n = 12
    est = estimate_ring(touches_of(truth.n_direction_program(n)), truth.diameter, PROBE, G17)
    amps = fourier_amplitudes(truth.rho, orders=200)
    tail = 2.0 * float(np.sum(amps[n // 2:]))
    k = np.array([amps[1], 0.0])                   # |first harmonic| of ρ, for the chord leak
    leak = float(np.linalg.norm(k)) * (math.hypot(0.3, 0.2) + 0.03) / (truth.big_r - truth.r)
    errors = [abs(along_d_error(est, truth, th)) for th in GRID]
    assert max(errors) <= tail + leak
    assert tail < 2e-4                              # the bound is meaningful: 0.1 µm class
    # at the calibrated directions only the leak remains
    assert max(abs(along_d_error(est, truth, th)) for th in range(0, 360, 30)) <= leak
    np.testing.assert_allclose(est.center, truth.m, atol=leak)


def test_symmetric_quadrant_model_is_band_limited_and_exact():
    """p(X+) = p(X−), p(Y+) = p(Y−): δ = c²·pX + s²·pY has orders 0 and 2 only."""
    truth = RingTruth(delta=quadrant_pretravel({"X+": 0.004, "X-": 0.004, "Y+": 0.007, "Y-": 0.007}))
    est = estimate_ring(touches_of(truth.n_direction_program(8)), truth.diameter, PROBE, G17)
    assert max(abs(along_d_error(est, truth, th)) for th in GRID) < EXACT


def test_machine_frame_map_and_a_known_centre_frees_the_first_harmonic():
    delta = trilobe_pretravel(0.004, 0.0015, 17.0, first=(0.0008, -0.0005))
    truth = RingTruth(delta=delta, frame="machine")
    touches = touches_of(truth.n_direction_program(12))
    est = estimate_ring(touches, truth.diameter, PROBE, G17, frame="machine")
    # first harmonic of ρ = −(k·d̂): absorbed by the centre, M + k
    tol = 0.001 * (math.hypot(0.3, 0.2) + 0.03) / (truth.big_r - truth.r)
    np.testing.assert_allclose(est.center, truth.m + np.array([0.0008, -0.0005]), atol=tol)
    np.testing.assert_allclose(est.skew, truth.e, atol=tol)
    assert not est.center_observable
    known = estimate_ring(touches, truth.diameter, PROBE, G17, frame="machine", center=[*truth.m, Z])
    assert 1 in known.lobing.amplitudes
    for th in GRID:
        assert known.lobing.radius(th) == pytest.approx(truth.rho(th), abs=EXACT)


# --- application: make_touch with the map ------------------------------------------------------

def _calibrated(delta=TRILOBE):
    truth = RingTruth(delta=delta, frame="probe", ecc=(0.012, -0.008), latency_path=0.02)
    est = estimate_ring(touches_of(truth.n_direction_program(12)), truth.diameter, PROBE, G17)
    record = replace(PROBE, skew=(float(est.skew[0]), float(est.skew[1])), trigger=dict(est.trigger),
                     effective_diameter=est.effective_diameter, calibrated_radius=True)
    return truth, est, record


@pytest.mark.parametrize("spindle", [0.0, 90.0, 215.0])
def test_bore_at_an_angle_at_any_spindle_orientation(spindle):
    """A bore Ø40 probed from its centre at 20°/200°/110°/290°/65° with the spindle at
    ``spindle``: surface points s = c + ρ(θ − φ)·d̂ lie on the true circle (normal incidence);
    the record alone (constant ρ for oblique directions) misses by the lobing."""
    truth, est, record = _calibrated()
    bore = RingTruth(center=(150.0, -40.0), diameter=40.0, delta=TRILOBE, frame="probe",
                     ecc=tuple(truth.e), latency_path=0.02)
    skew = skew_in_wcs(record, Frame(), spindle)
    with_map, without = [], []
    for theta in (20.0, 200.0, 110.0, 290.0, 65.0):
        u = np.array([math.cos(math.radians(theta)), math.sin(math.radians(theta))])
        rec2 = bore.latch(bore.m - bore.ecc_at(spindle), u, spindle)   # ball on the centre line
        rec, d = np.array([rec2[0], rec2[1], Z]), np.array([u[0], u[1], 0.0])
        with_map.append(make_touch(rec, d, record, G17, skew_wcs=skew, lobing=est.lobing,
                                   spindle_angle=spindle).surface[:2])
        without.append(make_touch(rec, d, record, G17, skew_wcs=skew).surface[:2])
    fit = fit_circle(np.array(with_map))
    np.testing.assert_allclose(fit.center, bore.m, atol=EXACT)
    assert fit.radius == pytest.approx(20.0, abs=EXACT) and fit.form_error < EXACT
    assert fit_circle(np.array(without)).form_error > 1e-3                    # 1.5 µm lobes


def test_oblique_face_through_contact_centres():
    """A wall at 25° to the travel (+X at SPOS 0): contact centres c₀ = c − (r − ρ(θ))·d̂ lie on
    the wall's offset line; shifting the fitted line by r along its normal gives the wall."""
    truth, est, record = _calibrated()
    normal = np.array([math.cos(math.radians(25.0)), math.sin(math.radians(25.0))])   # into the wall
    level = 80.0                                   # wall: normal·x = level, material beyond
    skew = skew_in_wcs(record, Frame(), 0.0)
    u = np.array([1.0, 0.0])
    centres = []
    for y in (-10.0, 5.0, 30.0):
        q = np.array([0.0, y])
        b0 = q + truth.ecc_at(0.0)
        s_contact = (level - truth.r - normal @ b0) / (normal @ u)
        s = s_contact + TRILOBE(0.0) + truth.lat
        rec = np.array([*(q + s * u), Z])
        c = make_touch(rec, np.array([1.0, 0.0, 0.0]), record, G17, skew_wcs=skew).ball_centre
        centres.append(est.lobing.contact_centre(c, np.array([1.0, 0.0, 0.0]), truth.r)[:2])
    line = fit_line(np.array(centres))
    n_fit = line.normal if line.normal @ normal > 0 else -line.normal
    wall = float(n_fit @ line.point) + truth.r
    assert wall == pytest.approx(level, abs=EXACT) and np.allclose(n_fit, normal, atol=EXACT)


def test_default_make_touch_path_is_unchanged():
    record = replace(PROBE, trigger={"X+": -1.97, "X-": 1.98, "Y+": -1.975, "Y-": 1.971},
                     skew=(0.01, -0.006), effective_diameter=3.95)
    for d in (np.array([1.0, 0, 0]), np.array([0, -1.0, 0]), np.array([0.6, 0.8, 0.0])):
        rec = np.array([3.0, 4.0, -5.0])
        a = make_touch(rec, d, record, G17, skew_wcs=np.array([0.01, -0.006, 0.0]))
        b = make_touch(rec, d, record, G17, np.array([0.01, -0.006, 0.0]), None, lobing=None, spindle_angle=90.0)
        np.testing.assert_array_equal(a.surface, b.surface)
        np.testing.assert_array_equal(a.ball_centre, b.ball_centre)
    # axis-parallel along +X: s_x = c_x − t(X+) (measuring-math §5.3)
    t = make_touch(np.array([3.0, 4.0, -5.0]), np.array([1.0, 0, 0]), record, G17, skew_wcs=np.zeros(3))
    assert t.surface[0] == pytest.approx(3.0 + 1.97)


def test_infeed_component_blends_with_the_axial_value():
    lob = fit_lobing_map([0, 90, 180, 270], [1.99, 1.97, 1.99, 1.97], frame="probe")
    d = np.array([0.6, 0.0, -0.8])
    assert lob.radius_for(d, axial_radius=2.0) == pytest.approx(0.36 * 1.99 + 0.64 * 2.0, abs=1e-15)
    assert lob.radius_for(np.array([0.0, 0.0, -1.0]), axial_radius=2.0) == pytest.approx(2.0)
    # make_touch takes the record's current |t(−Z)|
    rec = replace(PROBE, trigger={"Z-": 2.0})
    touch = make_touch(np.zeros(3), d, rec, G17, lobing=lob)
    assert touch.surface == pytest.approx(lob.radius_for(d, axial_radius=2.0) * d)


def test_map_construction_rules():
    with pytest.raises(ValueError):
        fit_lobing_map([0, 120, 240], [1, 1, 1])
    with pytest.raises(ValueError):
        fit_lobing_map([0, 90, 180, 270], [1, 1, 1, 1], orders=(1, 2))      # order 1 is the skew's
    th = np.arange(0.0, 360.0, 30.0)
    rho = 1.98 + 0.001 * np.cos(np.radians(3 * th)) + 0.0002 * np.cos(np.radians(5 * th))
    smooth = fit_lobing_map(th, rho, orders=(3,))
    assert smooth.terms == ((0, "cos"), (3, "cos"), (3, "sin"))
    assert np.max(np.abs(smooth.fit_residuals)) == pytest.approx(0.0002, rel=1e-9)
    full = fit_lobing_map(th, rho)
    assert len(full.terms) == 10 and np.max(np.abs(full.fit_residuals)) < 1e-12
    assert ("6", "sin") not in [(str(o), k) for o, k in full.terms]          # Nyquist: cosine only
    tv = full.trigger_values(0.0)
    assert tv["X+"] == pytest.approx(-rho[0]) and tv["Y-"] == pytest.approx(rho[9])
    assert full.trigger_values(90.0)["X+"] == pytest.approx(-rho[9])       # turned with the spindle


# --- the n-direction ring program ----------------------------------------------------------------

def test_ring_program_with_12_directions():
    """Driven against the plan tests' analytic world (pre-travel fixed to the machine axes):
    the search, then 12 directions at SPOS 180° and 0°, each from the found centre."""
    pre = {"X+": 0.003, "X-": 0.003, "Y+": 0.005, "Y-": 0.005}
    true_skew = np.array([0.012, -0.008, 0.0])
    mp = np.array([600.03, 99.98, -150.0])
    world = World(shapes=[Bore(mp, 12.5, np.array([0, 0, 1.0]))], r=2.0, skew=true_skew, pretravel=pre)
    ctx = PlanContext(plane=G17, probe_record=PROBE, skew_wcs=np.zeros(3), measuring_path=10.0)
    start = mp + np.array([0.4, -0.3, 0.0])
    point, steps = drive(ring_program({"diameter": 25.0, "directions": 12}, start, ctx, "cal"), start, world)
    assert isinstance(point, RingCalibrationPoint)
    assert [s.angle for s in steps if isinstance(s, SpindleStep)] == [0.0, 180.0, 0.0]
    assert len([s for s in steps if isinstance(s, ProbeStep)]) == 4 + 24
    assert list(point.passes[1].rec) == [f"{30 * k:g}" for k in range(12)]
    np.testing.assert_allclose(point.passes[1].directions["30"], [math.cos(math.pi / 6), 0.5, 0.0])
    touches = ring_touches(point, G17)
    est = estimate_ring(touches, 25.0, PROBE, G17, frame="machine")
    np.testing.assert_allclose(est.skew, true_skew[:2], atol=EXACT)
    np.testing.assert_allclose(est.center, mp[:2], atol=EXACT)            # k = 0 here
    for th, rho in zip(est.angles, est.radii, strict=True):
        c, s = math.cos(math.radians(th)), math.sin(math.radians(th))
        assert rho == pytest.approx(2.0 - (c * c * 0.003 + s * s * 0.005), abs=EXACT)
    # n = 4 stays the JOG program (search, 180°, 0°)
    point4, _ = drive(ring_program({"diameter": 25.0}, start, ctx, "cal"), start, World(
        shapes=[Bore(mp, 12.5, np.array([0, 0, 1.0]))], r=2.0, skew=true_skew, pretravel=pre))
    assert list(point4.passes[0].rec) == ["X+", "X-", "Y+", "Y-"] and point4.passes[0].directions == {}


def test_ring_program_with_oblique_chords_and_the_separating_estimate():
    """chord_offset: every direction along two chords off the centre; with them the machine-
    frame estimate needs no convention: centre M and X+ ≠ X− come out exactly (k ≠ 0)."""
    pre = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006}
    true_skew = np.array([0.012, -0.008, 0.0])
    mp = np.array([600.03, 99.98, -150.0])
    world = World(shapes=[Bore(mp, 12.5, np.array([0, 0, 1.0]))], r=2.0, skew=true_skew, pretravel=pre)
    ctx = PlanContext(plane=G17, probe_record=PROBE, skew_wcs=np.zeros(3), measuring_path=10.0)
    start = mp + np.array([0.4, -0.3, 0.0])
    program = ring_program({"diameter": 25.0, "directions": 4, "chord_offset": 5.0}, start, ctx, "cal")
    point, steps = drive(program, start, world)
    assert list(point.passes[0].rec) == ["0/+", "0/-", "90/+", "90/-", "180/+", "180/-", "270/+", "270/-"]
    est = estimate_ring(ring_touches(point, G17), 25.0, PROBE, G17, frame="machine", first_harmonic="estimate")
    np.testing.assert_allclose(est.center, mp[:2], atol=EXACT)
    np.testing.assert_allclose(est.skew, true_skew[:2], atol=EXACT)
    assert est.trigger["X+"] == pytest.approx(-(2.0 - 0.004), abs=EXACT)
    assert est.trigger["X-"] == pytest.approx(2.0 - 0.005, abs=EXACT)
    assert est.trigger["Y-"] == pytest.approx(2.0 - 0.006, abs=EXACT)
    with pytest.raises(ValueError):
        drive(ring_program({"diameter": 25.0, "chord_offset": 11.0}, start, ctx, "cal"), start, world)


def _wall_offset(truth: RingTruth, est, record, delta, normal, level) -> float:
    """The oblique-face procedure of test_oblique_face_through_contact_centres; returns the
    fitted wall offset along ``normal``."""
    skew = skew_in_wcs(record, Frame(), 0.0)
    u = np.array([1.0, 0.0])
    centres = []
    for y in (-10.0, 5.0, 30.0):
        q = np.array([0.0, y])
        s = (level - truth.r - normal @ (q + truth.ecc_at(0.0))) / (normal @ u) + delta(0.0) + truth.lat
        rec = np.array([*(q + s * u), Z])
        c = make_touch(rec, np.array([1.0, 0.0, 0.0]), record, G17, skew_wcs=skew).ball_centre
        centres.append(est.lobing.contact_centre(c, np.array([1.0, 0.0, 0.0]), truth.r)[:2])
    line = fit_line(np.array(centres))
    n_fit = line.normal if line.normal @ normal > 0 else -line.normal
    return float(n_fit @ line.point) + truth.r


def test_oblique_face_with_a_first_harmonic_convention_versus_estimate():
    """The simulator's asymmetric quadrant lobing (first harmonic k ≠ 0) on a wall at 25°: the
    convention (skew = e − k) leaves −n̂·k + (k·d̂)(n̂·d̂) — k = the first harmonic sampled by the
    12 directions — while the oblique-chord calibration (first_harmonic="estimate") is exact."""
    table = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006}
    delta = quadrant_pretravel(table)
    truth = RingTruth(delta=delta, frame="probe", ecc=(0.012, -0.008), latency_path=0.02)
    normal = np.array([math.cos(math.radians(25.0)), math.sin(math.radians(25.0))])
    level = 80.0
    th = np.radians(np.arange(0.0, 360.0, 30.0))
    k = (2.0 / 12.0) * np.array([sum(delta(math.degrees(t)) * math.cos(t) for t in th),
                                 sum(delta(math.degrees(t)) * math.sin(t) for t in th)])
    d = np.array([1.0, 0.0])
    expected = -float(normal @ k) + float(k @ d) * float(normal @ d)
    for mode, passes in (("convention", truth.n_direction_program(12)),
                         ("estimate", truth.oblique_program(12, 5.0))):
        est = estimate_ring(touches_of(passes), truth.diameter, PROBE, G17, first_harmonic=mode)
        record = replace(PROBE, skew=(float(est.skew[0]), float(est.skew[1])), trigger=dict(est.trigger))
        error = _wall_offset(truth, est, record, delta, normal, level) - level
        if mode == "convention":
            leak = float(np.linalg.norm(k)) * 0.4 / (truth.big_r - truth.r)
            assert error == pytest.approx(expected, abs=leak)
            assert abs(expected) > 3e-4                    # 0.4 µm: the convention's limit is real
        else:
            assert error == pytest.approx(0.0, abs=EXACT)
