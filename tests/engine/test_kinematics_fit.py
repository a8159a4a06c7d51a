"""engine.kinematics (design.md §10.6): axis lines from sphere centres, exact on noise-free data,
typed failures. The centres are made here with this file's own rotation (Rodrigues), not the engine's."""

from __future__ import annotations

import math

import numpy as np
import pytest

from engine import alarms
from engine.kinematics import (
    check_sphere_diameter,
    fit_axis,
    fit_circle_3d,
    line_deviation,
    sphere_at_position,
)
from engine.types import MeasuringError


def rot(d, deg) -> np.ndarray:
    d = np.asarray(d, float) / np.linalg.norm(d)
    k = np.array([[0, -d[2], d[1]], [d[2], 0, -d[0]], [-d[1], d[0], 0]])
    t = math.radians(deg)
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * (k @ k)


def dist_to_line(point, line_point, line_dir) -> float:
    off = np.asarray(point, float) - line_point
    return float(np.linalg.norm(off - (off @ line_dir) * line_dir))


P_TRUE = np.array([0.012, 0.031, -0.027])
D_TRUE = np.array([1.0, 35e-6, -20e-6]) / np.linalg.norm([1.0, 35e-6, -20e-6])
V = np.array([0.004, -0.003, -112.5])       # ball centre − reference point at the zero position
S = np.array([420.0, 210.0, -260.0])        # sphere centre (MCS)


@pytest.mark.parametrize("angles", [[-45, 0, 45], [-60, -30, 0, 30, 60], [10, 50, 90, 130]])
def test_head_axis_exact_from_reference_point_centres(angles):
    # A_c(θ) = S − T(θ)(v), T(θ)x = p + R(d, θ)(x − p): where the axes stand when the ball is at S
    centres = [S - (P_TRUE + rot(D_TRUE, a) @ (V - P_TRUE)) for a in angles]
    line = fit_axis("head", centres, angles, V, (np.zeros(3), np.array([1.0, 0, 0])))
    assert dist_to_line(P_TRUE, line.point, line.direction) < 1e-9
    assert math.acos(min(1.0, float(line.direction @ D_TRUE))) < 1e-9
    assert line.residual < 1e-9 and line.angle_residual < 1e-7
    # the reported point is the foot of the perpendicular from the nominal point (0)
    assert abs(float(line.point @ line.direction)) < 1e-9


def test_table_axis_exact_and_turning_minus_theta():
    p = np.array([300.02, 199.97, 0.0])
    d = np.array([25e-6, -15e-6, 1.0]) / np.linalg.norm([25e-6, -15e-6, 1.0])
    s0 = np.array([380.0, 200.0, -150.0])
    angles = [0, 90, 180, 270]
    sphere = [p + rot(d, -a) @ (s0 - p) for a in angles]         # DIN 66217: the part turns −θ
    centres = [s - V for s in sphere]                             # the axes when the ball is there
    line = fit_axis("table", centres, angles, V, (np.array([300.0, 200.0, 0.0]), np.array([0, 0, 1.0])))
    assert dist_to_line(p, line.point, line.direction) < 1e-9
    assert float(line.direction @ d) > 1 - 1e-15             # +Z, not −Z
    dev = line_deviation(line, (np.array([300.0, 200.0, 0.0]), np.array([0, 0, 1.0])))
    assert dev["angle_urad"] == pytest.approx(math.hypot(25, 15), rel=1e-6)
    assert dev["offset"] == pytest.approx(math.hypot(0.02, 0.03), abs=1e-6)


def test_sphere_centre_and_diameter_from_latched_axes():
    rho = 1.995
    u = [np.array(x, float) / np.linalg.norm(x) for x in ([0, 0, 1], [1, 0, .3], [-1, 0, .3], [0, 1, .3],
                                                          [0, -1, .3], [1, 1, .8])]
    latched = [S - V + (12.5 + rho) * x for x in u]
    sphere = sphere_at_position(15.0, latched, rho)
    assert np.linalg.norm(sphere.axes_centre - (S - V)) < 1e-9
    assert sphere.diameter == pytest.approx(25.0, abs=1e-9)
    check_sphere_diameter([sphere], 25.0, 0.02)
    with pytest.raises(MeasuringError) as err:
        check_sphere_diameter([sphere], 25.03, 0.02)
    assert err.value.definition is alarms.KINEMATICS_SPHERE


@pytest.mark.parametrize("angles, alarm", [([0, 30], alarms.CIRCLE_PARAMETERS),
                                           ([0, 3, 6], alarms.KINEMATICS_AXIS),
                                           ([0, 0, 30], alarms.KINEMATICS_AXIS)])
def test_failed_fits_are_typed(angles, alarm):
    centres = [S - (P_TRUE + rot(D_TRUE, a) @ (V - P_TRUE)) for a in angles]
    with pytest.raises(MeasuringError) as err:
        fit_axis("head", centres, angles, V, (np.zeros(3), np.array([1.0, 0, 0])))
    assert err.value.definition is alarm


def test_collinear_centres_fix_no_circle():
    with pytest.raises(MeasuringError) as err:
        fit_circle_3d([[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3]])
    assert err.value.definition is alarms.KINEMATICS_AXIS
