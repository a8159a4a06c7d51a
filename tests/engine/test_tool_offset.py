"""engine.tool_offset (with engine.strategy's decisions) against measuring-math §2.3, §3.7, §9 and
turning.md §0.11 / §5.

Expected values are the spec's worked examples (3.7-A, 9-A, the §2.3 worked check, turning
5-B/5-C) or hand arithmetic on them; the sign property checks the rule against small physical
models written here from measuring-math §0.3, turning §0.4 and design.md §9.3's simulator
formula (bore Ø = nominal + 2·(R_true − R_comp)), not against the code.
"""

from __future__ import annotations

import pytest
from hypothesis import given
from hypothesis import strategies as st

from engine import alarms
from engine.strategy import Tolerance, decide_tool_offset
from engine.tool_offset import FEATURES, apply_compensation, compensation_value, tool_offset_update

T20 = {"t": 20, "edge": 1, "length": 120.0, "radius": 8.0, "wear": {"length": 0.0, "radius": 0.0}}


# --- measuring-math 3.7-A: five parts of the bore example, in sequence ------------------------

def test_3_7_A_all_five_parts():
    """3.7-A (manual §5.4 bore example): _SETVAL 132, ±0.03, _TZL 0.01, _TMV 0.02, _TDIF 0.06,
    _TSA 1, _K 3, _EVNUM 10, _CHBIT[4]=1, _KNUM 2001 (D1, radius, normal), T20;
    _EV[9] = 0.004, _MV[9] = 0.006. T20's radius wear starts at 0 (assumed)."""
    tol = Tolerance(setpoint=132.0, upper=0.03, lower=-0.03, zero_range=0.01, mean_range=0.02,
                    dim_difference=0.06, safe_area=1.0, k=3, evnum=10, keep_mean=True)
    assert tol.memories.ev_index == 9 and tol.memories.mv_index == 9 and tol.warnings() == []
    ev, mv, tool = 0.004, 0.006, T20

    # 1. Ø132.020 → D = 0.016 ≤ _TMV → Mv = 0.006 − (0.006 − 0.016)/3 = 0.009333 (= 28/3000)
    #    ≤ _TZL → no correction, _MV[9] = 0.009333
    d = decide_tool_offset(132.020, tol, ev=ev, mv_old=mv)
    assert d.deviation == pytest.approx(0.016, abs=1e-9)
    assert d.mean_value == pytest.approx(0.009333, abs=5e-7)
    assert d.mean_value == pytest.approx(28 / 3000, abs=1e-9)
    assert (d.decision, d.alarm, d.corrected, d.memory_cleared) == ("none", None, 0.0, False)
    assert d.mv_memory == pytest.approx(28 / 3000, abs=1e-9)
    up = tool_offset_update(tool, d, "bore", correct="radius", mode="wear")
    assert not up.written and up.compensation == 0.0 and up.after == up.before
    mv, tool = d.mv_memory, up.after

    # 2. Ø132.021 → D = 0.017 → Mv = 0.009333 − (0.009333 − 0.017)/3 = 0.011889 (= 107/9000)
    #    > _TZL → radius wear += +0.011889/2 = +0.005944 (bore: c = +Mv/2), _MV[9] = 0
    d = decide_tool_offset(132.021, tol, ev=ev, mv_old=mv)
    assert d.deviation == pytest.approx(0.017, abs=1e-9)
    assert d.mean_value == pytest.approx(0.011889, abs=5e-7)
    assert d.mean_value == pytest.approx(107 / 9000, abs=1e-9)
    assert (d.decision, d.alarm, d.memory_cleared, d.mv_memory) == ("mean", None, True, 0.0)
    assert d.corrected == d.mean_value
    up = tool_offset_update(tool, d, "bore", correct="radius", mode="wear")
    assert up.compensation == pytest.approx(0.005944, abs=5e-7)
    assert up.compensation == pytest.approx(107 / 18000, abs=1e-9)
    assert up.after["wear"]["radius"] == pytest.approx(107 / 18000, abs=1e-9)
    assert up.after["radius"] == 8.0 and up.after["wear"]["length"] == 0.0
    mv, tool = d.mv_memory, up.after

    # 3. Ø132.050 → D = 0.046 > TUL_eff 0.03 → 62304 "oversize", c = +0.023, _MV[9] = 0
    d = decide_tool_offset(132.050, tol, ev=ev, mv_old=mv)
    assert d.deviation == pytest.approx(0.046, abs=1e-9)
    assert (d.decision, d.alarm, d.mv_memory) == ("oversize", alarms.OVERSIZE, 0.0)
    assert d.corrected == pytest.approx(0.046, abs=1e-9)
    up = tool_offset_update(tool, d, "bore", correct="radius", mode="wear")
    assert up.compensation == pytest.approx(0.023, abs=1e-9)
    assert up.after["wear"]["radius"] == pytest.approx(107 / 18000 + 0.023, abs=1e-9)
    mv, tool = d.mv_memory, up.after

    # 4. Ø132.070 → D = 0.066 > _TDIF → 62306, no correction
    d = decide_tool_offset(132.070, tol, ev=ev, mv_old=mv)
    assert d.deviation == pytest.approx(0.066, abs=1e-9)
    assert (d.decision, d.alarm, d.corrected, d.violation) == ("dimension_difference",
                                                               alarms.DIMENSION_DIFFERENCE, 0.0,
                                                               "dimension_difference")
    up = tool_offset_update(tool, d, "bore")
    assert not up.written and up.after == tool

    # 5. Ø133.2 → D = 1.196 > _TSA → 61303, abort
    d = decide_tool_offset(133.2, tol, ev=ev, mv_old=mv)
    assert d.deviation == pytest.approx(1.196, abs=1e-9)
    assert (d.decision, d.alarm, d.abort, d.violation) == ("safe_area", alarms.SAFE_AREA, True, "safe_area")
    up = tool_offset_update(tool, d, "bore")
    assert not up.written and up.after["wear"]["radius"] == pytest.approx(107 / 18000 + 0.023, abs=1e-9)


# --- measuring-math 9-A and the §2.3 worked check (CYCLE978, 1 point) -------------------------

def test_9_A_one_point_radius_correction():
    """9-A: surface X = 100 by T20, probe travels −X (σ = −1), _KNUM 2001, ±0.03, _TMV 0.02,
    _TZL 0.01, _TDIF 0.06, _TSA 1, _K 1, no memory. s = 100.008 → D 0.008 → Mv ≤ _TZL → none;
    s = 100.025 → D 0.025 > _TMV → 100 %: c = σ·D = −0.025 on T20's radius wear (full
    difference, not half: measuring-math §9.1, §17 Q2)."""
    tol = Tolerance(setpoint=100.0, upper=0.03, lower=-0.03, zero_range=0.01, mean_range=0.02,
                    dim_difference=0.06, safe_area=1.0, k=1)
    d = decide_tool_offset(100.008, tol)
    assert d.decision == "none" and d.mean_value == pytest.approx(0.008, abs=1e-9)
    assert not tool_offset_update(T20, d, "surface", direction=-1).written
    d = decide_tool_offset(100.025, tol)
    assert d.decision == "full" and d.corrected == pytest.approx(0.025, abs=1e-9)
    up = tool_offset_update(T20, d, "surface", correct="radius", mode="wear", direction=-1)
    assert up.compensation == pytest.approx(-0.025, abs=1e-9)
    assert up.after["wear"]["radius"] == pytest.approx(-0.025, abs=1e-9)


def test_2_3_worked_check_top_face():
    """measuring-math §2.3: a top face probed −Z is 0.02 too high (D = +0.02, σ = −1) → c = −0.02
    on L1 (the tool gets shorter, the next cut goes 0.02 deeper)."""
    assert compensation_value("surface", 0.02, "length", direction=-1) == pytest.approx(-0.02, abs=1e-15)
    up = tool_offset_update(T20, 0.02, "surface", correct="length", direction=-1)
    assert up.after["wear"]["length"] == pytest.approx(-0.02) and up.after["wear"]["radius"] == 0.0


def test_radius_rule_follows_the_probing_direction():
    """measuring-math §2.3 and turning §0.11: radius c = σ·D = +d·Δ."""
    assert compensation_value("surface", 0.01, "radius", direction=+1) == pytest.approx(0.01)
    assert compensation_value("surface", 0.01, "radius", direction=-1) == pytest.approx(-0.01)
    assert compensation_value("surface", -0.01, "radius", direction=-1) == pytest.approx(0.01)
    with pytest.raises(ValueError, match="direction"):
        compensation_value("surface", 0.01, "radius")
    with pytest.raises(ValueError, match="direction"):
        compensation_value("surface", 0.01, "radius", direction=0)


def test_length_rule_does_not_follow_the_probing_direction():
    """turning §0.11 / §12 Q4: length c = −Δ for −X/−Z and for +X/+Z probing alike (§2.3's σ·D
    would give +Δ for +X/+Z)."""
    for direction in (+1, -1):
        assert compensation_value("surface", 0.01, "length", direction=direction) == pytest.approx(-0.01)
        assert compensation_value("surface", -0.01, "length", direction=direction) == pytest.approx(0.01)


# --- widths and diameters ---------------------------------------------------------------------

@pytest.mark.parametrize("feature, sign", [("bore", 1), ("slot", 1), ("inner_rectangle", 1),
                                           ("shaft", -1), ("web", -1), ("outer_rectangle", -1)])
def test_width_features_halve_for_the_radius(feature, sign):
    """measuring-math §2.3: bore, slot, inner rectangle c = +D/2; shaft, web, outer c = −D/2;
    a rectangle's A is the mean of its two length differences (§8.3 [I])."""
    assert compensation_value(feature, 0.02, "radius") == pytest.approx(sign * 0.01, abs=1e-15)
    assert compensation_value(feature, -0.02, "radius") == pytest.approx(-sign * 0.01, abs=1e-15)
    assert compensation_value(feature, 0.02, "radius", inverse=True) == pytest.approx(-sign * 0.01)
    # the probing direction does not matter for a width (both sides were probed)
    assert compensation_value(feature, 0.02, "radius", direction=-1) == pytest.approx(sign * 0.01)


def test_rectangle_mean_of_both_lengths():
    d_a, d_o = 0.012, 0.020                                      # hand: mean 0.016, half 0.008
    assert compensation_value("inner_rectangle", (d_a + d_o) / 2, "radius") == pytest.approx(0.008)
    assert compensation_value("outer_rectangle", (d_a + d_o) / 2, "radius") == pytest.approx(-0.008)


def test_length_from_a_milled_width_is_refused():
    with pytest.raises(ValueError, match="side"):
        compensation_value("bore", 0.02, "length")
    with pytest.raises(ValueError, match="side"):
        compensation_value("shaft", 0.02, "length", side=0)


def test_cycle994_rules():
    """turning §0.11, CYCLE994: Δ = A/2 with DIAMON, A with DIAMOF; length c = −Δ (tool on the +X
    side), radius c = −Δ (OD), +Δ (ID); a tool below the turning centre: the inverse digit, or
    side = −1."""
    assert compensation_value("shaft", 0.02, "length", side=+1) == pytest.approx(-0.01)
    assert compensation_value("bore", 0.02, "length", side=+1) == pytest.approx(-0.01)
    assert compensation_value("shaft", 0.02, "length", side=-1) == pytest.approx(+0.01)
    assert compensation_value("shaft", 0.02, "length", side=+1, inverse=True) == pytest.approx(+0.01)
    assert compensation_value("shaft", 0.02, "radius") == pytest.approx(-0.01)
    assert compensation_value("bore", 0.02, "radius") == pytest.approx(+0.01)
    assert compensation_value("shaft", 0.02, "length", side=+1, amount_is_diameter=False) == pytest.approx(-0.02)
    assert compensation_value("bore", 0.02, "radius", amount_is_diameter=False) == pytest.approx(+0.02)


# --- turning 5-B / 5-C (CYCLE974 on X with DIAMON, L1 wear) -----------------------------------

LATHE = dict(zero_range=0.002, mean_range=0.005, dim_difference=0.04, safe_area=0.5, k=2, keep_mean=True)
T7 = {"t": 7, "length": 60.0, "radius": 0.8, "wear": {"length": 0.0, "radius": 0.0}}


def test_turning_5_B_outside_diameter():
    """turning 5-B: OD 45 (+0/−0.01), probe travels −X, _EVNUM 13, _EV[12] = 0.002,
    _MV[12] = 0.0010, _K 2: the five parts and the corrections of T7 D1's L1 wear (radius)."""
    tol = Tolerance(setpoint=45.0, upper=0.0, lower=-0.01, evnum=13, **LATHE)
    ev = 0.002

    def step(actual, mv):
        d = decide_tool_offset(actual, tol, ev=ev, mv_old=mv)
        up = tool_offset_update(T7, d, "surface", correct="length", direction=-1, amount_is_diameter=True)
        return d, up

    d, up = step(45.001, 0.0010)     # D 0.004 ≤ _TMV → Mv = 0.001 − (0.001 − 0.004)/2 = 0.0025 > _TZL
    assert d.deviation == pytest.approx(0.004, abs=1e-9) and d.mean_value == pytest.approx(0.0025, abs=1e-9)
    assert d.decision == "mean" and d.mv_memory == 0.0
    assert up.compensation == pytest.approx(-0.00125, abs=1e-9)
    assert up.after["wear"]["length"] == pytest.approx(-0.00125, abs=1e-9)
    d, up = step(45.009, 0.0)        # D 0.012 > TUL_eff → 62304, −0.006
    assert (d.decision, d.alarm) == ("oversize", alarms.OVERSIZE)
    assert up.compensation == pytest.approx(-0.006, abs=1e-9)
    d, up = step(44.990, 0.0)        # D −0.007 < TLL_eff → 62305, +0.0035
    assert d.deviation == pytest.approx(-0.007, abs=1e-9)
    assert (d.decision, d.alarm) == ("undersize", alarms.UNDERSIZE)
    assert up.compensation == pytest.approx(0.0035, abs=1e-9)
    d, up = step(45.060, 0.0)        # D 0.063 > _TDIF → 62306, none
    assert d.deviation == pytest.approx(0.063, abs=1e-9)
    assert (d.decision, d.alarm, up.written) == ("dimension_difference", alarms.DIMENSION_DIFFERENCE, False)
    d, up = step(45.600, 0.0)        # D 0.603 > _TSA → 61303, none
    assert d.deviation == pytest.approx(0.603, abs=1e-9)
    assert (d.decision, d.alarm, d.abort, up.written) == ("safe_area", alarms.SAFE_AREA, True, False)


def test_turning_5_B_inside_diameter_probed_plus_x():
    """turning 5-B, the ID 35 (+0.015/−0) by T8, probe travels +X: D = +0.012 → 62304 and
    c = −0.006 on T8's L1 wear, the same sign as an oversized OD (turning §0.11). measuring-math
    §2.3's 1-point rule c = σ·D would have given +0.006 (turning §12 Q4)."""
    tol = Tolerance(setpoint=35.0, upper=0.015, lower=0.0, evnum=14, **LATHE)
    assert tol.setpoint_eff == pytest.approx(35.0075) and tol.upper_eff == pytest.approx(0.0075)
    d = decide_tool_offset(35.0195, tol)                      # no EV: D = 35.0195 − 35.0075
    assert d.deviation == pytest.approx(0.012, abs=1e-9) and d.decision == "oversize"
    t8 = {"t": 8, "length": 45.0, "radius": 0.4, "wear": {"length": 0.001, "radius": 0.0}}
    up = tool_offset_update(t8, d, "surface", correct="length", direction=+1, amount_is_diameter=True)
    assert up.compensation == pytest.approx(-0.006, abs=1e-9)
    assert up.after["wear"]["length"] == pytest.approx(0.001 - 0.006, abs=1e-9)
    sigma_times_d_over_2 = +1 * 0.012 / 2                      # the old §2.3 rule, for contrast
    assert up.compensation == pytest.approx(-sigma_times_d_over_2)


def test_turning_5_C_reversal():
    """turning 5-C: act 45.006 against 44.995 → D 0.011 > TUL_eff → 62304, c = −0.0055 on L1 wear."""
    tol = Tolerance(setpoint=45.0, upper=0.0, lower=-0.01, zero_range=0.002, dim_difference=0.4, safe_area=1.0)
    d = decide_tool_offset(45.006, tol)
    assert d.deviation == pytest.approx(0.011, abs=1e-9) and d.alarm is alarms.OVERSIZE
    up = tool_offset_update(T7, d, "surface", correct="length", direction=-1, amount_is_diameter=True)
    assert up.compensation == pytest.approx(-0.0055, abs=1e-9)


# --- write rule -----------------------------------------------------------------------------

def test_wear_and_geometry_write_rule():
    """manual §2.3.6: _CHBIT[6]=0 wear += c; _CHBIT[6]=1 geometry := geometry + wear + c, wear := 0."""
    tool = {"t": 5, "name": "cutter", "length": 100.0, "radius": 6.0, "wear": {"length": 0.01, "radius": -0.002}}
    wear = apply_compensation(tool, 0.004, "radius", "wear")
    assert wear["radius"] == 6.0 and wear["wear"]["radius"] == pytest.approx(0.002)
    assert wear["wear"]["length"] == 0.01 and wear["t"] == 5 and wear["name"] == "cutter"
    geo = apply_compensation(tool, 0.004, "radius", "geometry")
    assert geo["radius"] == pytest.approx(6.002) and geo["wear"]["radius"] == 0.0
    assert geo["wear"]["length"] == 0.01 and geo["length"] == 100.0
    geo_l = apply_compensation(tool, -0.03, "length", "geometry")
    assert geo_l["length"] == pytest.approx(99.98) and geo_l["wear"]["length"] == 0.0
    # the input is not modified
    assert tool == {"t": 5, "name": "cutter", "length": 100.0, "radius": 6.0,
                    "wear": {"length": 0.01, "radius": -0.002}}


def test_no_correction_writes_nothing_even_in_geometry_mode():
    """A decision that corrects nothing leaves the tool alone: geometry mode does not fold the wear."""
    tool = {"length": 100.0, "radius": 6.0, "wear": {"length": 0.01, "radius": -0.002}}
    tol = Tolerance(setpoint=0.0, upper=0.03, lower=-0.03, zero_range=0.01, mean_range=0.02,
                    dim_difference=0.06, safe_area=1.0)
    for actual in (0.005, 0.07, 1.5):                         # none, dimension difference, safe area
        up = tool_offset_update(tool, decide_tool_offset(actual, tol), "bore", mode="geometry")
        assert not up.written and up.compensation == 0.0 and up.after == up.before == tool
    up = tool_offset_update(tool, None, "bore", mode="geometry")
    assert not up.written and up.after == tool


def test_missing_wear_is_zero_and_bad_input():
    up = tool_offset_update({"length": 50.0, "radius": 4.0}, 0.01, "bore")
    assert up.before["wear"] == {"length": 0.0, "radius": 0.0}
    assert up.after["wear"]["radius"] == pytest.approx(0.005)
    with pytest.raises(ValueError, match="radius"):
        apply_compensation({"length": 50.0}, 0.01, "radius", "geometry")
    with pytest.raises(ValueError, match="feature"):
        compensation_value("hole", 0.01)
    with pytest.raises(ValueError, match="feature"):
        tool_offset_update(T20, None, "hole")
    with pytest.raises(ValueError, match="correct"):
        compensation_value("bore", 0.01, "diameter")
    with pytest.raises(ValueError, match="mode"):
        tool_offset_update(T20, 0.01, "bore", mode="setup")
    with pytest.raises(ValueError, match="wear.radius"):
        apply_compensation({"radius": 4.0, "wear": {"radius": "x"}}, 0.01)
    with pytest.raises(ValueError, match="amount"):
        compensation_value("bore", True)


# --- the sign rule against physical models ------------------------------------------------------

def _measured_amount(feature, correct, r_true, r_comp, l_true, l_comp, d, side):
    """What a probe measures after a cut, from first principles (not from the code):

    - radius (design.md §9.3 simulator): the tool centre runs R_comp off the contour on the free
      side; the cut surface lies R_true from the centre. Bore/slot/inner Ø = nominal + 2(R_true −
      R_comp), shaft/web/outer Ø = nominal − 2(R_true − R_comp); a surface the probe reaches
      travelling d (material ahead) lies at contour + d·(R_true − R_comp).
    - length (measuring-math §0.3, turning §0.4): the NC puts F at programmed + L_comp, the real
      tip is F − L_true: the cut surface lies at programmed + (L_comp − L_true) along the axis;
      a turned diameter cut on side s of the centre: radius R_nom + s·(L_comp − L_true).
    """
    if correct == "radius":
        e = r_true - r_comp
        if feature == "surface":
            return d * e
        return 2 * e if feature in ("bore", "slot", "inner_rectangle") else -2 * e
    e = l_comp - l_true
    if feature == "surface":
        return e
    return 2 * side * e


@given(feature=st.sampled_from(FEATURES), correct=st.sampled_from(["radius", "length"]),
       r_true=st.floats(1, 20), r_comp=st.floats(1, 20), l_true=st.floats(50, 200),
       l_comp=st.floats(50, 200), d=st.sampled_from([1, -1]), side=st.sampled_from([1, -1]),
       mode=st.sampled_from(["wear", "geometry"]))
def test_a_full_correction_removes_the_deviation(feature, correct, r_true, r_comp, l_true, l_comp, d, side,
                                                 mode):
    """Measure, correct by 100 %, cut again: the deviation is gone — for every feature kind,
    probing direction, turning side and write mode."""
    wear = 0.3
    tool = {"length": l_comp - wear, "radius": r_comp - wear, "wear": {"length": wear, "radius": wear}}
    amount = _measured_amount(feature, correct, r_true, r_comp, l_true, l_comp, d, side)
    up = tool_offset_update(tool, amount, feature, correct=correct, mode=mode, direction=d,
                            side=side if feature != "surface" and correct == "length" else None)
    after = up.after
    r_new = after["radius"] + after["wear"]["radius"]
    l_new = after["length"] + after["wear"]["length"]
    again = _measured_amount(feature, correct, r_true, r_new, l_true, l_new, d, side)
    assert again == pytest.approx(0.0, abs=1e-9)
