"""engine.toolmeasure against the manual's examples (measuring-math §14) and a synthetic truth."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine.plan_base import ToolPoint, ToolProbePoint, ToolTouch
from engine.planes import PLANES
from engine.toolmeasure import (
    calibrate_tool_probe,
    calibrate_tool_probe_point,
    compensation_table_value,
    spindle_speed_feeds,
    tool_length,
    tool_offset_update,
    tool_point_value,
    tool_radius,
)
from engine.types import MeasuringError

G17 = PLANES["G17"]


def test_14_2_A_speed_and_feed():
    """§14.2-A / spec §7.3: S = 90 m/min, r = 5..100 -> n = 2865..143 rpm; Δ = 0.005 -> 14..0.7."""
    small = spindle_speed_feeds(5.0, max_surface_speed=90.0, max_speed=math.inf, accuracy=0.005)
    large = spindle_speed_feeds(100.0, max_surface_speed=90.0, max_speed=math.inf, accuracy=0.005)
    assert small.speed == pytest.approx(2864.79, abs=0.01)
    assert large.speed == pytest.approx(143.24, abs=0.01)
    assert small.final_feed == pytest.approx(14.32, abs=0.01)
    assert large.final_feed == pytest.approx(0.716, abs=0.001)
    assert round(small.speed) == 2865 and round(large.speed) == 143
    assert round(small.final_feed) == 14 and round(large.final_feed, 1) == 0.7


def test_speed_limits_and_first_feed():
    """Defaults (spec §8.3): MAX_V 100, MAX_S 1000, MIN_D 0.01, MIN_F 1, MAX_F 20, FAK1 10."""
    sf = spindle_speed_feeds(5.0)                 # 100/(2π·0.005) = 3183 > 1000 -> 1000 rpm
    assert sf.speed == 1000.0
    assert sf.final_feed == pytest.approx(10.0)
    assert sf.feeds == pytest.approx((20.0, 10.0))   # 10·10 = 100 clamped to MAX_F
    big = spindle_speed_feeds(100.0)              # n = 100 m/min / (2π·0.1 m) = 159.15, F = 1.59
    n = 100.0 / (2.0 * math.pi * 0.1)
    assert big.speed == pytest.approx(n, rel=1e-12)
    assert big.feeds == pytest.approx((10 * 0.01 * n, 0.01 * n), rel=1e-12)
    tiny = spindle_speed_feeds(100.0, accuracy=0.0005)   # F = 0.0796, 10·F < MIN_F -> 1
    assert tiny.feeds[0] == 1.0
    three = spindle_speed_feeds(100.0, factor2=3.0)
    assert len(three.feeds) == 3 and three.feeds[1] == pytest.approx(3 * three.final_feed)
    with pytest.raises(MeasuringError) as err:
        spindle_speed_feeds(0.0)
    assert err.value.alarm == 61351


def test_14_5_A_tool_probe_calibration():
    """§14.5-A: R_c = 5, L_c = 20: −X at X_c 55.012 -> 50.012 (Δ 0.012); again 55.004 -> 50.004
    (Δ −0.008); −Z at F_z 100.006 -> 80.006."""
    rough = {"X-": 50.0, "Z-": 80.0}
    rec, shown = calibrate_tool_probe({"X-": 55.012}, 20.0, 5.0, G17, rough)
    assert rec["X-"] == pytest.approx(50.012, abs=1e-12)
    assert shown["difference"]["X-"] == pytest.approx(0.012, abs=1e-12)
    rec, shown = calibrate_tool_probe({"X-": 55.004}, 20.0, 5.0, G17, rec)
    assert rec["X-"] == pytest.approx(50.004, abs=1e-12)
    assert shown["difference"]["X-"] == pytest.approx(-0.008, abs=1e-12)
    rec, _ = calibrate_tool_probe({"Z-": 100.006}, 20.0, 5.0, G17, rec)
    assert rec["Z-"] == pytest.approx(80.006, abs=1e-12)


def test_14_4_A_length_radius_and_offsets():
    """§14.4-A: _TP[0,0] = 50.012, _TP[0,4] = 80.006, L1 = 70, R = 18."""
    tp = {"X-": 50.012, "Z-": 80.006}
    length = tool_length(150.306, tp, G17)
    assert length == pytest.approx(70.300, abs=1e-12)
    upd = tool_offset_update(length, 70.0, 0.0, "geometry")
    assert upd["delta"] == pytest.approx(0.300, abs=1e-12) and upd["geometry"] == pytest.approx(70.3)
    radius = tool_radius(67.912, "X-", tp)
    assert radius == pytest.approx(17.900, abs=1e-12)
    upd = tool_offset_update(radius, 18.0, 0.0, "geometry")
    assert upd["geometry"] == pytest.approx(17.900) and upd["wear"] == 0.0
    # re-measurement into wear (_CHBIT[3]=1), R_geo 18.000, wear 0.024, _TZL 0.04
    same = tool_offset_update(17.990, 18.0, 0.024, "wear", zero_limit=0.04)
    assert same["delta"] == pytest.approx(-0.034, abs=1e-12) and same["wear"] == 0.024
    moved = tool_offset_update(17.950, 18.0, 0.024, "wear", zero_limit=0.04)
    assert moved["delta"] == pytest.approx(-0.074, abs=1e-12)
    assert moved["wear"] == pytest.approx(-0.050, abs=1e-12) and moved["geometry"] == 18.0


def test_offset_modes_jog():
    """spec §7.3 / §11 Q13: geometry := measured, wear cleared; wear := measured − geometry."""
    geo = tool_offset_update(85.123, 85.0, 0.05, "geometry")
    assert (geo["geometry"], geo["wear"]) == (85.123, 0.0)
    wear = tool_offset_update(85.123, 85.0, 0.05, "wear")
    assert wear["geometry"] == 85.0 and wear["wear"] == pytest.approx(0.123, abs=1e-12)


def test_14_3_A_compensation_table():
    """§14.3-A: radii (5, 10, 20, 40), speeds (20, 50, 80, 100, 150); r = 12, v = 100 -> [4, 3]."""
    table = [[0, 5, 10, 20, 40]] + [[v] + [10 * n + m for m in range(1, 5)]
                                    for n, v in enumerate((20, 50, 80, 100, 150), start=1)]
    assert compensation_table_value(table, 12.0, 100.0) == 43          # row 4, column 3
    assert compensation_table_value(table, 50.0, 200.0) == 54          # clamped to the last


@settings(max_examples=40, deadline=None)
@given(top=st.floats(-300, 0), face_minus=st.floats(100, 400), width=st.floats(10, 40),
       cal_l=st.floats(20, 150), cal_r=st.floats(2, 20), tool_l=st.floats(30, 200),
       tool_r=st.floats(1, 30), pre=st.floats(0, 0.01), nc_l=st.floats(30, 200))
def test_calibrate_then_measure_truth(top, face_minus, width, cal_l, cal_r, tool_l, tool_r, pre, nc_l):
    """A probe (faces X face_minus..face_minus+width, top Z) switching after pre-travel ``pre``:
    calibrating with an exact tool, then measuring another tool gives its true L and R."""
    face_plus = face_minus + width

    def tip_z(length, nc_length):          # latched tip = F − L_nc, F = top + L_true − pre
        return top + length - pre - nc_length

    cal = ToolProbePoint(mode="length_diameter", tool_radius=cal_r, tool_length=cal_l, touches=(
        ToolTouch("Z-", np.array([0.0, 0.0, tip_z(cal_l, cal_l)])),
        ToolTouch("X+", np.array([face_minus - cal_r + pre, 0.0, 0.0])),
        ToolTouch("X-", np.array([face_plus + cal_r - pre, 0.0, 0.0])),
        ToolTouch("Z-", np.array([1.0, 0.0, tip_z(cal_l, cal_l)]))))
    tp, shown = calibrate_tool_probe_point(cal, G17)
    assert shown["center"]["X"] == pytest.approx((face_minus + face_plus) / 2, abs=1e-9)
    length_point = ToolPoint(kind="length", touch=ToolTouch("Z-", np.array([0, 0, tip_z(tool_l, nc_l)])),
                             rotating=False, speed=0.0, feeds=(100.0,), offset_v=0.0, lateral_offset=0.0,
                             tool_radius=tool_r, tool_length=nc_l)
    assert tool_point_value(length_point, tp, G17) == pytest.approx(tool_l, abs=1e-9)
    for key, x in (("X-", face_plus + tool_r - pre), ("X+", face_minus - tool_r + pre)):
        radius_point = ToolPoint(kind="radius", touch=ToolTouch(key, np.array([x, 0.0, 0.0])),
                                 rotating=True, speed=500.0, feeds=(5.0,), offset_v=0.0,
                                 lateral_offset=0.0, tool_radius=tool_r + 0.3, tool_length=nc_l)
        assert tool_point_value(radius_point, tp, G17) == pytest.approx(tool_r, abs=1e-9)


def test_missing_calibration_and_zero_tool():
    with pytest.raises(MeasuringError) as err:
        tool_length(100.0, {}, G17)
    assert err.value.alarm == 61341
    with pytest.raises(MeasuringError) as err:
        calibrate_tool_probe({"X-": 10.0}, 20.0, 0.0, G17)
    assert err.value.alarm == 61351


def test_evaluate_tool_task_wrappers():
    from engine.toolmeasure import evaluate_tool_task
    tp = {"X-": 50.012, "Z-": 80.006}
    point = ToolPoint(kind="length", touch=ToolTouch("Z-", np.array([0.0, 0.0, 80.306])), rotating=False,
                      speed=0.0, feeds=(100.0,), offset_v=0.0, lateral_offset=0.0, tool_radius=18.0,
                      tool_length=70.0)                      # F_z = 80.306 + 70 = 150.306 (§14.4-A)
    tool, values = evaluate_tool_task("tool.length", {"compensation": "geometry"}, point, G17, tp,
                                      {"t": 3, "length": 70.0, "radius": 18.0,
                                       "wear": {"length": 0.01, "radius": 0.0}})
    assert values["length"] == pytest.approx(70.300, abs=1e-9)
    assert tool["length"] == pytest.approx(70.300) and tool["wear"]["length"] == 0.0
    point_r = ToolPoint(kind="radius", touch=ToolTouch("X-", np.array([67.912, 0.0, 0.0])), rotating=True,
                        speed=800.0, feeds=(8.0,), offset_v=0.0, lateral_offset=0.0, tool_radius=18.0,
                        tool_length=70.0)
    tool, values = evaluate_tool_task("tool.diameter", {"compensation": "wear"}, point_r, G17, tp,
                                      {"length": 70.0, "radius": 18.0})
    assert values["radius"] == pytest.approx(17.900, abs=1e-9)
    assert values["diameter"] == pytest.approx(35.800, abs=1e-9)
    assert tool["radius"] == 18.0 and tool["wear"]["radius"] == pytest.approx(-0.100, abs=1e-9)


def test_latch_delay_from_two_stages_at_different_feeds():
    """Latched tip = switch point + v·t along the travel (design.md §5): two stages at 100 and
    10 mm/min give t back, and the correction refers a 10 mm/min measurement to a 100 mm/min
    calibration: (v_meas − v_cal)·t."""
    from engine.toolmeasure import latch_delay_correction

    t_true, switch_z = 0.004, -137.25
    feeds = [100.0, 10.0]
    tips = [np.array([0.0, 0.0, switch_z - f / 60.0 * t_true]) for f in feeds]   # travel −Z
    t, correction = latch_delay_correction(tips, "Z-", feeds, 100.0, cal_feed=100.0, cal_override=100.0)
    assert t == pytest.approx(t_true, rel=1e-9)
    assert correction == pytest.approx((10.0 - 100.0) / 60.0 * t_true, rel=1e-9)
    # stages that cannot tell the delay apart give no correction
    assert latch_delay_correction(tips[:1], "Z-", feeds[:1], 100.0, 100.0, 100.0) == (None, 0.0)
    assert latch_delay_correction([tips[0], None], "Z-", feeds, 100.0, 100.0, 100.0) == (None, 0.0)
