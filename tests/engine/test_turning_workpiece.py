"""CYCLE974 / CYCLE994 against turning.md §5–§7 (worked examples 5-A … 7-A) and an analytic truth.

The decisions of the mean-value strategy (MM §3.5) are not the engine's business here: where a
worked example needs one, the test passes the spec's decision and amount (e.g. 5-B part 1:
Mv = 0.0025) and checks the deviation D the strategy would get and the correction that results.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_turning_model import ProbeWorld, Solid, drive
from test_turning_probe import sl7_groove

from engine import alarms
from engine.turning import LatheContext, LatheProbe, LatheTool
from engine.turning_offsets import ToolTarget
from engine.turning_point import evaluate_point, point_program
from engine.turning_probe import Cycle973, evaluate_probe_calibration, probe_calibration_program
from engine.turning_twopoint import evaluate_two_point, two_point_program
from engine.turning_workpiece import WorkpieceCall, finish_workpiece, symmetrise
from engine.types import MeasuringError, MoveStep, ProbeStep, SpindleStep

PROBE = LatheTool(t=9, d=1, type=580, sl=7, l1=40.123, l2=100.456, radius=3.0)


def xz(x, z):
    return np.array([x, 0.0, z])


def wp(**trig):
    return LatheProbe(trigger=trig)


def run_974(call, start, world, record, *, ev=0.0, **kw):
    ctx = LatheContext(tool=PROBE, wp=(record,), **kw)
    point = drive(point_program(call, start, ctx), world)
    return evaluate_point(call, point, ctx, ev=ev), ctx, world


def run_994(call, start, world, record, *, ev=0.0, **kw):
    ctx = LatheContext(tool=PROBE, wp=(record,), **kw)
    point = drive(two_point_program(call, start, ctx), world)
    return evaluate_two_point(call, point, ctx, ev=ev), ctx, world


def moves(world):
    return [s for s in world.steps if isinstance(s, MoveStep) and not s.label.endswith("return")]


def test_symmetrise():
    """MM §3.2-A: _TUL 0, _TLL −0.004, _SETVAL 10 -> 9.998, ±0.002; 5-B: 44.995, ±0.005."""
    assert symmetrise(10.0, 0.0, -0.004) == pytest.approx((9.998, 0.002, -0.002))
    assert symmetrise(45.0, 0.0, -0.01) == pytest.approx((44.995, 0.005, -0.005))
    assert symmetrise(35.0, 0.015, 0.0) == pytest.approx((35.0075, 0.0075, -0.0075))


# --- 5-A: zero offset ------------------------------------------------------------------------

def test_5A_zero_offset():
    """5-A: start X36 (r 18) Z100, _SETVAL=60 on Z, _FA=1: Z -> 63.995, window to 61.995 at
    150 mm/min; the face at 60.150 switches at 63.145 -> s = 60.150, D = 0.150 -> G54 Z 200.150."""
    start = xz(18.0, 100.0)
    world = ProbeWorld(solids=[Solid(0.0, 30.0, 0.0, 60.15)], radius={"Z-": 2.995}, true_r=3.0, start=start)
    call = WorkpieceCall(cycle=974, mvar=100, setval=60.0, ma=1, tsa=1.0, knum=1, fa=1.0)
    m, ctx, world = run_974(call, start, world, wp(**{"Z-": 2.995}), diamon=True)
    (mv,) = moves(world)
    assert mv.target[2] == pytest.approx(63.995) and mv.coords == "WCS"
    (p,) = [s for s in world.steps if isinstance(s, ProbeStep)]
    assert p.distance == 2.0 and p.feed == 150.0
    assert world.touches[0][1][2] == pytest.approx(63.145, abs=1e-9)
    assert m.actual == pytest.approx(60.15, abs=1e-9) and m.deviation == pytest.approx(0.15, abs=1e-9)
    result = finish_workpiece(call, m, ctx, frame={"coarse": [0.0, 0.0, 200.0], "fine": [0.0, 0.0, 0.0]})
    assert result.frame_after["coarse"][2] == pytest.approx(200.15, abs=1e-9)
    assert result.values["decision"] == "full" and result.compensation == pytest.approx(0.15)
    assert result.ovr[0] == 60.0 and result.ovr[4] == pytest.approx(60.15) and result.ovr[16] == pytest.approx(0.15)
    assert result.ovi[0] == 1 and result.ovi[2] == 974
    assert result.fix.position == {"Z": pytest.approx(60.15)}


def test_zero_offset_on_x_halves_and_safe_area():
    """ZO on X with DIAMON: the frame moves by D/2 (radius); |D| > _TSA -> 61303; fine mode."""
    start = xz(40.0, 20.0)
    world = ProbeWorld(solids=[Solid(0.0, 30.02, 0.0, 50.0)], radius={"X-": 2.995}, true_r=3.0, start=start)
    call = WorkpieceCall(cycle=974, mvar=100, setval=60.0, ma=2, tsa=1.0, knum=1, fa=1.0)
    m, ctx, _ = run_974(call, start, world, wp(**{"X-": 2.995}), diamon=True, fine_offset=True)
    assert m.actual == pytest.approx(60.04, abs=1e-9)
    result = finish_workpiece(call, m, ctx, frame={"coarse": [1.0, 0.0, 0.0], "fine": [0.5, 0.0, 0.0]})
    assert result.frame_after["fine"][0] == pytest.approx(0.52, abs=1e-9) and result.frame_after["coarse"][0] == 1.0
    with pytest.raises(MeasuringError) as err:
        finish_workpiece(WorkpieceCall(cycle=974, mvar=100, setval=60.0, ma=2, tsa=0.03, knum=1, fa=1.0), m, ctx)
    assert err.value.definition is alarms.SAFE_AREA
    only = finish_workpiece(WorkpieceCall(cycle=974, mvar=100, setval=60.0, ma=2, tsa=1.0, knum=0, fa=1.0), m, ctx,
                            frame={"coarse": [1.0, 0.0, 0.0], "fine": [0.5, 0.0, 0.0]})
    assert only.values["decision"] == "none" and only.compensation == 0.0 and only.frame_after is None


# --- 5-B: tool offset, OD and ID -------------------------------------------------------------

def od_world(radius, start, eff=2.995, ecc=(0.0, 0.0), key="X-"):
    return ProbeWorld(solids=[Solid(0.0, radius, -40.0, 60.0, ecc=ecc)], radius={key: eff, "X+": eff}, true_r=3.0,
                      start=start)


CALL_5B = dict(tzl=0.002, tmv=0.005, tdif=0.04, tsa=0.5, fa=1.0, tul=0.0, tll=-0.01, tnum=7, knum=1, evnum=13,
               k=2.0, ma=2)


@pytest.mark.parametrize("latched, actual, dev", [(25.4955, 45.001, 0.004), (25.4995, 45.009, 0.012),
                                                  (25.490, 44.990, -0.007), (25.525, 45.060, 0.063),
                                                  (25.795, 45.600, 0.603)])
def test_5B_parts(latched, actual, dev):
    """5-B table: latched ball centre -> act (dia) and D = act − 0.002 − 44.995; positioning
    26.495 (display X52.990), window to 24.495."""
    start = xz(45.0, 30.0)
    call = WorkpieceCall(cycle=974, mvar=0, setval=45.0, **CALL_5B)
    m, _, world = run_974(call, start, od_world(latched - 2.995, start), wp(**{"X-": 2.995}), ev=0.002,
                          diamon=True, chbit={4: 1})
    (mv,) = moves(world)
    assert mv.target[0] == pytest.approx(26.495)
    assert world.touches[0][1][0] == pytest.approx(latched, abs=1e-9)
    assert m.actual == pytest.approx(actual, abs=1e-9)
    assert m.deviation == pytest.approx(dev, abs=1e-9)
    assert m.setpoint_eff == pytest.approx(44.995) and m.upper_eff == pytest.approx(0.005)
    assert m.scale == 0.5 and m.direction == -1


def test_5B_corrections():
    """5-B: the strategy's amounts give c = −A/2 on L1 wear of T7 D1: part 1 Mv 0.0025 ->
    −0.00125; part 2 (62304) D 0.012 -> −0.006; part 3 (62305) −0.007 -> +0.0035; part 4 none."""
    start = xz(45.0, 30.0)
    call = WorkpieceCall(cycle=974, mvar=0, setval=45.0, **CALL_5B)
    t7 = LatheTool(t=7, d=1, type=500, sl=3, l1=60.0, l2=30.0, radius=0.8, wear_l1=0.01)
    m, ctx, _ = run_974(call, start, od_world(22.5005, start), wp(**{"X-": 2.995}), ev=0.002, diamon=True,
                        chbit={4: 1})
    cases = [("mean", 0.0025, None, -0.00125), ("oversize", 0.012, alarms.OVERSIZE, -0.006),
             ("undersize", -0.007, alarms.UNDERSIZE, 0.0035), ("dimension_difference", 0.063,
                                                               alarms.DIMENSION_DIFFERENCE, 0.0)]
    for decision, amount, warning, c in cases:
        result = finish_workpiece(call, m, ctx, decision=decision, amount=amount, warning=warning, tool=t7,
                                  mean_value=0.0)
        assert result.compensation == pytest.approx(c, abs=1e-12)
        assert result.quantity == "l1"
        assert result.ovr[20] == pytest.approx(c, abs=1e-12)
        if c:
            assert result.tool_after["wear"]["l1"] == pytest.approx(0.01 + c, abs=1e-12)
            assert result.tool_after["l1"] == 60.0
        else:
            assert result.tool_after is None
        assert result.ovi[9] == (warning.number if warning else 0)
    assert result.ovr[0] == pytest.approx(44.995) and result.ovr[8] == pytest.approx(0.005)
    assert result.ovr[12] == pytest.approx(-0.005) and result.ovr[30] == 0.002
    assert result.ovi[6] == 13 and result.ovi[7] == 13 and result.ovi[8] == 7 and result.ovi[4] == 2


def test_5B_inside_diameter():
    """5-B ID 35 by T8: from radius 0 the probe travels +X with _WP[0,4]; SETVAL_eff 35.0075;
    D = +0.012 after EV -> c = −0.006 on T8's L1 wear (the same sign as an oversized OD, §0.11)."""
    start = xz(0.0, 40.0)
    true_r = 0.5 * (35.0075 + 0.012 + 0.003)                 # ID so that D (after EV 0.003) = +0.012
    world = ProbeWorld(solids=[Solid(true_r, 40.0, -20.0, 60.0)], radius={"X+": 2.993}, true_r=3.0, start=start)
    call = WorkpieceCall(cycle=974, mvar=0, setval=35.0, **{**CALL_5B, "tul": 0.015, "tll": 0.0, "tnum": 8, "evnum": 14})
    m, ctx, world = run_974(call, start, world, wp(**{"X+": -2.993}), ev=0.003, diamon=True, chbit={4: 1})
    assert world.steps[0].target[0] == pytest.approx(17.5 - 2.993 - 1.0)
    assert m.direction == 1 and m.deviation == pytest.approx(0.012, abs=1e-9)
    assert m.setpoint_eff == pytest.approx(35.0075)
    result = finish_workpiece(call, m, ctx, decision="oversize", amount=m.deviation, warning=alarms.OVERSIZE)
    assert result.compensation == pytest.approx(-0.006, abs=1e-9)


# --- 5-C: reversal ---------------------------------------------------------------------------------

CALL_5C = dict(tul=0.0, tll=-0.01, ma=2, sta1=0.0, knum=1, tnum=7, tzl=0.002, tdif=0.4, tsa=1.0, fa=2.0)


def test_5C_reversal():
    """5-C: Ø45.006, e = 0.030 in +X at SPOS 0: switches 25.528 / 25.468 -> s 22.533 / 22.473 ->
    act 45.006, D = 0.011 -> c = −0.0055; without reversal act 45.066, D 0.071, c −0.0355."""
    start = xz(45.0, 30.0)
    world = od_world(22.503, start, ecc=(0.03, 0.0))
    call = WorkpieceCall(cycle=974, mvar=1000, setval=45.0, **CALL_5C)
    m, ctx, world = run_974(call, start, world, wp(**{"X-": 2.995}), diamon=True)
    spos = [s.angle for s in world.steps if isinstance(s, SpindleStep)]
    assert spos == [0.0, 180.0]
    assert [rec[0] for _, rec, _ in world.touches] == pytest.approx([25.528, 25.468], abs=1e-9)
    assert m.surfaces == pytest.approx({"P1 0": 22.533, "P1 180": 22.473}, abs=1e-9)
    assert m.actual == pytest.approx(45.006, abs=1e-9) and m.deviation == pytest.approx(0.011, abs=1e-9)
    (p,) = {s.distance for s in world.steps if isinstance(s, ProbeStep)}
    assert p == 4.0 and moves(world)[0].feed == 1000.0
    assert isinstance(world.steps[0], SpindleStep)                 # SPOS _STA1 with the probe at its start
    result = finish_workpiece(call, m, ctx, decision="oversize", amount=m.deviation, warning=alarms.OVERSIZE)
    assert result.compensation == pytest.approx(-0.0055, abs=1e-9)
    once = WorkpieceCall(cycle=974, mvar=0, setval=45.0, **CALL_5C)
    m0, ctx0, _ = run_974(once, start, od_world(22.503, start, ecc=(0.03, 0.0)), wp(**{"X-": 2.995}), diamon=True)
    assert m0.actual == pytest.approx(45.066, abs=1e-9) and m0.deviation == pytest.approx(0.071, abs=1e-9)
    assert m0.actual - m.actual == pytest.approx(2 * 0.03, abs=1e-9)           # twice e_X
    r0 = finish_workpiece(once, m0, ctx0, decision="dimension_difference", amount=0.0)
    assert r0.compensation == 0.0
    assert finish_workpiece(once, m0, ctx0, decision="full", amount=m0.deviation).compensation == pytest.approx(-0.0355)


def test_5C_eccentricity_in_y_residual():
    """e = 0.030 in Y: the reversal leaves −(R + r) + sqrt((R + r)² − e²) ≈ −1.8e-5 in s (§5.6, §11)."""
    start = xz(45.0, 30.0)
    m, _, _ = run_974(WorkpieceCall(cycle=974, mvar=1000, setval=45.0, **CALL_5C), start, od_world(22.503, start, ecc=(0.0, 0.03)),
                      wp(**{"X-": 2.995}), diamon=True)
    residual = math.sqrt((22.503 + 3.0) ** 2 - 0.03 ** 2) - (22.503 + 3.0)
    assert m.surface - 22.503 == pytest.approx(residual, abs=1e-9)
    assert residual == pytest.approx(-1.8e-5, abs=1e-6)


@settings(max_examples=50, deadline=None)
@given(radius=st.floats(5.0, 60.0), ex=st.floats(-0.2, 0.2), angle=st.floats(0.0, 359.0),
       eff=st.floats(2.9, 3.0), diamon=st.booleans(), nmsp=st.integers(1, 3))
def test_reversal_truth(radius, ex, angle, eff, diamon, nmsp):
    """Any X eccentricity at any _STA1: the reversal gives the true diameter; a single point is
    off by the eccentricity's X component at that angle (twice in the diameter)."""
    start = xz(radius + 6.0, 30.0)
    setval = 2 * radius if diamon else radius
    call = WorkpieceCall(cycle=974, mvar=1000, setval=setval, ma=2, sta1=angle, fa=2.0, tsa=5.0, tdif=5.0, nmsp=nmsp)
    m, _, _ = run_974(call, start, od_world(radius, start, eff=eff, ecc=(ex, 0.0)), wp(**{"X-": eff}), diamon=diamon)
    a = math.radians(angle)
    rho = radius + 3.0                     # the ball centre's circle about the clamped axis (§5.6, §11)
    residual = math.sqrt(rho ** 2 - (ex * math.sin(a)) ** 2) - rho          # second order in e_Y(φ)
    assert m.surface == pytest.approx(radius + residual, abs=1e-9)
    single = WorkpieceCall(cycle=974, mvar=0, setval=setval, ma=2, fa=2.0, tsa=5.0, tdif=5.0)
    world = od_world(radius, start, eff=eff, ecc=(ex, 0.0))
    world.angle = angle
    m1, _, _ = run_974(single, start, world, wp(**{"X-": eff}), diamon=diamon)
    assert m1.surface == pytest.approx(radius + ex * math.cos(a) + residual, abs=1e-9)


# --- 6-A / 6-B: two points ---------------------------------------------------------------------------

CALL_6A = dict(tll=-0.01, tul=0.0, ma=2, sza=55.0, szo=55.0, knum=1, k=3.0, tzl=0.002, tmv=0.005, tdif=0.04,
               tsa=0.5, fa=1.0, tnum=8, evnum=3)
WP_6A = LatheProbe.from_wp([6.0, 0.0, 0.0, 2.995, -2.993, 0, 0, 0, 0, 0, 0])


def world_6a(radius=22.4995, start=None):
    return ProbeWorld(solids=[Solid(0.0, radius, -40.0, 50.0, ecc=(0.02, 0.0))], radius={"X-": 2.995, "X+": 2.993},
                      true_r=3.0, start=start)


def test_6A_outside_with_protection_zone():
    """6-A: P1 26.495 -> 24.495, switch 25.5145 -> s1 22.5195; detour X27.5, Z55, X−27.5, Z30;
    P2 −26.493 -> −24.493, switch −25.4725 -> s2 −22.4795; D_act 44.999, D 0.003; ends −26.493."""
    start = xz(30.0, 30.0)
    call = WorkpieceCall(cycle=994, mvar=2, setval=45.0, **CALL_6A)
    m, ctx, world = run_994(call, start, world_6a(start=start), WP_6A, ev=0.001, diamon=True, chbit={4: 1})
    targets = [(round(s.target[0], 9), round(s.target[2], 9)) for s in moves(world)]
    assert targets == [(26.495, 30.0), (27.5, 30.0), (27.5, 55.0), (-27.5, 55.0), (-27.5, 30.0), (-26.493, 30.0)]
    assert [rec[0] for _, rec, _ in world.touches] == pytest.approx([25.5145, -25.4725], abs=1e-9)
    assert m.surfaces == pytest.approx({"P1": 22.5195, "P2": -22.4795}, abs=1e-9)
    assert m.actual == pytest.approx(44.999, abs=1e-9) and m.deviation == pytest.approx(0.003, abs=1e-9)
    assert world.pos[0] == pytest.approx(-26.493)
    result = finish_workpiece(call, m, ctx, decision="none", amount=0.0, mean_value=0.0016)
    assert result.compensation == 0.0 and result.ovr[31] == pytest.approx(0.0016)
    assert result.ovr[2] == pytest.approx(44.995) and result.ovr[6] == pytest.approx(44.999)   # _MA=2 only
    assert result.ovr[1] == 0.0 and result.ovr[5] == 0.0
    t8 = LatheTool(t=8, d=1, type=500, sl=3, l1=70.0, l2=20.0, radius=0.4)
    result = finish_workpiece(call, m, ctx, decision="mean", amount=0.0025666666666666667, tool=t8)
    assert result.compensation == pytest.approx(-0.0012833333, abs=1e-9)
    assert result.tool_after["wear"]["l1"] == pytest.approx(-0.0012833333, abs=1e-9)


def test_6A_next_part():
    """6-A next part, D_act 45.0005 -> D 0.0045 (the strategy's Mv 0.0025667 is then > _TZL)."""
    start = xz(30.0, 30.0)
    m, _, _ = run_994(WorkpieceCall(cycle=994, mvar=2, setval=45.0, **CALL_6A), start, world_6a(radius=22.50025, start=start),
                      WP_6A, ev=0.001, diamon=True)
    assert m.actual == pytest.approx(45.0005, abs=1e-9) and m.deviation == pytest.approx(0.0045, abs=1e-9)


def test_6B_ball_diameter():
    """6-B: _CHBIT[7]=1 with _WP[0,0] = 6.000: D_act = (25.5145 + 25.4725) − 6 = 44.987."""
    start = xz(30.0, 30.0)
    m, _, _ = run_994(WorkpieceCall(cycle=994, mvar=2, setval=45.0, **CALL_6A), start, world_6a(start=start), WP_6A, ev=0.001,
                      diamon=True, chbit={7: 1})
    assert m.actual == pytest.approx(44.987, abs=1e-9)


def test_6A_inside_and_variants():
    """The ID 35 of 6-A: start (Z30, X20 -> radius 10) inside; P1 +X, P2 −X across at Z30
    (_MVAR=2); _MVAR=1 crosses via Z_det; an OD start with _MVAR=1 -> 61307; zone too small -> 61334."""
    bore = 17.5 + 0.004
    solids = [Solid(bore, 40.0, -40.0, 50.0)]
    start = xz(10.0, 30.0)
    world = ProbeWorld(solids=solids, radius={"X-": 2.995, "X+": 2.993}, true_r=3.0, start=start)
    call = WorkpieceCall(cycle=994, mvar=2, setval=35.0, **{**CALL_6A, "tul": 0.015, "tnum": 9, "evnum": 4})
    m, ctx, world = run_994(call, start, world, WP_6A, diamon=True)
    assert m.inside and m.actual == pytest.approx(35.008, abs=1e-9)
    assert [s.direction[0] for s in world.steps if isinstance(s, ProbeStep)] == [1.0, -1.0]
    assert all(s.target[2] == 30.0 for s in moves(world))
    result = finish_workpiece(call, m, ctx, decision="full", amount=0.002)
    assert result.compensation == pytest.approx(-0.001)
    r_target = ToolTarget(t=9, d=1, quantity="radius")
    result = finish_workpiece(call, m, ctx, decision="full", amount=0.002, target=r_target)
    assert result.compensation == pytest.approx(0.001) and result.quantity == "radius"     # ID radius: +Δ
    world = ProbeWorld(solids=solids, radius={"X-": 2.995, "X+": 2.993}, true_r=3.0, start=start)
    m1, _, world = run_994(WorkpieceCall(cycle=994, mvar=1, setval=35.0, **CALL_6A), start, world, WP_6A, diamon=True)
    assert m1.actual == pytest.approx(35.008, abs=1e-9)
    assert max(s.target[2] for s in moves(world)) == 55.0
    with pytest.raises(MeasuringError) as err:
        run_994(WorkpieceCall(cycle=994, mvar=1, setval=45.0, **CALL_6A), xz(30.0, 30.0), world_6a(start=xz(30.0, 30.0)), WP_6A,
                diamon=True)
    assert err.value.definition is alarms.WRONG_VARIANT
    with pytest.raises(MeasuringError) as err:
        run_994(WorkpieceCall(cycle=994, mvar=2, setval=45.0, **{**CALL_6A, "szo": 50.0}), xz(30.0, 30.0),
                world_6a(start=xz(30.0, 30.0)), WP_6A, diamon=True)
    assert err.value.definition is alarms.PROTECTION_ZONE


@settings(max_examples=40, deadline=None)
@given(radius=st.floats(10.0, 50.0), ex=st.floats(-0.3, 0.3), angle=st.floats(0.0, 359.0),
       pm=st.floats(2.9, 3.0), pp=st.floats(2.9, 3.0), diamon=st.booleans())
def test_two_point_truth(radius, ex, angle, pm, pp, diamon):
    """OD with any eccentricity at any spindle angle: the X component cancels in s1 − s2 (§6.4);
    the Y component leaves the exact chord 2·(sqrt((R + r)² − e_Y²) − r)."""
    start = xz(radius + 8.0, 30.0)
    setval = 2 * radius if diamon else radius
    zone = radius + 6.0
    call = WorkpieceCall(cycle=994, mvar=2, setval=setval, ma=2, sza=60.0, szo=2 * zone if diamon else zone, fa=2.0, tsa=5.0,
                    tdif=5.0)
    world = ProbeWorld(solids=[Solid(0.0, radius, -40.0, 50.0, ecc=(ex, 0.0))], radius={"X-": pm, "X+": pp},
                       true_r=3.0, start=start, angle=angle)
    record = LatheProbe(trigger={"X-": pm, "X+": -pp})
    m, _, _ = run_994(call, start, world, record, diamon=diamon)
    e_y = ex * math.sin(math.radians(angle))
    chord = 2.0 * (math.sqrt((radius + 3.0) ** 2 - e_y ** 2) - 3.0)
    assert m.actual == pytest.approx(chord if diamon else chord / 2.0, abs=1e-9)


def test_two_point_on_z():
    """_MA=1 (SL 8 probe): faces at ±_SETVAL, outside: P1 −Z, across via X to the zone, P2 +Z."""
    probe = LatheTool(t=9, d=1, type=580, sl=8, l1=40.0, l2=100.0, radius=2.0)
    solids = [Solid(0.0, 30.0, -20.01, 19.99)]
    start = xz(20.0, 30.0)
    world = ProbeWorld(solids=solids, radius={"Z-": 1.99, "Z+": 1.98}, true_r=2.0, start=start)
    ctx = LatheContext(tool=probe, wp=(LatheProbe(trigger={"Z-": 1.99, "Z+": -1.98}),), diamon=True)
    call = WorkpieceCall(cycle=994, mvar=2, setval=20.0, ma=1, szo=80.0, fa=1.0, tsa=1.0, tdif=1.0)
    point = drive(two_point_program(call, start, ctx), world)
    m = evaluate_two_point(call, point, ctx)
    assert m.actual == pytest.approx(20.0, abs=1e-9) and m.scale == 1.0
    assert max(s.target[0] for s in moves(world)) == pytest.approx(40.0)


# --- §7: the complete example ---------------------------------------------------------------------

def test_7_complete_example():
    """turning.md §7 / 7-A: calibrate −Z and −X in groove 1 (CYCLE973 _MVAR=13), then four
    CYCLE974 points; P2 Z50.012 -> D +0.012 > 0.01 -> L2 wear of T2 −0.012; P3 Ø150.002 ->
    SETVAL_eff 150.001, TUL_eff 0.004, D 0.001 (no correction with _K=1, _TZL 0.002)."""
    probe = LatheTool(t=8, d=1, type=580, sl=7, l1=40.123, l2=100.456, radius=3.0)
    kb = (60.123, 50.054, 15.021, 0.0, 0.0, 0.0, 0.0)
    eff = {"Z-": 2.995, "X-": 2.994}
    groove = ProbeWorld(solids=sl7_groove(), radius=eff, true_r=3.0, start=xz(150.0, 150.0))
    record = LatheProbe()
    pos = xz(150.0, 150.0)
    for ma in (1, 2):
        ctx = LatheContext(tool=probe, wp=(record,), kb=(kb,), diamon=True)
        call = Cycle973(mvar=13, ma=ma, md=1, calnum=1, tzl=0.0, tsa=3.5, fa=1.0)
        point = drive(probe_calibration_program(call, pos, ctx), groove)
        record = evaluate_probe_calibration(call, point, ctx).record
        pos = groove.pos
    assert record.trigger_value("Z-") == pytest.approx(2.995, abs=1e-9)
    assert record.trigger_value("X-") == pytest.approx(2.994, abs=1e-9)
    # the part (WCS): Ø200 to Z50 (P1, face P2 at 50.012), Ø150.002 to Z190 (P3), bore bottom Z99.997 (P4)
    solids = [Solid(0.0, 99.998, 0.0, 50.012), Solid(40.0, 75.001, 0.0, 190.0), Solid(0.0, 40.0, 0.0, 99.997)]
    points = [  # start (display X), _MA, _SETVAL, _TUL, _TLL, expected act, D
        ((220.0, 40.0), 2, 200.0, 0.0, -0.01, 199.996, 0.001),
        ((175.0, 70.0), 1, 50.0, 0.01, -0.01, 50.012, 0.012),
        ((175.0, 180.0), 2, 150.0, 0.005, -0.003, 150.002, 0.001),
        ((50.0, 150.0), 1, 100.0, 0.01, -0.01, 99.997, -0.003),
    ]
    ctx = LatheContext(tool=probe, wp=(record,), diamon=True)
    found = []
    for (x, z), ma, setval, tul, tll, act, dev in points:
        start = xz(x / 2.0, z)
        world = ProbeWorld(solids=solids, radius=eff, true_r=3.0, start=start)
        call = WorkpieceCall(cycle=974, mvar=0, setval=setval, ma=ma, tul=tul, tll=tll, tzl=0.002, tdif=0.2, tsa=0.3, knum=1,
                        tnum=len(found) + 1, fa=1.0)
        m = evaluate_point(call, drive(point_program(call, start, ctx), world), ctx)
        assert m.actual == pytest.approx(act, abs=1e-9) and m.deviation == pytest.approx(dev, abs=1e-9)
        found.append((call, m))
    call2, m2 = found[1]
    t2 = LatheTool(t=2, d=1, type=500, sl=3, l1=50.0, l2=30.0, radius=0.8)
    result = finish_workpiece(call2, m2, ctx, decision="oversize", amount=m2.deviation, warning=alarms.OVERSIZE,
                              tool=t2)
    assert result.quantity == "l2" and result.compensation == pytest.approx(-0.012, abs=1e-9)
    assert result.tool_after["wear"]["l2"] == pytest.approx(-0.012, abs=1e-9)
    call3, m3 = found[2]
    assert m3.setpoint_eff == pytest.approx(150.001) and m3.upper_eff == pytest.approx(0.004)
    call4, m4 = found[3]
    result = finish_workpiece(call4, m4, ctx, decision="mean", amount=m4.deviation)
    assert result.quantity == "l2" and result.compensation == pytest.approx(0.003, abs=1e-9)   # face low: L2 up


# --- checks ------------------------------------------------------------------------------------------

def test_point_checks():
    start = xz(45.0, 30.0)
    record = wp(**{"X-": 2.995})
    cases = [
        (WorkpieceCall(cycle=974, mvar=5, setval=45.0), {}, alarms.WRONG_VARIANT),
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, ma=3), {}, alarms.MEASURING_AXIS),
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, k=0.0, knum=1, tnum=7), {}, alarms.WEIGHTING_FACTOR),
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, knum=3001, tnum=7), {}, alarms.KNUM_DIGIT4),
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, knum=20001, tnum=7), {}, alarms.KNUM_DIGIT5),
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, knum=500001, tnum=7), {}, alarms.KNUM_DIGIT6),
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, knum=4000001, tnum=7), {}, alarms.KNUM_DIGIT7),
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, knum=1000, tnum=7), {}, alarms.D_NUMBER),
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, knum=1), {}, alarms.TOOL_NUMBER),
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, knum=1001001, tnum=7, dlnum=9), {}, alarms.DL_NUMBER),
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, knum=2100000), {}, alarms.TOOL_ENVIRONMENT),
        (WorkpieceCall(cycle=974, mvar=100, setval=45.0, knum=777), {}, alarms.ZO_NUMBER),
        (WorkpieceCall(cycle=974, mvar=1000, setval=45.0), {"spos": False}, alarms.NEEDS_SPOS),
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, prnum=2), {}, alarms.PROBE_NUMBER),
        (WorkpieceCall(cycle=974, mvar=0, setval=60.0, ma=2), {}, alarms.NOT_CALIBRATED_IN_PLANE),   # +X: _WP[0,4] = 0
        (WorkpieceCall(cycle=974, mvar=0, setval=45.0, ma=1), {}, alarms.CUTTING_EDGE_POSITION),     # start Z30 < 45: +Z
    ]
    for call, kw, alarm in cases:
        ctx = LatheContext(tool=PROBE, wp=(record,), diamon=False, **kw)
        with pytest.raises(MeasuringError) as err:
            next(point_program(call, start, ctx))
        assert err.value.definition is alarm, call


def test_setup_sum_offsets():
    """_KNUM digit 7 = 1: the setup/sum offset _DLNUM (MM §2.3): _CHBIT[8]=0 into the sum offset."""
    start = xz(45.0, 30.0)
    call = WorkpieceCall(cycle=974, mvar=0, setval=45.0, **{**CALL_5B, "knum": 1001001, "dlnum": 2})
    m, ctx, _ = run_974(call, start, od_world(22.5005, start), wp(**{"X-": 2.995}), ev=0.002, diamon=True)
    tool = {"t": 7, "type": 500, "sl": 3, "l1": 60.0, "l2": 30.0, "radius": 0.8,
            "dl": {2: {"setup": {"l1": 0.1}, "sum": {"l1": 0.02}}}}
    result = finish_workpiece(call, m, ctx, decision="full", amount=0.004, tool=tool)
    assert result.tool_after["dl"][2]["sum"]["l1"] == pytest.approx(0.018)
    with pytest.raises(MeasuringError) as err:
        finish_workpiece(call, m, ctx, decision="full", amount=0.004, tool={**tool, "dl": {}})
    assert err.value.definition is alarms.SETUP_OFFSET_MISSING


@settings(max_examples=30, deadline=None)
@given(skew_x=st.floats(-0.1, 0.1), d_plus=st.floats(0.0, 0.03), d_minus=st.floats(0.0, 0.03),
       od=st.floats(15.0, 40.0), bore=st.floats(8.0, 12.0), diamon=st.booleans())
def test_groove_calibration_then_measuring(skew_x, d_plus, d_minus, od, bore, diamon):
    """End to end: CYCLE973 in the groove (both X directions, skew, asymmetric pre-travel), then
    CYCLE974 on an OD (−X) and in a bore (+X) and CYCLE994 on the OD with the new record: every
    result is the truth to 1e-9 (the stored skew absorbs the asymmetry consistently, §4.4, §12 Q16)."""
    probe = LatheTool(t=8, d=1, type=580, sl=7, l1=40.0, l2=100.0, radius=3.0)
    eff = {"X+": 3.0 - d_plus, "X-": 3.0 - d_minus, "Z-": 3.0}
    kb = (60.123, 50.054, 15.021, 0.0, 0.0, 0.0, 0.0)
    start = np.array([95.0, 0.0, 125.0])
    groove = ProbeWorld(solids=sl7_groove(), radius=eff, true_r=3.0, skew=(0.0, skew_x), start=start)
    ctx = LatheContext(tool=probe, wp=(LatheProbe(),), kb=(kb,))
    call = Cycle973(mvar=12013, ma=2, calnum=1, tzl=0.0, tsa=5.0, fa=1.0)
    record = evaluate_probe_calibration(call, drive(probe_calibration_program(call, start, ctx), groove), ctx).record
    solids = [Solid(bore, od, -40.0, 60.0)]
    scale = 2.0 if diamon else 1.0
    for setval, s0, key in ((od * scale, od + 8.0, "X-"), (bore * scale, 0.5 * bore, "X+")):
        call = WorkpieceCall(cycle=974, mvar=0, setval=setval, ma=2, fa=1.5, tsa=5.0, tdif=5.0)
        world = ProbeWorld(solids=solids, radius=eff, true_r=3.0, skew=(0.0, skew_x), start=xz(s0, 30.0))
        m, _, _ = run_974(call, xz(s0, 30.0), world, record, diamon=diamon)
        assert m.actual == pytest.approx(setval, abs=1e-9), key
    call = WorkpieceCall(cycle=994, mvar=2, setval=od * scale, ma=2, sza=65.0, szo=(od + 5.0) * scale, fa=1.5, tsa=5.0, tdif=5.0)
    world = ProbeWorld(solids=[Solid(0.0, od, -40.0, 60.0)], radius=eff, true_r=3.0, skew=(0.0, skew_x),
                       start=xz(od + 8.0, 30.0))
    m, _, _ = run_994(call, xz(od + 8.0, 30.0), world, record, diamon=diamon)
    assert m.actual == pytest.approx(od * scale if diamon else od, abs=1e-9)
