"""CYCLE973 against turning.md §4 (worked examples 4-A, 4-B) and an analytic truth."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_turning_model import ProbeWorld, Solid, drive

from engine import alarms
from engine.turning import LatheContext, LatheProbe, LatheTool
from engine.turning_probe import Cycle973, decode_973, evaluate_probe_calibration, probe_calibration_program
from engine.types import MeasuringError, MoveStep, ProbeStep

KB_4A = (60.123, 50.054, 15.021, 0.0, 0.0, 0.0, 0.0)
T8 = LatheTool(t=8, d=1, type=580, sl=7, l1=40.123, l2=100.456, radius=3.0)
OLD_4A = LatheProbe.from_wp([0.0, 2.990, 0.0, 2.992, -2.997, 0, 0, 0, 0, 0, 0])


def xz(x, z):
    return np.array([x, 0.0, z])


def sl7_groove(kb=KB_4A, wall=5.0, top=None):
    """The SL 7 reference groove body of turning.md §10.2 (rings and bottom, machine-fixed)."""
    x_plus, x_minus, bottom = kb[0], kb[1], kb[2]
    top = bottom + 10.0 if top is None else top
    return [Solid(x_minus - wall, x_minus, bottom - wall, top, turns=False),
            Solid(x_plus, x_plus + wall, bottom - wall, top, turns=False),
            Solid(x_minus, x_plus, bottom - wall, bottom, turns=False)]


def sl8_groove(z_minus=10.0, z_plus=20.0, top_x=120.0, bottom_x=110.0, wall=5.0):
    return [Solid(bottom_x - wall, top_x, z_minus - wall, z_minus, turns=False),
            Solid(bottom_x - wall, top_x, z_plus, z_plus + wall, turns=False),
            Solid(bottom_x - wall, bottom_x, z_minus, z_plus, turns=False)]


def run(call, start, world, probe=T8, record=OLD_4A, kb=KB_4A, **kw):
    ctx = LatheContext(tool=probe, wp=(record,), kb=(kb,), **kw)
    point = drive(probe_calibration_program(call, start, ctx), world)
    return evaluate_probe_calibration(call, point, ctx), world


def world_4a(start):
    return ProbeWorld(solids=sl7_groove(), radius={k: 2.995 for k in ("X+", "X-", "Z-", "Z+")}, true_r=3.0,
                      skew=(0.0, 0.004), start=start)


def test_variants():
    assert decode_973(0).surface
    assert not decode_973(13).both
    v = decode_973(12113)
    assert v.both and v.ball and v.skew
    for bad in (11013, 1113, 23, 3013, 113013, 14):
        with pytest.raises(MeasuringError) as err:
            decode_973(bad)
        assert err.value.definition is alarms.WRONG_VARIANT


def test_4A_call1_bottom():
    """4-A call 1: X -> 55.0885, Z start 21.021, window to 15.021, switch at 18.016 ->
    t(−Z) = 2.995 -> _WP[0,1]; the probe stays at Z21.021."""
    start = xz(95.0, 125.0)
    call = Cycle973(mvar=13, ma=1, md=1, calnum=1, tzl=0.0, tsa=1.0, fa=3.0)
    result, world = run(call, start, world_4a(start))
    mv = [s for s in world.steps if isinstance(s, MoveStep)]
    assert mv[0].target[0] == pytest.approx(55.0885) and mv[0].target[2] == 125.0 and mv[0].coords == "MCS"
    assert mv[1].target[2] == pytest.approx(21.021)
    (p,) = [s for s in world.steps if isinstance(s, ProbeStep)]
    assert p.distance == pytest.approx(6.0) and p.feed == 300.0
    assert world.touches[0][1][2] == pytest.approx(18.016, abs=1e-9)
    assert result.trigger["Z-"] == pytest.approx(2.995, abs=1e-9)
    assert result.record.wp()[1] == pytest.approx(2.995, abs=1e-9)
    assert result.ovr[8] == pytest.approx(2.995) and result.ovr[9] == pytest.approx(0.005)
    assert world.pos[2] == pytest.approx(21.021)


def test_4A_call2_both_directions():
    """4-A call 2 (_MVAR=02013, _MA=2): +X from 54.123 -> rec 57.124, −X from 56.054 -> 53.045:
    t(+X) = −2.999 -> _WP[0,4], t(−X) = 2.991 -> _WP[0,3]; _OVR holds the second call."""
    start = xz(55.0885, 21.021)
    call = Cycle973(mvar=2013, ma=2, calnum=1, tzl=0.0, tsa=1.0, fa=3.0)
    result, world = run(call, start, world_4a(start))
    ps = [s for s in world.steps if isinstance(s, ProbeStep)]
    assert [p.direction.tolist() for p in ps] == [[1, 0, 0], [-1, 0, 0]]
    recs = [rec[0] for _, rec, _ in world.touches]
    assert recs == pytest.approx([57.124, 53.045], abs=1e-9)
    starts = [s.target[0] for s in world.steps if isinstance(s, MoveStep) and "start of probing" in s.label]
    assert starts == pytest.approx([54.123, 56.054])
    assert result.trigger == pytest.approx({"X+": -2.999, "X-": 2.991}, abs=1e-9)
    wp = result.record.wp()
    assert wp[3] == pytest.approx(2.991, abs=1e-9) and wp[4] == pytest.approx(-2.999, abs=1e-9)
    assert wp[1] == 2.990                                   # the Z value of the old record untouched
    assert result.ovr[12] == pytest.approx(2.991) and result.ovr[14] == pytest.approx(-2.999)


def test_4A_skew_and_ball_diameter():
    """4-A with _MVAR=12013: e_X = 0.004 -> _WP[0,8], t(±X) = ∓2.995; 12113: d_eff 5.990 -> _WP[0,0]."""
    start = xz(55.0885, 21.021)
    result, _ = run(Cycle973(mvar=12013, ma=2, calnum=1, tzl=0.0, tsa=1.0, fa=3.0), start, world_4a(start))
    assert result.skew["X"] == pytest.approx(0.004, abs=1e-9)
    assert result.trigger == pytest.approx({"X+": -2.995, "X-": 2.995}, abs=1e-9)
    assert result.record.wp()[8] == pytest.approx(0.004, abs=1e-9) and result.ovr[21] == pytest.approx(0.004)
    result, _ = run(Cycle973(mvar=12113, ma=2, calnum=1, tzl=0.0, tsa=1.0, fa=3.0), start, world_4a(start))
    assert result.effective_diameter == pytest.approx(5.99, abs=1e-9)
    assert result.record.wp()[0] == pytest.approx(5.99, abs=1e-9)
    assert result.ovr[4] == pytest.approx(5.99)
    result, _ = run(Cycle973(mvar=2113, ma=2, calnum=1, tzl=0.0, tsa=1.0, fa=3.0), start, world_4a(start))
    assert result.effective_diameter == pytest.approx(5.99, abs=1e-9)     # independent of the skew


def test_stored_skew_is_applied():
    """With a stored skew, positions are commanded q − e and c = rec + e (§12 Q16): a later
    one-direction calibration gives the skew-free trigger."""
    start = xz(55.0885, 21.021)
    skewed = OLD_4A.replace(skew={"Z": 0.0, "X": 0.004})
    result, world = run(Cycle973(mvar=13, ma=2, md=0, calnum=1, tzl=0.0, tsa=1.0, fa=3.0), start,
                        world_4a(start), record=skewed)
    starts = [s.target[0] for s in world.steps if isinstance(s, MoveStep) and "start of probing" in s.label]
    assert starts == pytest.approx([54.123 - 0.004])
    assert result.trigger["X+"] == pytest.approx(-2.995, abs=1e-9)


def test_4B_surface():
    """4-B: DIAMON start X66 (radius 33) Z90, _SETVAL=−18, −Z: Z to −12, window to −18; the
    plane at −18, effective radius 2.996 -> switch −15.004 -> t(−Z) = 2.996 (Δ 0.006)."""
    t9 = LatheTool(t=9, d=1, type=580, sl=7, l1=40.123, l2=100.456, radius=3.0)
    start = xz(33.0, 90.0)
    world = ProbeWorld(solids=[Solid(0.0, 40.0, -60.0, -18.0)], radius={"Z-": 2.996}, true_r=3.0, start=start)
    call = Cycle973(mvar=0, setval=-18.0, ma=1, md=1, tzl=0.0, tsa=1.0, fa=3.0)
    result, world = run(call, start, world, probe=t9, diamon=True)
    (mv,) = [s for s in world.steps if isinstance(s, MoveStep) and "start" in s.label]
    assert mv.target[2] == pytest.approx(-12.0) and mv.coords == "WCS"
    assert world.touches[0][1][2] == pytest.approx(-15.004, abs=1e-9)
    assert result.trigger["Z-"] == pytest.approx(2.996, abs=1e-9)
    assert result.difference["Z-"] == pytest.approx(0.006, abs=1e-9)
    assert result.record.wp()[1] == pytest.approx(2.996, abs=1e-9)
    assert world.pos[2] == pytest.approx(-12.0)


def test_surface_on_x_with_diamon():
    """_SETVAL on X is a diameter with DIAMON: Ø60 OD probed −X -> surface radius 30."""
    start = xz(40.0, 20.0)
    world = ProbeWorld(solids=[Solid(0.0, 30.0, 0.0, 50.0)], radius={"X-": 2.99}, true_r=3.0, start=start)
    result, _ = run(Cycle973(mvar=0, setval=60.0, ma=2, md=1, tsa=5.0, tzl=0.0, fa=2.0), start, world,
                    record=LatheProbe(), diamon=True)
    assert result.trigger["X-"] == pytest.approx(2.99, abs=1e-9)


def test_first_calibration_and_safe_area():
    """A zeroed record needs _TSA > r (turning.md §4.2): _TSA=1 -> 61303, _TSA=3.5 -> stored."""
    start = xz(95.0, 125.0)
    zero = LatheProbe()
    with pytest.raises(MeasuringError) as err:
        run(Cycle973(mvar=13, ma=1, md=1, calnum=1, tsa=1.0, fa=3.0), start, world_4a(start), record=zero)
    assert err.value.definition is alarms.SAFE_AREA
    result, _ = run(Cycle973(mvar=13, ma=1, md=1, calnum=1, tsa=3.5, fa=3.0), start, world_4a(start), record=zero)
    assert result.record.trigger_value("Z-") == pytest.approx(2.995, abs=1e-9)
    result, _ = run(Cycle973(mvar=12113, ma=2, calnum=1, tsa=3.5, fa=3.0), xz(55.0885, 21.021),
                    world_4a(xz(55.0885, 21.021)), record=zero)
    assert result.record.effective_diameter == pytest.approx(5.99, abs=1e-9)


def test_zero_range_keeps_old_value():
    start = xz(95.0, 125.0)
    result, _ = run(Cycle973(mvar=13, ma=1, md=1, calnum=1, tzl=0.01, tsa=1.0, fa=3.0), start, world_4a(start))
    assert result.record.trigger_value("Z-") == 2.990 and result.stored == ()


def test_checks():
    start = xz(95.0, 125.0)
    ctx = LatheContext(tool=T8, wp=(OLD_4A,), kb=(KB_4A,))
    cases = [
        (Cycle973(mvar=13, ma=1, md=0, calnum=1), T8, alarms.CUTTING_EDGE_POSITION),    # +Z into the stylus
        (Cycle973(mvar=2013, ma=1, calnum=1), T8, alarms.CUTTING_EDGE_POSITION),        # both on Z for SL 7
        (Cycle973(mvar=13, ma=1, md=2, calnum=1), T8, alarms.MEASURING_DIRECTION),
        (Cycle973(mvar=13, ma=3, md=1, calnum=1), T8, alarms.MEASURING_AXIS),
        (Cycle973(mvar=13, ma=1, md=1, calnum=2), T8, alarms.CALIBRATION_BODY),
        (Cycle973(mvar=13, ma=1, md=1, calnum=1, prnum=2), T8, alarms.PROBE_NUMBER),
        (Cycle973(mvar=13, ma=1, md=1, calnum=1, fa=-1.0), T8, alarms.MEASURING_PATH),
        (Cycle973(mvar=2013, ma=2, calnum=1, fa=4.1), T8, alarms.CALIBRATION_BODY),     # w7 10.069 ≤ 2r + _FA
        (Cycle973(mvar=13, ma=1, md=1, calnum=1), LatheTool(type=710, sl=7, radius=3.0), alarms.PROBE_TYPE),
        (Cycle973(mvar=13, ma=1, md=1, calnum=1), LatheTool(type=580, sl=6, radius=3.0),
         alarms.CUTTING_EDGE_POSITION),
        (Cycle973(mvar=0, ma=1, md=0, setval=5.0), LatheTool(type=580, sl=7, radius=3.0),
         alarms.CUTTING_EDGE_POSITION),
    ]
    for call, probe, alarm in cases:
        c = LatheContext(tool=probe, wp=ctx.wp, kb=ctx.kb)
        with pytest.raises(MeasuringError) as err:
            next(probe_calibration_program(call, start, c))
        assert err.value.definition is alarm, call
    deep = (60.123, 50.054, 15.021, 0.0, 0.0, 120.0, 111.0)       # SL 8 depth 9 < 2r + _FA = 9.5 (walls)
    c = LatheContext(tool=LatheTool(t=8, d=1, type=580, sl=8, radius=3.0), wp=ctx.wp, kb=(deep,))
    with pytest.raises(MeasuringError) as err:
        next(probe_calibration_program(Cycle973(mvar=2013, ma=1, calnum=1, fa=3.5), start, c))
    assert err.value.definition is alarms.CALIBRATION_BODY


@settings(max_examples=40, deadline=None)
@given(skew_x=st.floats(-0.2, 0.2), skew_z=st.floats(-0.2, 0.2), pre=st.lists(st.floats(0.0, 0.05), min_size=3,
       max_size=3), r=st.floats(1.0, 2.5))
def test_groove_truth_sl7(skew_x, skew_z, pre, r):
    """SL 7 groove, both X directions with skew and ball diameter, then −Z (turning.md §4.4):
    the skew absorbs half the pre-travel asymmetry, e = e_true − (δ(+) − δ(−))/2, so that
    t(±X) = ∓(r − δ̄) and d_eff = 2r − δ(+) − δ(−); a later measurement is exact (see
    test_turning_workpiece); −Z (Z skew not measured): t = r − δ(−Z) − e_Z."""
    probe = LatheTool(t=8, d=1, type=580, sl=7, l1=40.0, l2=100.0, radius=r)
    eff = {"X+": r - pre[0], "X-": r - pre[1], "Z-": r - pre[2]}
    start = xz(95.0, 125.0)
    world = ProbeWorld(solids=sl7_groove(), radius=eff, true_r=r, skew=(skew_z, skew_x), start=start)
    result, world = run(Cycle973(mvar=12113, ma=2, calnum=1, tzl=0.0, tsa=5.0, fa=1.0), start, world, probe=probe,
                        record=LatheProbe())
    mean = 0.5 * (eff["X+"] + eff["X-"])
    assert result.skew["X"] == pytest.approx(skew_x - 0.5 * (pre[0] - pre[1]), abs=1e-9)
    assert result.trigger["X+"] == pytest.approx(-mean, abs=1e-9)
    assert result.trigger["X-"] == pytest.approx(mean, abs=1e-9)
    assert result.effective_diameter == pytest.approx(eff["X+"] + eff["X-"], abs=1e-9)
    rec = result.record
    world.start = world.pos
    ctx = LatheContext(tool=probe, wp=(rec,), kb=(KB_4A,))
    call = Cycle973(mvar=13, ma=1, md=1, calnum=1, tzl=0.0, tsa=5.0, fa=1.0)
    point = drive(probe_calibration_program(call, world.pos, ctx), world)
    result = evaluate_probe_calibration(call, point, ctx)
    assert result.trigger["Z-"] == pytest.approx(eff["Z-"] - skew_z, abs=1e-9)   # the Z skew is not measured


@settings(max_examples=30, deadline=None)
@given(skew_z=st.floats(-0.2, 0.2), pre=st.lists(st.floats(0.0, 0.05), min_size=3, max_size=3))
def test_groove_truth_sl8(skew_z, pre):
    """SL 8 radial groove: both Z walls with skew (_WP[k,7]) and the bottom −X."""
    r = 2.0
    probe = LatheTool(t=8, d=1, type=580, sl=8, l1=40.0, l2=100.0, radius=r)
    eff = {"Z+": r - pre[0], "Z-": r - pre[1], "X-": r - pre[2]}
    kb = (0.0, 0.0, 0.0, 20.0, 10.0, 120.0, 110.0)
    start = xz(140.0, 60.0)
    world = ProbeWorld(solids=sl8_groove(), radius=eff, true_r=r, skew=(skew_z, 0.0), start=start)
    result, world = run(Cycle973(mvar=12113, ma=1, calnum=1, tzl=0.0, tsa=5.0, fa=1.0), start, world, probe=probe,
                        record=LatheProbe(), kb=kb)
    e_z = skew_z - 0.5 * (pre[0] - pre[1])
    mean = 0.5 * (eff["Z+"] + eff["Z-"])
    assert result.skew["Z"] == pytest.approx(e_z, abs=1e-9)
    assert result.trigger["Z+"] == pytest.approx(-mean, abs=1e-9)
    assert result.trigger["Z-"] == pytest.approx(mean, abs=1e-9)
    assert result.record.wp()[7] == pytest.approx(e_z, abs=1e-9)
    ctx = LatheContext(tool=probe, wp=(result.record,), kb=(kb,))
    call = Cycle973(mvar=13, ma=2, md=1, calnum=1, tzl=0.0, tsa=5.0, fa=1.0)
    point = drive(probe_calibration_program(call, world.pos, ctx), world)
    assert evaluate_probe_calibration(call, point, ctx).trigger["X-"] == pytest.approx(eff["X-"], abs=1e-9)
