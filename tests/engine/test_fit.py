"""engine.fit: circles, lines, planes against analytic truth; degenerate cases raise the alarm."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.fit import LineFit, fit_circle, fit_line, fit_plane, intersect_lines
from engine.types import MeasuringError

coord = st.floats(-500.0, 500.0, allow_nan=False)
SETTINGS = settings(max_examples=60, deadline=None)


def test_circle_example_6a():
    """measuring-math §6, worked example 6-A: (0,10), (−10,0), (0,−10) -> centre 0, R 10."""
    fit = fit_circle([(0.0, 10.0), (-10.0, 0.0), (0.0, -10.0)])
    assert np.allclose(fit.center, [0.0, 0.0], atol=1e-12)
    assert fit.radius == pytest.approx(10.0, abs=1e-12)


def test_circle_example_6b_collinear():
    """measuring-math §6, worked example 6-B: collinear points -> 61316."""
    with pytest.raises(MeasuringError) as err:
        fit_circle([(0.0, 0.0), (1.0, 1.0), (2.0, 2.0)])
    assert err.value.alarm == 61316


def test_circle_too_few_points():
    with pytest.raises(MeasuringError) as err:
        fit_circle([(0.0, 0.0), (1.0, 1.0)])
    assert err.value.alarm == 61317


def test_circle_coincident_points():
    with pytest.raises(MeasuringError) as err:
        fit_circle([(5.0, 5.0), (5.0, 5.0), (5.0, 5.0), (5.0, 5.0)])
    assert err.value.alarm == 61316


@SETTINGS
@given(cx=coord, cy=coord, r=st.floats(0.5, 200.0),
       angles=st.lists(st.floats(0.0, 360.0), min_size=3, max_size=8, unique=True))
def test_circle_recovers_truth(cx, cy, r, angles):
    a = np.radians(np.array(angles))
    # points must not be (nearly) coincident: keep only well separated angles
    a = np.sort(a)
    gaps = np.diff(np.concatenate([a, [a[0] + 2 * np.pi]]))
    if np.min(gaps) < 0.05:
        return
    pts = np.column_stack([cx + r * np.cos(a), cy + r * np.sin(a)])
    fit = fit_circle(pts)
    assert np.allclose(fit.center, [cx, cy], atol=1e-9)
    assert fit.radius == pytest.approx(r, abs=1e-9)
    assert fit.residual < 1e-9


def test_circle_least_squares_with_noise_is_geometric():
    """4 points, one off the circle: the geometric fit's residual is minimal vs. the true circle."""
    pts = np.array([(10.0, 0.0), (0.0, 10.0), (-10.0, 0.0), (0.0, -10.2)])
    fit = fit_circle(pts)

    def cost(c, r):
        return np.sum((np.linalg.norm(pts - c, axis=1) - r) ** 2)

    best = cost(fit.center, fit.radius)
    for dc in ([1e-4, 0], [0, 1e-4], [-1e-4, 0], [0, -1e-4]):
        for dr in (-1e-4, 0.0, 1e-4):
            assert best <= cost(fit.center + np.array(dc), fit.radius + dr) + 1e-15


@SETTINGS
@given(px=coord, py=coord, phi=st.floats(-180.0, 180.0), t1=st.floats(-100, 100),
       dt=st.floats(0.5, 200.0))
def test_line_two_points_direction_p1_to_p2(px, py, phi, t1, dt):
    u = np.array([np.cos(np.radians(phi)), np.sin(np.radians(phi))])
    p1, p2 = np.array([px, py]) + t1 * u, np.array([px, py]) + (t1 + dt) * u
    line = fit_line([p1, p2])
    assert np.allclose(line.direction, u, atol=1e-9)
    # the point lies on the true line
    w = line.point - np.array([px, py])
    assert abs(w[0] * u[1] - w[1] * u[0]) < 1e-9


def test_line_many_points_total_least_squares():
    pts = np.array([(0.0, 1.0), (1.0, 2.0), (2.0, 3.0), (3.0, 4.0)])
    line = fit_line(pts)
    assert np.allclose(line.direction, np.array([1.0, 1.0]) / np.sqrt(2), atol=1e-12)


def test_line_identical_points():
    with pytest.raises(MeasuringError) as err:
        fit_line([(3.0, 4.0), (3.0, 4.0)])
    assert err.value.alarm == 61367


def test_intersect_lines_and_parallel():
    a = LineFit(point=np.array([0.0, 1.0]), direction=np.array([1.0, 0.0]))
    b = LineFit(point=np.array([5.0, -3.0]), direction=np.array([0.0, 1.0]))
    assert np.allclose(intersect_lines(a, b), [5.0, 1.0])
    c = LineFit(point=np.array([0.0, 7.0]), direction=np.array([-1.0, 0.0]))
    with pytest.raises(MeasuringError) as err:
        intersect_lines(a, c)
    assert err.value.alarm == 61368


@SETTINGS
@given(nx=st.floats(-1, 1), ny=st.floats(-1, 1), q=st.tuples(coord, coord, coord),
       uv=st.lists(st.tuples(st.floats(-50, 50), st.floats(-50, 50)), min_size=3, max_size=5))
def test_plane_recovers_normal(nx, ny, q, uv):
    n = np.array([nx, ny, 1.0])
    n /= np.linalg.norm(n)
    e1 = np.cross(n, [1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.cross(n, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(n, e1)
    uv = np.array(uv)
    if np.linalg.svd(uv - uv.mean(axis=0), compute_uv=False)[-1] < 1.0:
        return                                   # (nearly) collinear in-plane layout
    pts = np.array(q) + uv[:, :1] * e1 + uv[:, 1:] * e2
    fit = fit_plane(pts)
    assert abs(abs(fit.normal @ n) - 1.0) < 1e-12
    assert np.all(np.abs((pts - fit.point) @ fit.normal) < 1e-9)


def test_plane_collinear():
    with pytest.raises(MeasuringError) as err:
        fit_plane([(0.0, 0.0, 0.0), (1.0, 1.0, 1.0), (2.0, 2.0, 2.0)])
    assert err.value.alarm == 61411
