"""CYCLE972/982 against turning.md §1–§3 (worked examples 1-A … 3-A) and an analytic truth."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_turning_model import Collision, MillTruth, ToolWorld, TurningToolTruth, drive

from engine import alarms
from engine.turning import LatheContext, LatheTool, tp_centre
from engine.turning_mills import evaluate_mill, mill_program
from engine.turning_tools import (
    Cycle982,
    decode_982,
    evaluate_toolprobe,
    evaluate_turning_tool,
    toolprobe_program,
    turning_tool_program,
)
from engine.types import MeasuringError, MoveStep, ProbeStep, SpindleStep

ROUGH_1B = {"Z-": 220.0, "Z+": 200.0, "X-": 400.0, "X+": 380.0}
TRUE_1B = {"Z-": 220.35, "Z+": 199.65, "X-": 400.25, "X+": 379.80}
T7 = LatheTool(t=7, d=1, type=500, sl=3, l1=10.0, l2=40.0, radius=5.0)
T3 = LatheTool(t=3, d=1, type=500, sl=3, l1=100.65, l2=60.32, radius=2.0)


def xz(x, z):
    return np.array([x, 0.0, z])


def ctx_for(tool, tp=None, tpw=None, **kw):
    return LatheContext(tool=tool, tp=(tp,) if tp is not None else (), tpw=(tpw,) if tpw is not None else (), **kw)


def calibrate(call, start, record, truth_faces, tool=T7, workpiece=False, **kw):
    ctx = ctx_for(tool, tpw=record, **kw) if workpiece else ctx_for(tool, tp=record, **kw)
    world = ToolWorld(faces=truth_faces, tool=TurningToolTruth(tool.sl, tool.l1, tool.l2, tool.radius,
                                                               recode=ctx.bit(23)),
                      stored_l1=tool.l1, stored_l2=tool.l2, start=start)
    point = drive(toolprobe_program(call, start, ctx), world)
    return evaluate_toolprobe(call, point, ctx), world


def moves(world):
    """The positioning moves (without the returns to the start of probing)."""
    return [s for s in world.steps if isinstance(s, MoveStep) and not s.label.endswith("return")]


def probes(world):
    return [s for s in world.steps if isinstance(s, ProbeStep)]


# --- _MVAR decoding -------------------------------------------------------------------------

@pytest.mark.parametrize("mvar", [0, 10, 100000, 100010, 1, 11, 2, 12, 100001, 100011, 12001, 2001, 1101,
                                  10101, 12101, 2, 10102, 3002, 14002])
def test_valid_variants(mvar):
    decode_982(mvar)


@pytest.mark.parametrize("mvar", [3, 20, 100002, 102001, 112001, 1102, 1000, 110, 1000000, -1, 5001])
def test_invalid_variants(mvar):
    with pytest.raises(MeasuringError) as err:
        decode_982(mvar)
    assert err.value.definition is alarms.WRONG_VARIANT


def test_cycle972_has_only_0_and_1():
    decode_982(0, 972)
    decode_982(1, 972)
    with pytest.raises(MeasuringError) as err:
        decode_982(2, 972)
    assert err.value.definition is alarms.WRONG_VARIANT


# --- 1-B: machine-related calibration of all four faces -----------------------------------

def test_1B_calibration_sequence():
    """turning.md 1-B: positioning, windows, latches, f_new and Δ of the four calls."""
    record = dict(ROUGH_1B)
    table = [  # (_MA, start, cross target, start of probing, rec, f_new, Δ)
        (2, xz(420, 240), ("Z", 205.0), ("X", 401.0), 400.250, 400.250, +0.250),
        (1, "Z240", ("X", 385.125), ("Z", 221.0), 220.350, 220.350, +0.350),
        (2, "X350", ("Z", 205.175), ("X", 369.0), 369.800, 379.800, -0.200),
        (1, "Z170", ("X", 385.025), ("Z", 189.0), 189.650, 199.650, -0.350),
    ]
    pos = None
    for ma, start, cross, probing, rec, f_new, delta in table:
        if isinstance(start, np.ndarray):
            pos = start
        elif start == "Z240":
            pos = xz(pos[0], 240.0)
        elif start == "X350":
            pos = xz(350.0, pos[2])
        elif start == "Z170":
            pos = xz(pos[0], 170.0)
        call = Cycle982(mvar=0, ma=ma, fa=1.0, tsa=1.0, tzl=0.001)
        result, world = calibrate(call, pos, record, TRUE_1B)
        mv = moves(world)
        j = {"X": 0, "Z": 2}
        assert mv[0].target[j[cross[0]]] == pytest.approx(cross[1], abs=1e-9)
        assert mv[1].target[j[probing[0]]] == pytest.approx(probing[1], abs=1e-9)
        (p,) = probes(world)
        assert p.distance == pytest.approx(2.0) and p.feed == 150.0 and p.coords == "MCS"
        assert world.touches[0][1][j[probing[0]]] == pytest.approx(rec, abs=1e-9)
        assert result.trigger == pytest.approx(f_new, abs=1e-9)
        assert result.difference == pytest.approx(delta, abs=1e-9)
        assert result.stored
        record = result.record
        pos = world.pos      # the tool ends _FA in front of the calibrated face
        assert pos[j[probing[0]]] == pytest.approx(probing[1], abs=1e-9)
    assert record == pytest.approx(TRUE_1B, abs=1e-9)
    assert tp_centre(record, "Z") == pytest.approx(210.0, abs=1e-9)
    assert tp_centre(record, "X") == pytest.approx(390.025, abs=1e-9)


def test_1B_ovr():
    call = Cycle982(mvar=0, ma=2, fa=1.0, tsa=1.0, tzl=0.001)
    result, _ = calibrate(call, xz(420, 240), ROUGH_1B, TRUE_1B)
    assert result.ovr[12] == pytest.approx(400.25) and result.ovr[13] == pytest.approx(0.25)
    assert result.ovr[8] == 220.0 and result.ovr[9] == 0.0           # not calibrated: old value
    assert result.ovr[27] == 0.001 and result.ovr[28] == 1.0
    assert result.ovi[2] == 982 and result.ovi[3] == 0 and result.ovi[5] == 1
    assert result.values["tool_probe"]["record"] == pytest.approx([220.0, 200.0, 400.25, 380.0])
    assert result.values["difference"] == {"X-": pytest.approx(0.25)}


def test_calibration_zero_range_and_safe_area():
    """§0.11: |Δ| < _TZL keeps the old value; |Δ| > _TSA -> 61303 (needs _TSA < _FA, §12 Q21)."""
    call = Cycle982(mvar=0, ma=2, fa=1.0, tsa=1.0, tzl=0.001)
    truth = dict(ROUGH_1B, **{"X-": 400.0005})
    result, _ = calibrate(call, xz(420, 240), ROUGH_1B, truth)
    assert not result.stored and result.record["X-"] == 400.0
    assert result.difference == pytest.approx(0.0005, abs=1e-12)
    call = Cycle982(mvar=0, ma=2, fa=2.0, tsa=1.0)
    with pytest.raises(MeasuringError) as err:
        calibrate(call, xz(420, 240), ROUGH_1B, dict(ROUGH_1B, **{"X-": 401.5}))
    assert err.value.definition is alarms.SAFE_AREA


# --- 1-A: workpiece-related calibration (_TPW, WCS) ---------------------------------------

def test_1A_workpiece_related_calibration():
    """turning.md 1-A: start Z100 X120 -> tip Z30 = (50+20)/2 − 5, X76 = 70 + 6, window to X64,
    300 mm/min; the four calls N30–N60 calibrate all faces of _TPW to the truth."""
    rough = {"Z-": 50.0, "Z+": 20.0, "X-": 70.0, "X+": 40.0}
    truth = {"Z-": 51.3, "Z+": 18.2, "X-": 71.234, "X+": 43.1}        # each within ±5 (window ±6)
    record = dict(rough)
    call = Cycle982(mvar=10, ma=2, fa=6.0, tsa=5.0, tzl=0.001)
    result, world = calibrate(call, xz(120, 100), record, truth, workpiece=True)
    mv = moves(world)
    assert mv[0].target[2] == pytest.approx(30.0) and mv[0].coords == "WCS"
    assert mv[1].target[0] == pytest.approx(76.0)
    (p,) = probes(world)
    assert p.distance == pytest.approx(12.0) and p.feed == 300.0 and p.coords == "WCS"
    record = result.record
    pos = world.pos
    for ma, move in ((1, ("Z", 80.0)), (2, ("X", 10.0)), (1, ("Z", -10.0))):   # N35/N45/N55 positions
        pos = pos.copy()
        pos[{"X": 0, "Z": 2}[move[0]]] = move[1]
        result, world = calibrate(Cycle982(mvar=10, ma=ma, fa=6.0, tsa=5.0, tzl=0.001), pos, record, truth,
                                  workpiece=True)
        record, pos = result.record, world.pos
    assert record == pytest.approx(truth, abs=1e-9)


# --- 1-C / 2-D: incremental ------------------------------------------------------------------

def test_1C_incremental_calibration():
    """turning.md 1-C: tip at X430 by hand, _MD=1, _FA=20 (300 mm/min, 40 mm window): switch
    after 29.750 mm at X400.250 -> _TP[0,2] = 400.250 without checks; back to X430."""
    unknown = {"Z-": 0.0, "Z+": 0.0, "X-": 0.0, "X+": 0.0}
    start = xz(430.0, 210.0 - 5.0)          # nose centre on the probe's Z centre 210
    call = Cycle982(mvar=100000, ma=2, md=1, fa=20.0)
    result, world = calibrate(call, start, unknown, TRUE_1B)
    (p,) = probes(world)
    assert p.distance == 40.0 and p.feed == 300.0
    assert world.touches[0][1][0] == pytest.approx(400.25, abs=1e-9)
    assert 430.0 - world.touches[0][1][0] == pytest.approx(29.75, abs=1e-9)
    assert result.record["X-"] == pytest.approx(400.25, abs=1e-12) and result.stored
    assert world.pos == pytest.approx(start)


def test_2D_incremental_measuring():
    """turning.md 2-D: T3 SL 3, _MA=2, _MD=1, _FA=20; L1 -> geometry, wear cleared; back to the start."""
    tool = LatheTool(t=3, d=1, type=500, sl=3, l1=100.0, l2=60.3, radius=2.0, wear_l1=0.04)
    record = {"X-": 400.25}
    start = xz(430.0, 210.0 - 2.0)
    ctx = ctx_for(tool, tp=record, chbit={3: 1})        # incremental ignores _CHBIT[3]
    world = ToolWorld(faces=TRUE_1B, tool=TurningToolTruth(3, 100.7, 60.3, 2.0), stored_l1=tool.effective("l1"),
                      stored_l2=60.3, start=start)
    call = Cycle982(mvar=100001, ma=2, md=1, fa=20.0, tsa=0.001, tdif=0.001)     # no checks (§0.11)
    point = drive(turning_tool_program(call, start, ctx), world)
    result = evaluate_turning_tool(call, point, ctx)
    assert result.after["l1"] == pytest.approx(100.7, abs=1e-9)
    assert result.after["wear"]["l1"] == 0.0
    assert result.alarm is None and result.written == ("L1",)
    assert world.pos == pytest.approx(start)


# --- 2-A / 2-B: turning tool T3 ---------------------------------------------------------------

def measure_t3(call, start, *, chbit=None, true_l1=100.7, true_l2=60.3, tool=T3, record=TRUE_1B, ev=0.0):
    ctx = ctx_for(tool, tp=record, chbit=chbit or {})
    world = ToolWorld(faces=TRUE_1B, tool=TurningToolTruth(tool.sl, true_l1, true_l2, tool.radius),
                      stored_l1=tool.effective("l1"), stored_l2=tool.effective("l2"), start=start)
    point = drive(turning_tool_program(call, start, ctx), world)
    return evaluate_turning_tool(call, point, ctx, ev=ev), world


def test_2A_remeasure_L1_and_L2():
    """turning.md 2-A: L1 Z208 / X401.250, rec 400.300 -> 100.700, wear L1 0.050; L2 X388.025 /
    Z221.350, rec 220.330 -> 60.300, wear L2 −0.020."""
    call = Cycle982(mvar=1, ma=2, fa=1.0, tsa=1.0, tdif=0.8, tzl=0.001)
    result, world = measure_t3(call, xz(420, 240), chbit={3: 1})
    mv = moves(world)
    assert mv[0].target[2] == pytest.approx(208.0) and mv[1].target[0] == pytest.approx(401.25)
    assert world.touches[0][1][0] == pytest.approx(400.3, abs=1e-9)
    assert result.measured["L1"]["actual"] == pytest.approx(100.7, abs=1e-9)
    assert result.measured["L1"]["difference"] == pytest.approx(0.05, abs=1e-9)
    assert result.after["wear"]["l1"] == pytest.approx(0.05, abs=1e-9) and result.after["l1"] == 100.65
    assert result.ovr[8] == pytest.approx(100.7) and result.ovr[9] == pytest.approx(0.05)
    assert result.ovi[0] == 1 and result.ovi[8] == 3 and result.ovi[3] == 1
    tool = LatheTool.from_dict(result.after)
    call = Cycle982(mvar=1, ma=1, fa=1.0, tsa=1.0, tdif=0.8, tzl=0.001)
    result, world = measure_t3(call, xz(401.25, 240), chbit={3: 1}, tool=tool)
    mv = moves(world)
    assert mv[0].target[0] == pytest.approx(388.025) and mv[1].target[2] == pytest.approx(221.35)
    assert world.touches[0][1][2] == pytest.approx(220.33, abs=1e-9)
    assert result.measured["L2"]["actual"] == pytest.approx(60.3, abs=1e-9)
    assert result.after["wear"]["l2"] == pytest.approx(-0.02, abs=1e-9)
    assert result.after["wear"]["l1"] == pytest.approx(0.05, abs=1e-9)


def test_2A_first_measurement_geometry():
    call = Cycle982(mvar=1, ma=2, fa=1.0, tsa=1.0, tdif=0.8)
    result, _ = measure_t3(call, xz(420, 240), chbit={3: 0})
    assert result.after["l1"] == pytest.approx(100.7, abs=1e-9) and result.after["wear"]["l1"] == 0.0


def test_2A_errors():
    """Δ 0.9 ≥ _TDIF -> 62306, nothing written; +1.2 -> contact while positioning (61302 in
    the simulator); −1.2 -> no switch (61301); _FA=2, _TSA=1, +1.2 -> 61303 (§0.11, §12 Q21)."""
    call = Cycle982(mvar=1, ma=2, fa=1.0, tsa=1.0, tdif=0.8)
    result, _ = measure_t3(call, xz(420, 240), chbit={3: 1}, true_l1=100.65 + 0.9)
    assert result.alarm is alarms.DIMENSION_DIFFERENCE and result.written == ()
    assert result.after == result.before and result.ovi[9] == alarms.DIMENSION_DIFFERENCE.number
    with pytest.raises(Collision):
        measure_t3(call, xz(420, 240), true_l1=100.65 + 1.2)
    with pytest.raises(MeasuringError) as err:
        measure_t3(call, xz(420, 240), true_l1=100.65 - 1.2)
    assert err.value.definition is alarms.PROBE_NOT_SWITCHED
    with pytest.raises(MeasuringError) as err:
        measure_t3(Cycle982(mvar=1, ma=2, fa=2.0, tsa=1.0, tdif=3.0), xz(420, 240), true_l1=100.65 + 1.2)
    assert err.value.definition is alarms.SAFE_AREA


def test_2A_empirical_value():
    """EV (only _EVNUM > 0) is subtracted from the measured length, added with _CHBIT[5]=1 (§2.4)."""
    call = Cycle982(mvar=1, ma=2, fa=1.0, tsa=1.0, tdif=0.8, evnum=11)
    result, _ = measure_t3(call, xz(420, 240), chbit={3: 1}, ev=0.01)
    assert result.measured["L1"]["actual"] == pytest.approx(100.69, abs=1e-9)
    assert result.ovr[30] == 0.01 and result.ovi[7] == 11
    result, _ = measure_t3(call, xz(420, 240), chbit={3: 1, 5: 1}, ev=0.01)
    assert result.measured["L1"]["actual"] == pytest.approx(100.71, abs=1e-9)
    result, _ = measure_t3(Cycle982(mvar=1, ma=2, fa=1.0, tsa=1.0, tdif=0.8), xz(420, 240), ev=0.01)
    assert result.measured["L1"]["actual"] == pytest.approx(100.7, abs=1e-9)      # _EVNUM = 0


def test_2B_automatic():
    """turning.md 2-B: (a) X388.025 (b) Z221.350 (c) −Z -> L2 60.300 (d) X401.250 (e) Z208 (f) −X
    -> L1 100.700, (g) Z240, X420; first measurement: geometry, wear 0."""
    call = Cycle982(mvar=2, fa=1.0, tsa=1.0, tdif=0.8)
    result, world = measure_t3(call, xz(420, 240), chbit={3: 0})
    targets = [(s.target[0], s.target[2]) for s in moves(world)]
    expected = [(388.025, 240.0), (388.025, 221.35), (401.25, 221.35), (401.25, 208.0), (401.25, 240.0),
                (420.0, 240.0)]
    assert targets == [pytest.approx(t, abs=1e-9) for t in expected]
    assert [p.direction.tolist() for p in probes(world)] == [[0, 0, -1], [-1, 0, 0]]
    assert result.after["l1"] == pytest.approx(100.7, abs=1e-9)
    assert result.after["l2"] == pytest.approx(60.3, abs=1e-9)
    assert result.after["wear"]["l1"] == 0.0 and result.after["wear"]["l2"] == 0.0
    assert result.values["length"]["L2"]["actual"] == pytest.approx(60.3, abs=1e-9)
    assert world.pos == pytest.approx(xz(420, 240))


def test_2C_grooving_tool_non_tip_axis():
    """turning.md 2-C: SL 8, R 0.4, −Z onto 220.350, true L2 75.000: F_z 295.750 -> L 75.000."""
    tool = LatheTool(t=5, d=1, type=500, sl=8, l1=80.0, l2=75.3, radius=0.4)
    call = Cycle982(mvar=1, ma=1, fa=1.0, tsa=1.0, tdif=0.8)
    result, world = measure_t3(call, xz(388.0, 240.0), tool=tool, true_l1=80.0, true_l2=75.0)
    f_z = world.touches[0][1][2] + 75.3
    assert f_z == pytest.approx(295.75, abs=1e-9)
    assert result.measured["L2"]["actual"] == pytest.approx(75.0, abs=1e-9)


def test_direction_rules():
    """SL 3 only travels −X/−Z (d = s): a start below the probe -> 61332; in the band -> 61332."""
    call = Cycle982(mvar=1, ma=2, fa=1.0)
    for start in (xz(350, 240), xz(400.5, 240)):
        with pytest.raises(MeasuringError) as err:
            measure_t3(call, start)
        assert err.value.definition is alarms.TOOL_TIP_POSITION
    with pytest.raises(MeasuringError) as err:
        calibrate(Cycle982(mvar=0, ma=1, fa=1.0), xz(420, 215), ROUGH_1B, TRUE_1B)
    assert err.value.definition is alarms.TOOL_TIP_POSITION


def test_tool_checks_before_motion():
    bad = [
        (Cycle982(mvar=0, ma=2), LatheTool(type=120, sl=3, radius=5.0), alarms.TOOL_TYPE),
        (Cycle982(mvar=0, ma=2), LatheTool(type=500, sl=2, radius=5.0), alarms.CUTTING_EDGE_POSITION),
        (Cycle982(mvar=1, ma=2), LatheTool(type=500, sl=9), alarms.CUTTING_EDGE_POSITION),
        (Cycle982(mvar=1, ma=2), LatheTool(type=900, sl=3), alarms.TOOL_TYPE),
        (Cycle982(mvar=1, ma=3), T3, alarms.MEASURING_AXIS),
        (Cycle982(mvar=1, ma=2, fa=0.0), T3, alarms.MEASURING_PATH),
        (Cycle982(mvar=1, ma=2, prnum=2), T3, alarms.PROBE_NUMBER),
        (Cycle982(mvar=100001, ma=2, md=2), T3, alarms.MEASURING_DIRECTION),
        (Cycle982(mvar=1101, ma=2), T3, alarms.WRONG_VARIANT),
        (Cycle982(mvar=1, ma=2), LatheTool(type=500, sl=3, d=0), alarms.NO_D_NUMBER),
    ]
    for call, tool, alarm in bad:
        with pytest.raises(MeasuringError) as err:
            list(zip(range(3), turning_tool_program(call, xz(420, 240), ctx_for(tool, tp=TRUE_1B)), strict=False))
        assert err.value.definition is alarm, (call, tool)
    ctx = ctx_for(LatheTool(type=120, sl=0, radius=5.0), tp=TRUE_1B, spos=False)
    with pytest.raises(MeasuringError) as err:
        next(mill_program(Cycle982(mvar=1, ma=1), xz(450, 285), ctx))
    assert err.value.definition is alarms.NEEDS_SPOS
    ctx = ctx_for(LatheTool(type=120, sl=0, radius=5.0), tp=TRUE_1B, chbit={20: 1})
    with pytest.raises(MeasuringError) as err:
        next(mill_program(Cycle982(mvar=2001, ma=2), xz(450, 285), ctx))
    assert err.value.definition is alarms.WRONG_VARIANT


def test_two_touch_and_nmsp():
    """_CHBIT[17]=1 (path > 2 mm): fast first touch at _SPEED[3], back 2 mm, fine touch;
    _NMSP=3: three probings at the same place, averaged (MM §1.4)."""
    call = Cycle982(mvar=1, ma=2, fa=3.0, tsa=3.0, tdif=3.0, nmsp=3)
    result, world = measure_t3(call, xz(420, 240), chbit={3: 1, 17: 1})
    ps = probes(world)
    assert len(ps) == 6 and ps[0].feed == 900.0 and ps[1].feed == 300.0 and ps[1].distance == 4.0
    assert result.measured["L1"]["actual"] == pytest.approx(100.7, abs=1e-9)


# --- analytic truth over every SL --------------------------------------------------------------

def _start_for(sx, sz, faces, margin=25.0):
    x = faces["X-"] + margin if sx <= 0 else faces["X+"] - margin
    z = faces["Z-"] + margin if sz <= 0 else faces["Z+"] - margin
    return xz(x, z)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(sl=st.integers(1, 8), radius=st.floats(0.0, 3.0), e1=st.floats(-0.6, 0.6), e2=st.floats(-0.6, 0.6),
       auto=st.booleans(), recode=st.booleans())
def test_turning_tool_truth(sl, radius, e1, e2, auto, recode):
    """Stored L1/L2 off by e1/e2 (< _FA): measuring every allowed axis (automatic or one by one)
    returns the true lengths to 1e-9 (turning.md §2.4), also with the SL recoded (_CHBIT[23])."""
    from engine.turning import SL_TIP
    true = (50.0 + radius, 30.0)
    tool = LatheTool(t=1, d=1, type=510, sl=sl, l1=true[0] + e1, l2=true[1] + e2, radius=radius)
    ctx = ctx_for(tool, tp=TRUE_1B, chbit={3: 0, 23: int(recode)})
    truth = TurningToolTruth(sl, true[0], true[1], radius, recode=recode)
    sx, sz = SL_TIP[sl]
    sx = -sx if recode else sx
    start = _start_for(sx, sz, TRUE_1B)
    if auto:
        calls = [Cycle982(mvar=2, fa=1.0, tsa=1.0, tdif=1.0)]
    else:
        calls = [Cycle982(mvar=1, ma=ma, fa=1.0, tsa=1.0, tdif=1.0) for ma in (1, 2)]
    found = {}
    for call in calls:
        world = ToolWorld(faces=TRUE_1B, tool=truth, stored_l1=tool.l1, stored_l2=tool.l2, start=start)
        point = drive(turning_tool_program(call, start, ctx), world)
        result = evaluate_turning_tool(call, point, ctx)
        for name, v in result.measured.items():
            found[name] = v["actual"]
    axes = {"L1": true[0], "L2": true[1]}
    if auto and (sx == 0 or sz == 0):
        tip = "L1" if sx != 0 else "L2"
        axes = {tip: axes[tip]}
    for name, value in axes.items():
        assert found[name] == pytest.approx(value, abs=1e-9)


@settings(max_examples=40, deadline=None)
@given(radius=st.floats(0.5, 6.0), dz=st.floats(-0.8, 0.8), dz2=st.floats(-0.8, 0.8), dx=st.floats(-0.8, 0.8),
       dx2=st.floats(-0.8, 0.8), nmsp=st.integers(1, 2))
def test_calibration_truth(radius, dz, dz2, dx, dx2, nmsp):
    """Four calls from the start quadrants calibrate every face to the truth (turning.md §1.4)."""
    tool = LatheTool(t=7, d=1, type=500, sl=3, l1=10.0, l2=40.0, radius=radius)
    truth = {"Z-": 220 + dz, "Z+": 200 + dz2, "X-": 400 + dx, "X+": 380 + dx2}
    record = dict(ROUGH_1B)
    starts = [(2, xz(430, 240)), (1, xz(390, 240)), (2, xz(350, 240)), (1, xz(390, 170))]
    for ma, start in starts:
        call = Cycle982(mvar=0, ma=ma, fa=1.0, tsa=1.0, tzl=0.0, nmsp=nmsp)
        result, _ = calibrate(call, start, record, truth, tool=tool)
        record = result.record
    assert record == pytest.approx(truth, abs=1e-9)


# --- mills (turning.md §3) -----------------------------------------------------------------------

TP_3A = {"Z-": 220.0, "Z+": 200.0, "X-": 400.0, "X+": 380.0}


def measure_mill(call, start, stored: LatheTool, truth: MillTruth, chbit=None, faces=TP_3A):
    ctx = ctx_for(stored, tp=faces, chbit=chbit or {})
    world = ToolWorld(faces=faces, tool=truth, stored_l1=stored.effective("l1"), stored_l2=stored.effective("l2"),
                      start=start)
    point = drive(mill_program(call, start, ctx), world)
    return evaluate_mill(call, point, ctx), world


def test_3A_radial_mill_length_and_radius():
    """turning.md 3-A: P1 = 244.100 − 220 = 24.100, P2 = 196.140 − 200 = −3.860 -> L2 = 10.120,
    R = 13.980 (geometry); SPOS 15°, +180° before P2; the spindle stays there."""
    stored = LatheTool(t=3, d=1, type=120, l1=60.0, l2=10.0, radius=14.0)
    call = Cycle982(mvar=12001, ma=1, fa=3.0, tdif=2.5, tsa=3.0, tzl=0.001, sta1=15.0)
    result, world = measure_mill(call, xz(450, 285), stored, MillTruth(60.0, 10.12, 13.98, radial=True),
                                 chbit={3: 0, 20: 0})
    f = [rec[2] + 10.0 for _, rec, _ in world.touches]
    assert f == pytest.approx([244.1, 196.14], abs=1e-9)
    assert [a for *_, a in world.touches] == [15.0, 195.0]
    assert isinstance(world.steps[0], SpindleStep) and world.steps[0].angle == 15.0
    assert result.after["l2"] == pytest.approx(10.12, abs=1e-9)
    assert result.after["radius"] == pytest.approx(13.98, abs=1e-9)
    assert result.ovr[10] == pytest.approx(10.12) and result.ovr[12] == pytest.approx(13.98)
    assert result.ovr[13] == pytest.approx(-0.02)
    assert world.angle == 195.0
    ps = probes(world)
    assert ps[0].feed == 300.0 and ps[0].distance == 6.0


@settings(max_examples=40, deadline=None)
@given(radial=st.booleans(), radius=st.floats(2.0, 12.0), e_l1=st.floats(-1.5, 1.5), e_l2=st.floats(-1.5, 1.5),
       e_r=st.floats(-1.0, 1.0), reversal=st.booleans(), variant=st.sampled_from(["length", "radius", "both", "end"]))
def test_mill_truth(radial, radius, e_l1, e_l2, e_r, reversal, variant):
    """Every measure variant (digit 4 = 0/1/2, digit 3, digit 5) returns the truth (turning.md §3.2)."""
    true = MillTruth(l1=60.0, l2=10.0, radius=radius, radial=radial)
    cross = 2 if not radial else 1           # the radius axis Q: X (axial) or Z (radial)
    end = 1 if not radial else 2             # the tool axis T
    stored = LatheTool(t=3, d=1, type=120, l1=60.0, l2=10.0, radius=radius)
    if variant == "end":
        stored = LatheTool(t=3, d=1, type=120, l1=60.0 + (0 if not radial else e_l1),
                           l2=10.0 + (e_l2 if not radial else 0), radius=radius)
        ma, d4 = end, 0
    elif variant == "length":                # the length across the axis, R known
        stored = LatheTool(t=3, d=1, type=120, l1=60.0 + (e_l1 if not radial else 0),
                           l2=10.0 + (0 if not radial else e_l2), radius=radius)
        ma, d4 = cross, 0
    elif variant == "radius":                # R only, the length known
        stored = LatheTool(t=3, d=1, type=120, l1=60.0, l2=10.0, radius=radius + e_r)
        ma, d4 = cross, 1
    else:
        stored = LatheTool(t=3, d=1, type=120, l1=60.0 + e_l1, l2=10.0 + e_l2, radius=radius + e_r)
        ma, d4 = cross, 2
    mvar = 1 + 1000 * d4 + 100 * int(reversal) + 10000 * int(radial)
    start = xz(450.0, 285.0)
    call = Cycle982(mvar=mvar, ma=ma, fa=3.0, tdif=5.0, tsa=5.0, tzl=0.0, sta1=15.0, cora=2.0)
    result, world = measure_mill(call, start, stored, true)
    expect = {"length": ("L1" if not radial else "L2"), "end": ("L2" if not radial else "L1")}
    if variant in expect:
        name = expect[variant]
        assert result.measured[name]["actual"] == pytest.approx(getattr(true, name.lower()), abs=1e-9)
    if variant in ("radius", "both"):
        assert result.measured["R"]["actual"] == pytest.approx(radius, abs=1e-9)
    if variant == "both":
        name = "L1" if not radial else "L2"
        assert result.measured[name]["actual"] == pytest.approx(getattr(true, name.lower()), abs=1e-9)
    if reversal:
        angles = sorted({a for *_, a in world.touches})
        assert angles == [15.0, 197.0]


@settings(max_examples=30, deadline=None)
@given(radial=st.booleans(), radius=st.sampled_from([0.0, 4.0, 9.5]), e_l1=st.floats(-1.5, 1.5),
       e_l2=st.floats(-1.5, 1.5), reversal=st.booleans())
def test_mill_automatic_truth(radial, radius, e_l1, e_l2, reversal):
    """Automatic (_MVAR 2/102/10002/10102): L1, L2 (and R when R ≠ 0) to the truth; back to the start."""
    true = MillTruth(l1=60.0, l2=10.0, radius=radius, radial=radial)
    stored = LatheTool(t=3, d=1, type=120, l1=60.0 + e_l1, l2=10.0 + e_l2, radius=radius)
    mvar = 2 + 100 * int(reversal) + 10000 * int(radial)
    start = xz(450.0, 285.0)
    call = Cycle982(mvar=mvar, fa=3.0, tdif=5.0, tsa=5.0, tzl=0.0, sta1=0.0)
    result, world = measure_mill(call, start, stored, true)
    assert result.measured["L1"]["actual"] == pytest.approx(60.0, abs=1e-9)
    assert result.measured["L2"]["actual"] == pytest.approx(10.0, abs=1e-9)
    if radius:
        assert result.measured["R"]["actual"] == pytest.approx(radius, abs=1e-9)
        assert len({t for t, *_ in world.touches}) == 4 * (2 if reversal else 1)
    else:
        assert "R" not in result.measured
    assert world.pos == pytest.approx(start)


def test_drill_applicate_length():
    """turning.md §3.4: a drill with SD 42950=0 in G17: L1 on Z, _MA ignored."""
    stored = LatheTool(t=4, d=1, type=200, l1=80.3, l2=0.0, radius=0.0)
    ctx = LatheContext(tool=stored, tp=(TP_3A,), tool_length_type=0, plane="G17")
    world = ToolWorld(faces=TP_3A, tool=MillTruth(l1=0.0, l2=80.0, radius=0.0), stored_l1=0.0, stored_l2=80.3,
                      start=xz(450, 320))
    call = Cycle982(mvar=1, ma=2, fa=1.0, tsa=1.0, tdif=1.0)
    point = drive(mill_program(call, xz(450, 320), ctx), world)
    result = evaluate_mill(call, point, ctx)
    assert result.measured["L1"]["actual"] == pytest.approx(80.0, abs=1e-9)
    assert result.after["l1"] == pytest.approx(80.0, abs=1e-9)
