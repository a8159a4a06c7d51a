"""Lathe conventions (turning.md §0) and the tool/frame updates (§0.11, MM §2.1–§2.3)."""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine import alarms
from engine.turning import (
    LatheProbe,
    LatheTool,
    axis_of_ma,
    check_fa,
    direction_of_md,
    ev_mv_numbers,
    leading_offset,
    measuring_feed,
    probe_directions,
    sl_vector,
    to_display,
    to_radius,
    tool_family,
    tp_to_list,
)
from engine.turning_offsets import (
    ToolTarget,
    correction_value,
    decode_tool_knum,
    tool_measure_update,
    workpiece_tool_update,
    zero_offset_update,
)
from engine.types import MeasuringError


def test_sl_table():
    """§0.5: SL 3 tip down-left (M-derived: Z30 = 35 − 5), SL 7 −Z, SL 8 −X; the ISO grid."""
    assert sl_vector(3) == {"X": -1, "Y": 0, "Z": -1}
    assert sl_vector(7) == {"X": 0, "Y": 0, "Z": -1}
    assert sl_vector(8) == {"X": -1, "Y": 0, "Z": 0}
    assert sl_vector(1) == {"X": 1, "Y": 0, "Z": 1}
    assert 35.0 + sl_vector(3)["Z"] * 5.0 == 30.0                  # P_z = z_c + s_Z·R (1-A)
    with pytest.raises(MeasuringError) as err:
        sl_vector(10)
    assert err.value.definition is alarms.CUTTING_EDGE_POSITION


def test_sl_recode():
    """_CHBIT[23]: mirrored at X: SL 1<->4, 2<->3, 6<->8; 5, 7 unchanged (§0.5)."""
    for a, b in ((1, 4), (2, 3), (6, 8), (5, 5), (7, 7)):
        assert sl_vector(a, recode=True) == sl_vector(b)


def test_leading_point():
    """§0.5: leading = P + (d − s)·R: d = s the tip, d = −s 2R beyond, s = 0: R."""
    assert leading_offset(-1, -1, 5.0) == 0.0
    assert leading_offset(1, -1, 5.0) == 10.0
    assert leading_offset(-1, 0, 0.4) == -0.4


def test_probe_directions():
    """§0.6: every axis direction except into the stylus."""
    assert set(probe_directions(7)) == {"X+", "X-", "Y+", "Y-", "Z-"}
    assert set(probe_directions(8)) == {"X-", "Y+", "Y-", "Z+", "Z-"}
    assert "Z-" not in probe_directions(5) and "X-" not in probe_directions(6)
    with pytest.raises(MeasuringError) as err:
        probe_directions(3)
    assert err.value.definition is alarms.CUTTING_EDGE_POSITION


def test_diamon():
    """§0.3 engine rule: halve/double on X with DIAMON only; Y only with _CHBIT[19]."""
    assert to_radius(45.0, "X", True) == 22.5 and to_radius(45.0, "X", False) == 45.0
    assert to_radius(60.0, "Z", True) == 60.0
    assert to_radius(45.0, "Y", True) == 45.0 and to_radius(45.0, "Y", True, True) == 22.5
    assert to_display(22.503, "X", True) == pytest.approx(45.006)


def test_parameters():
    assert measuring_feed(0.0, 1.0) == 150.0 and measuring_feed(0.0, 0.5) == 150.0
    assert measuring_feed(0.0, 2.0) == 300.0 and measuring_feed(500.0, 1.0) == 500.0
    assert ev_mv_numbers(11) == (11, 11) and ev_mv_numbers(90012) == (12, 9)
    assert axis_of_ma(1) == "Z" and axis_of_ma(2) == "X" and axis_of_ma(3) == "Y"
    assert direction_of_md(0) == 1 and direction_of_md(1) == -1
    for bad, fn, alarm in ((0.0, check_fa, alarms.MEASURING_PATH), (4, axis_of_ma, alarms.MEASURING_AXIS),
                           (2, direction_of_md, alarms.MEASURING_DIRECTION)):
        with pytest.raises(MeasuringError) as err:
            fn(bad)
        assert err.value.definition is alarm
    assert tool_family(500) == "turning" and tool_family(120) == "mill" and tool_family(750) == "mill"
    assert tool_family(220) == "drill" and tool_family(710) is None


def test_records():
    """§0.7: _TP[k,0..3] = Z−, Z+, X−, X+; _WP[k,0..10] turning layout."""
    assert tp_to_list({"X-": 400.25, "Z-": 220.35}) == [220.35, 0.0, 400.25, 0.0]
    values = [5.99, 2.995, -2.99, 2.991, -2.999, 2.9, -2.9, 0.001, 0.004, 0.0, 0.0]
    probe = LatheProbe.from_wp(values)
    assert probe.wp() == values
    assert probe.trigger_value("X+") == -2.999 and probe.skew == {"Z": 0.001, "X": 0.004}
    assert list(probe.skew_vector()) == [0.004, 0.0, 0.001]


# --- tool data ---------------------------------------------------------------------------------

def test_tool_measure_update():
    """§2.4: first measurement geometry := L − base, wear := 0; re-measurement wear += Δ."""
    tool = LatheTool(t=3, l1=100.65, l2=60.32, radius=2.0, wear_l1=0.01, base_l1=1.0)
    before, after = tool_measure_update(tool, "l1", 101.7, remeasure=False)
    assert before["l1"] == 100.65 and before["wear"]["l1"] == 0.01
    assert after["l1"] == pytest.approx(100.7) and after["wear"]["l1"] == 0.0
    _, after = tool_measure_update(tool, "l1", 101.7, remeasure=True)
    assert after["l1"] == 100.65 and after["wear"]["l1"] == pytest.approx(0.05)
    _, after = tool_measure_update(tool, "l1", 101.7, remeasure=True, incremental=True)
    assert after["l1"] == pytest.approx(100.7) and after["wear"]["l1"] == 0.0
    _, after = tool_measure_update({"l1": 5, "l2": 6, "radius": 14.0, "sl": 0, "type": 120}, "radius", 13.98,
                                   remeasure=False)
    assert after["radius"] == 13.98 and after["sl"] == 0 and after["type"] == 120


def test_correction_signs():
    """§0.11: test cut Ø200.100 vs Ø200 -> L1 60.000 -> 59.950 [L16855–L16858] (c = −A/2);
    1-point radius c = +d·Δ; 2-point radius −Δ outside, +Δ inside; inverse flips."""
    assert 60.0 + correction_value(0.1, scale=0.5, radius=False) == pytest.approx(59.95)
    assert correction_value(0.012, scale=1.0, radius=False) == pytest.approx(-0.012)
    assert correction_value(0.01, scale=0.5, radius=True, direction=-1) == pytest.approx(-0.005)
    assert correction_value(0.01, scale=0.5, radius=True, direction=1) == pytest.approx(0.005)
    assert correction_value(0.01, scale=0.5, radius=True, two_point=True) == pytest.approx(-0.005)
    assert correction_value(0.01, scale=0.5, radius=True, two_point=True, inside=True) == pytest.approx(0.005)
    assert correction_value(0.01, scale=0.5, radius=False, inverse=True) == pytest.approx(0.005)
    with pytest.raises(ValueError):
        correction_value(0.01, scale=1.0, radius=True)


@given(stored_err=st.floats(-0.5, 0.5), below=st.booleans(), diamon=st.booleans())
def test_length_correction_closes_the_loop(stored_err, below, diamon):
    """Closed loop (turning.md §11): a surface cut with L1 stored too long by err lies at the
    programmed X + err (signed, above or below the turning centre); the signed 1-point D and
    c = −Δ (§0.11) make the next cut exact."""
    nominal = (-1.0 if below else 1.0) * 40.0          # programmed radius of the surface
    cut = nominal + stored_err                          # turning.md §11: + (L_stored − L_true)
    scale = 0.5 if diamon else 1.0
    d = (cut - nominal) / scale                         # D in the display unit (diameter with DIAMON)
    c = correction_value(d, scale=scale, radius=False)
    assert nominal + (stored_err + c) == pytest.approx(nominal, abs=1e-12)


def test_knum_tool_layout():
    """MM §2.3 decoding examples: 12003 -> D3 radius inverse; 100002 -> D2 L1; 1001002 -> D2
    length, setup/sum offset _DLNUM; 2100000 -> D/T from the tool environment, L1."""
    t = decode_tool_knum(12003, tnum=5)
    assert (t.d, t.quantity, t.inverse, t.dl) == (3, "radius", True, 0)
    assert decode_tool_knum(100002, tnum=5).quantity == "l1"
    t = decode_tool_knum(1001002, tnum=5, dlnum=3)
    assert (t.d, t.quantity, t.dl) == (2, "length", 3)
    t = decode_tool_knum(2100000, tenv="ENV1")
    assert (t.quantity, t.tenv) == ("l1", "ENV1")
    assert decode_tool_knum(0) is None
    assert ToolTarget(quantity="length").resolve("Z") == "l2"
    assert ToolTarget(quantity="length").resolve("Y") == "l3"
    assert ToolTarget(quantity="length").resolve("Y", y_like_x=True) == "l1"


def test_workpiece_tool_update():
    """MM §2.3 write rule: wear += c; _CHBIT[6]=1 geometry := geometry + wear + c, wear := 0;
    DL offsets: sum += c, with _CHBIT[8]=1 setup += c."""
    tool = LatheTool(t=7, l1=60.0, wear_l1=0.01)
    _, after = workpiece_tool_update(tool, "l1", -0.005, ToolTarget(t=7))
    assert after["wear"]["l1"] == pytest.approx(0.005) and after["l1"] == 60.0
    _, after = workpiece_tool_update(tool, "l1", -0.005, ToolTarget(t=7, geometry=True))
    assert after["l1"] == pytest.approx(60.005) and after["wear"]["l1"] == 0.0
    dl_tool = {"l1": 60.0, "dl": {1: {"setup": {"l1": 0.2}, "sum": {"l1": 0.01}}}}
    _, after = workpiece_tool_update(dl_tool, "l1", 0.003, ToolTarget(t=7, dl=1, setup=True))
    assert after["dl"][1]["setup"]["l1"] == pytest.approx(0.203) and after["dl"][1]["sum"]["l1"] == 0.01
    _, after = workpiece_tool_update(dl_tool, "l1", 0.003, ToolTarget(t=7, dl=1, geometry=True))
    assert after["dl"][1]["setup"]["l1"] == pytest.approx(0.213) and after["dl"][1]["sum"]["l1"] == 0.0
    with pytest.raises(MeasuringError) as err:
        workpiece_tool_update({"l1": 1.0, "dl": {1: {"setup": {}}}}, "l1", 0.1, ToolTarget(dl=1))
    assert err.value.definition is alarms.SUM_OFFSET_MISSING


def test_zero_offset_update():
    """MM §2.1/§2.2: fine += d; coarse := coarse + fine + d, fine := 0 (5-A: Z 200 -> 200.150)."""
    before, after = zero_offset_update([0, 0, 200.0], [0, 0, 0], "Z", 0.15, fine_mode=False)
    assert after["coarse"][2] == pytest.approx(200.15) and before["coarse"][2] == 200.0
    _, after = zero_offset_update([1.0, 0, 200.0], [0.5, 0, 0.02], "Z", 0.15, fine_mode=False)
    assert after["coarse"] == pytest.approx([1.5, 0.0, 200.17]) and after["fine"] == [0.0, 0.0, 0.0]
    _, after = zero_offset_update([1.0, 0, 200.0], [0.5, 0, 0.02], "Z", 0.15, fine_mode=True)
    assert after["fine"] == pytest.approx([0.5, 0.0, 0.17]) and after["coarse"] == [1.0, 0.0, 200.0]
