"""Whole engine loop against the analytic world of the plan tests (tests/engine/test_plan_world.py):

ring calibration (engine.plan program -> engine.calibration) with a probe whose true ball,
eccentricity and per-axis pre-travel differ from the nominal data, then hole / spigot / edge
points probed with the calibrated record (engine.plan -> engine.evaluate) recover the truth.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_plan_world import Bore, HalfSpace, Spigot, World, drive

from engine.calibration import calibrate_radius
from engine.compensation import skew_in_wcs
from engine.frames import Frame
from engine.plan import PlanContext, point_program, validate_params
from engine.planes import PLANES
from engine.tasks import evaluate
from engine.types import ProbeRecord

G17 = PLANES["G17"]
P_HAT = np.array([0.0, 0.0, 1.0])


def run(task, params, start, ctx, world, n=1):
    params = validate_params(task, params, ctx.plane)
    point, _ = drive(point_program(task, params, n, np.asarray(start, float), ctx), start, world)
    return point, params


@settings(max_examples=15, deadline=None)
@given(r_true=st.floats(1.9, 2.1), ex=st.floats(-0.03, 0.03), ey=st.floats(-0.03, 0.03),
       dx=st.floats(0.0, 0.008), dy=st.floats(0.0, 0.008), off=st.tuples(st.floats(-0.5, 0.5),
       st.floats(-0.5, 0.5)), bore=st.tuples(st.floats(-100, 100), st.floats(-100, 100)),
       bore_d=st.floats(15.0, 60.0), edge=st.floats(-50, 50))
def test_calibrate_then_measure(r_true, ex, ey, dx, dy, off, bore, bore_d, edge):
    skew = np.array([ex, ey, 0.0])
    pre = {"X+": dx, "X-": dx, "Y+": dy, "Y-": dy}
    ring_c = np.array([300.0, 200.0, -150.0])
    nominal = ProbeRecord(ball_diameter=4.0)
    ctx = PlanContext(plane=G17, probe_record=nominal, skew_wcs=np.zeros(3))
    world = World(shapes=[Bore(ring_c, 12.5, P_HAT)], r=r_true, skew=skew, pretravel=pre)
    start = ring_c + np.array([off[0], off[1], 0.0])
    ring_point, params = run("probe.radius", {"diameter": 25.0}, start, ctx, world)
    probe, shown = calibrate_radius(ring_point, nominal, G17)
    assert shown["center"]["X"] == pytest.approx(ring_c[0], abs=1e-9)
    assert probe.skew == pytest.approx((ex, ey), abs=1e-12)

    ctx = PlanContext(plane=G17, probe_record=probe, skew_wcs=skew_in_wcs(probe, Frame.identity(), 0.0))
    centre = np.array([bore[0], bore[1], -20.0])
    world = World(shapes=[Bore(centre, bore_d / 2, P_HAT)], r=r_true, skew=skew, pretravel=pre)
    point, params = run("hole.1", {"diameter": bore_d}, centre + np.array([0.3, -0.4, 0.0]), ctx, world)
    res = evaluate("hole.1", params, [point], G17, probe)
    assert res.values["center"] == pytest.approx({"X": bore[0], "Y": bore[1]}, abs=1e-9)
    assert res.values["diameter"] == pytest.approx(bore_d, abs=1e-9)

    world = World(shapes=[Spigot(centre, bore_d / 2, P_HAT, top=-20.0)], r=r_true, skew=skew,
                  pretravel=pre)
    start = centre + np.array([0.4, 0.2, 5.0])
    point, params = run("spigot.1", {"diameter": bore_d, "infeed": 10.0}, start, ctx, world)
    res = evaluate("spigot.1", params, [point], G17, probe)
    assert res.values["center"] == pytest.approx({"X": bore[0], "Y": bore[1]}, abs=1e-9)
    assert res.values["diameter"] == pytest.approx(bore_d, abs=1e-9)

    # set edge X: material at x > edge (outward normal −X)
    world = World(shapes=[HalfSpace(np.array([-1.0, 0.0, 0.0]), -edge)], r=r_true, skew=skew,
                  pretravel=pre)
    point, params = run("edge.set", {"axis": "X", "direction": "+", "setpoint": 0.0},
                        np.array([edge - 20.0, 5.0, -10.0]), ctx, world)
    res = evaluate("edge.set", params, [point], G17, probe)
    assert res.values["position"]["X"] == pytest.approx(edge, abs=1e-9)
