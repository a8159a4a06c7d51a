"""engine.fit with n > minimum points: residuals, form error, standard deviations, sphere.

Expected values come from the analytic shapes (points placed on a known line, circle, plane or
sphere, then perturbed by known amounts); the standard deviations are checked against a Monte
Carlo over Gaussian noise (fixed seeds, a few hundred draws, tolerances from the sampling error
of a variance: ±3·sqrt(2/N) relative).
"""

from __future__ import annotations

import numpy as np
import pytest

from engine import alarms
from engine.fit import LineFit, fit_circle, fit_line, fit_plane, fit_sphere
from engine.types import MeasuringError

DRAWS = 400
VAR_TOL = 3.0 * np.sqrt(2.0 / DRAWS)        # relative tolerance on a variance from DRAWS samples


def _ratio_ok(sample_var: float, predicted_var: float) -> bool:
    return abs(sample_var / predicted_var - 1.0) < VAR_TOL


# --- exact on analytic shapes ---------------------------------------------------------------

def test_line_exact_with_many_points():
    u = np.array([np.cos(0.3), np.sin(0.3)])
    p0 = np.array([12.0, -4.0])
    t = np.array([-40.0, -3.0, 7.5, 22.0, 61.0])
    fit = fit_line(p0 + t[:, None] * u)
    assert np.allclose(fit.direction, u, atol=1e-12)
    assert fit.n == 5 and fit.dof == 3
    assert np.max(np.abs(fit.residuals)) < 1e-9 and fit.form_error < 1e-9 and fit.rms < 1e-9
    assert abs((fit.point - p0) @ fit.normal) < 1e-9


def test_circle_exact_with_many_points():
    c, r = np.array([-3.0, 250.0]), 17.5
    a = np.radians([3.0, 50.0, 121.0, 170.0, 233.0, 301.0, 333.0])
    fit = fit_circle(c + r * np.column_stack([np.cos(a), np.sin(a)]))
    assert np.allclose(fit.center, c, atol=1e-9) and fit.radius == pytest.approx(r, abs=1e-9)
    assert fit.n == 7 and fit.form_error < 1e-9 and fit.rms == pytest.approx(fit.residual)


def test_plane_exact_with_many_points():
    n = np.array([0.1, -0.2, 1.0]) / np.linalg.norm([0.1, -0.2, 1.0])
    e1 = np.cross(n, [1.0, 0.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    uv = np.array([(0, 0), (50, 3), (8, 40), (-30, 22), (45, -35), (-12, -18)], dtype=float)
    pts = np.array([1.0, 2.0, -120.0]) + uv[:, :1] * e1 + uv[:, 1:] * e2
    fit = fit_plane(pts)
    assert abs(abs(fit.normal @ n) - 1.0) < 1e-12
    assert fit.n == 6 and np.max(np.abs(fit.residuals)) < 1e-9 and fit.form_error < 1e-9
    assert fit.axes.shape == (2, 3) and np.allclose(fit.axes @ fit.normal, 0.0, atol=1e-12)


@pytest.mark.parametrize("n", [4, 5, 9, 30])
def test_sphere_exact(n):
    rng = np.random.default_rng(n)
    c, r = np.array([100.8, 99.7, 100.4]), 27.99
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    fit = fit_sphere(c + r * d)
    assert np.allclose(fit.center, c, atol=1e-9) and fit.radius == pytest.approx(r, abs=1e-9)
    assert fit.n == n and fit.form_error < 1e-9 and not fit.radius_fixed


def test_sphere_cycle997_paraxial_five_points():
    """Worked example 13-A geometry: 4 ball centres on the equator (P1..P4), P5 on top; the
    ball-centre sphere has radius R + ρ (outside), ρ = 2.99."""
    c, big_r, rho = np.array([100.8, 99.7, 100.4]), 25.0, 2.99
    rc = big_r + rho
    pts = c + rc * np.array([(-1, 0, 0), (1, 0, 0), (0, -1, 0), (0, 1, 0), (0, 0, 1)], dtype=float)
    fit = fit_sphere(pts)
    assert np.allclose(fit.center, c, atol=1e-9)
    assert fit.radius - rho == pytest.approx(big_r, abs=1e-9)           # §13.2: R = R_c − ρ
    assert fit.dof == 1 and fit.form_error < 1e-9


def test_sphere_known_radius_needs_the_side_for_coplanar_points():
    c, rc = np.array([10.0, 20.0, 30.0]), 12.0
    # 3 points on a small circle 5 below the centre: two mirror solutions
    a = np.radians([0.0, 120.0, 240.0])
    rr = np.sqrt(rc * rc - 25.0)
    pts = c + np.column_stack([rr * np.cos(a), rr * np.sin(a), -5.0 * np.ones(3)])
    fit = fit_sphere(pts, radius=rc, center0=c + np.array([0.3, -0.2, 0.5]))
    assert np.allclose(fit.center, c, atol=1e-9) and fit.radius_fixed
    assert fit.param_names == ("center_x", "center_y", "center_z")
    mirror = fit_sphere(pts, radius=rc, center0=c - np.array([0.0, 0.0, 10.0]))
    assert np.allclose(mirror.center, c - np.array([0.0, 0.0, 10.0]), atol=1e-9)
    with pytest.raises(MeasuringError) as err:
        fit_sphere(pts, radius=rc)
    assert err.value.definition is alarms.CIRCLE_UNDETERMINED


# --- residuals and form error on known perturbations ----------------------------------------

def test_line_residuals_signed_along_the_left_normal():
    t = np.array([0.0, 10.0, 20.0, 30.0, 40.0])
    bump = np.array([0.0, 0.002, -0.003, 0.002, -0.001])    # sums to 0 and is orthogonal to t − t̄
    bump = bump - bump.mean()
    tc = t - t.mean()
    bump = bump - (bump @ tc) / (tc @ tc) * tc                # remove the mean and the tilt part
    pts = np.column_stack([t, 5.0 + bump])                    # along +a: left normal = +o
    fit = fit_line(pts)
    np.testing.assert_allclose(fit.residuals, bump, atol=1e-12)
    assert fit.form_error == pytest.approx(bump.max() - bump.min(), abs=1e-12)
    assert fit.rms == pytest.approx(np.sqrt(np.mean(bump ** 2)), abs=1e-12)


def test_circle_residuals_and_roundness():
    """r(φ) = R + A·cos 3φ (a three-lobed bore): the LS circle is the true one (the lobes are
    orthogonal to centre and radius for equally spaced points), residuals A·cos 3φ_i."""
    big_r, amp = 20.0, 0.004
    phi = np.radians(np.arange(0.0, 360.0, 15.0))
    radii = big_r + amp * np.cos(3 * phi)
    fit = fit_circle(np.array([5.0, -7.0]) + radii[:, None] * np.column_stack([np.cos(phi), np.sin(phi)]))
    assert np.allclose(fit.center, [5.0, -7.0], atol=1e-9) and fit.radius == pytest.approx(big_r, abs=1e-9)
    np.testing.assert_allclose(fit.residuals, amp * np.cos(3 * phi), atol=1e-9)
    assert fit.form_error == pytest.approx(2 * amp, abs=1e-9)


def test_plane_residuals_and_flatness():
    uv = np.array([(x, y) for x in (-20.0, 0.0, 20.0) for y in (-10.0, 10.0)])
    w = 0.001 * np.array([1.0, -1.0, -2.0, 2.0, 1.0, -1.0])    # orthogonal to 1, u, v on this grid
    pts = np.column_stack([uv, -50.0 + w])
    fit = fit_plane(pts)
    normal = fit.normal if fit.normal[2] > 0 else -fit.normal
    assert np.allclose(normal, [0, 0, 1], atol=1e-12)
    np.testing.assert_allclose(np.sign(fit.normal[2]) * fit.residuals, w, atol=1e-12)
    assert fit.form_error == pytest.approx(0.004, abs=1e-12)


def test_sphere_residuals_outside_positive():
    c, big_r = np.zeros(3), 10.0
    dirs = np.array([(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)], dtype=float)
    bumps = 0.003 * np.array([1.0, 1.0, -1.0, -1.0, 0.0, 0.0])     # an ellipsoidal distortion
    fit = fit_sphere(c + (big_r + bumps)[:, None] * dirs)
    assert np.allclose(fit.center, c, atol=1e-12) and fit.radius == pytest.approx(big_r, abs=1e-12)
    np.testing.assert_allclose(fit.residuals, bumps, atol=1e-12)
    assert fit.form_error == pytest.approx(0.006, abs=1e-12)


# --- standard deviations against Monte Carlo ----------------------------------------------------

def _mc(fit_fn, truth_pts, noise_dirs, sigma, seed):
    """Fit DRAWS noisy copies (noise σ along ``noise_dirs``, per point); returns (params, fits)."""
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(DRAWS):
        noisy = truth_pts + rng.normal(0.0, sigma, len(truth_pts))[:, None] * noise_dirs
        out.append(fit_fn(noisy))
    return out


def test_line_std_matches_monte_carlo():
    sigma = 0.0003
    t = np.array([0.0, 15.0, 60.0, 120.0])
    pts = np.column_stack([t, np.zeros(4)])
    fits = _mc(lambda p: fit_line(p, sigma=sigma), pts, np.array([[0.0, 1.0]] * 4), sigma, 1)
    angles = np.array([np.arctan2(f.direction[1], f.direction[0]) for f in fits])
    offsets = np.array([f.point[1] for f in fits])
    tc = t - t.mean()
    assert fits[0].std["angle"] == pytest.approx(sigma / np.sqrt(tc @ tc), rel=1e-9)   # σ²/Σt²
    assert fits[0].std["offset"] == pytest.approx(sigma / 2.0, rel=1e-9)               # σ²/n
    assert _ratio_ok(angles.var(), fits[0].std["angle"] ** 2)
    assert _ratio_ok(offsets.var(), fits[0].std["offset"] ** 2)
    # the line's position at the corner (t = 0, off the centroid) and the a-posteriori σ̂
    at0 = np.array([f.point[1] - f.point[0] * f.direction[1] / f.direction[0] for f in fits])
    assert _ratio_ok(at0.var(), fits[0].offset_std_at([0.0, 0.0]) ** 2)
    assert np.mean([f.sigma_hat ** 2 for f in fits]) == pytest.approx(sigma ** 2, rel=VAR_TOL)


def test_circle_std_matches_monte_carlo():
    sigma = 0.0003
    phi = np.radians([0.0, 70.0, 180.0, 250.0, 300.0])
    radial = np.column_stack([np.cos(phi), np.sin(phi)])
    pts = np.array([10.0, 20.0]) + 12.5 * radial
    fits = _mc(lambda p: fit_circle(p, sigma=sigma), pts, radial, sigma, 2)
    params = np.array([[*f.center, f.radius] for f in fits])
    predicted = np.diag(fits[0].covariance)
    for k in range(3):
        assert _ratio_ok(params[:, k].var(), predicted[k]), k
    # a posteriori: σ̂² = Σr²/(n − 3) is unbiased
    assert np.mean([f.sigma_hat ** 2 for f in fits]) == pytest.approx(sigma ** 2, rel=VAR_TOL)


def test_plane_std_matches_monte_carlo():
    sigma = 0.0003
    uv = np.array([(0.0, 0.0), (80.0, 5.0), (10.0, 60.0), (70.0, 55.0)])
    pts = np.column_stack([uv, np.zeros(4)])
    fits = _mc(lambda p: fit_plane(p, sigma=sigma), pts, np.array([[0.0, 0.0, 1.0]] * 4), sigma, 3)
    f0 = fits[0]
    offsets = np.array([(f.point - pts.mean(axis=0)) @ np.array([0, 0, 1.0]) for f in fits])
    sign = np.array([np.sign(f.normal[2]) for f in fits])
    tilt_u = np.array([s * f.normal @ f0.axes[0] for s, f in zip(sign, fits, strict=True)])
    tilt_v = np.array([s * f.normal @ f0.axes[1] for s, f in zip(sign, fits, strict=True)])
    assert _ratio_ok(offsets.var(), f0.std["offset"] ** 2)
    assert _ratio_ok(tilt_u.var(), f0.std["tilt_u"] ** 2)
    assert _ratio_ok(tilt_v.var(), f0.std["tilt_v"] ** 2)


def test_sphere_std_matches_monte_carlo():
    sigma = 0.0003
    dirs = np.array([(-1, 0, 0), (1, 0, 0), (0, -1, 0), (0, 1, 0), (0, 0, 1),
                     (0.6, 0.0, 0.8), (0.0, -0.6, 0.8)], dtype=float)
    pts = np.array([100.0, 100.0, 100.0]) + 27.99 * dirs
    fits = _mc(lambda p: fit_sphere(p, sigma=sigma), pts, dirs, sigma, 4)
    params = np.array([[*f.center, f.radius] for f in fits])
    predicted = np.diag(fits[0].covariance)
    for k in range(4):
        assert _ratio_ok(params[:, k].var(), predicted[k]), k


# --- typed failures -------------------------------------------------------------------------

@pytest.mark.parametrize("call,alarm", [
    (lambda: fit_line([(1.0, 2.0)]), alarms.POINTS_IDENTICAL),
    (lambda: fit_circle([(0.0, 0.0), (1.0, 0.0)]), alarms.CIRCLE_PARAMETERS),
    (lambda: fit_circle([(0.0, 0.0), (1.0, 1.0), (2.0, 2.0), (3.0, 3.0)]), alarms.CIRCLE_UNDETERMINED),
    (lambda: fit_plane([(0, 0, 0), (1, 0, 0)]), alarms.FRAME_IMPOSSIBLE),
    (lambda: fit_sphere([(0, 0, 0), (1, 0, 0), (0, 1, 0)]), alarms.CIRCLE_PARAMETERS),
    (lambda: fit_sphere([(1, 0, 0), (0, 1, 0), (-1, 0, 0), (0, -1, 0), (0.6, 0.8, 0)]), alarms.CIRCLE_UNDETERMINED),
    (lambda: fit_sphere([(0, 0, 0), (1, 1, 1), (2, 2, 2)], radius=5.0), alarms.CIRCLE_UNDETERMINED),
    (lambda: fit_sphere([(1, 0, 0), (0, 1, 0), (0, 0, 1)], radius=0.0), alarms.SPHERE_DIAMETER),
    (lambda: fit_sphere([(1, 0, 0), (0, 1, 0)], radius=2.0), alarms.CIRCLE_PARAMETERS),
])
def test_failures_are_typed(call, alarm):
    with pytest.raises(MeasuringError) as err:
        call()
    assert err.value.definition is alarm


def test_known_radius_equal_to_the_circumradius_is_refused():
    """Points on a great circle with the given radius: the centre is not fixed across their plane."""
    a = np.radians([0.0, 90.0, 180.0, 270.0])
    pts = 10.0 * np.column_stack([np.cos(a), np.sin(a), np.zeros(4)])
    with pytest.raises(MeasuringError) as err:
        fit_sphere(pts, radius=10.0, center0=[0.0, 0.0, 0.5])
    assert err.value.definition is alarms.CIRCLE_UNDETERMINED


def test_minimum_points_have_no_a_posteriori_std_but_an_a_priori_one():
    fit = fit_circle([(0.0, 10.0), (-10.0, 0.0), (0.0, -10.0)])
    assert fit.dof == 0 and fit.covariance is None and np.isnan(fit.std["radius"])
    fit = fit_circle([(0.0, 10.0), (-10.0, 0.0), (0.0, -10.0)], sigma=0.001)
    assert np.isfinite(fit.std["radius"]) and fit.sigma == 0.001


def test_hand_built_line_keeps_working():
    line = LineFit(point=np.array([0.0, 1.0]), direction=np.array([1.0, 0.0]))
    assert line.n == 0 and line.rms == 0.0 and line.covariance is None
    assert np.allclose(line.normal, [0.0, 1.0])
