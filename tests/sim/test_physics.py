import math

import numpy as np
import pytest
from sim_helpers import rotation

from app.machine.physics import braking_distance, eccentricity_at, latency_path, pretravel_along, rpy_matrix


def test_braking_worked_example_1_3_a():
    # measuring-math §1.3-A: v = 6 m/min, t = 0.016 s, a = 1 m/s², Kv = 1 -> 12.6 mm
    assert braking_distance(6000.0, 0.016, 1.0, 1.0) == pytest.approx(12.6, abs=1e-12)


def test_braking_worked_example_1_3_b():
    # §1.3-B: v = 300 mm/min, t = 0.004 s, a = 2 m/s², Kv = 2 -> 0.17625 mm
    assert braking_distance(300.0, 0.004, 2.0, 2.0) == pytest.approx(0.17625, abs=1e-12)


def test_latency_path_is_v_times_t():
    assert latency_path(600.0, 0.004) == pytest.approx(10.0 * 0.004)


def test_pretravel_weights_squared_components():
    table = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006, "Z-": 0.002}
    assert pretravel_along([1, 0, 0], table) == pytest.approx(0.004)
    assert pretravel_along([0, -1, 0], table) == pytest.approx(0.006)
    assert pretravel_along([0, 0, 1], table) == pytest.approx(0.002)      # Z+ falls back to Z-
    d = np.array([-1.0, 1.0, 0.0]) / math.sqrt(2)
    assert pretravel_along(d, table) == pytest.approx(0.5 * 0.005 + 0.5 * 0.003)


def test_eccentricity_turns_with_spindle():
    e = eccentricity_at([0.01, 0.0], 90.0)
    assert e == pytest.approx([0.0, 0.01, 0.0], abs=1e-15)
    e = eccentricity_at([0.01, -0.006], 180.0)
    assert e == pytest.approx([-0.01, 0.006, 0.0], abs=1e-15)


@pytest.mark.parametrize("rot", [(0, 0, 0), (10, 0, 0), (0, -20, 0), (0, 0, 33), (3, -7, 125)])
def test_rpy_matches_independent_rotation(rot):
    assert rpy_matrix(rot) == pytest.approx(rotation(rot), abs=1e-14)
