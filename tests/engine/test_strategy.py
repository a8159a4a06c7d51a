"""engine.strategy against measuring-math §3 (manual §1.9–§1.11, §2.3.11, §2.3.14, §9.2).

Expected numbers come from the spec and the manual (worked examples 3.2-A, 3.4-A, 14.4-A,
14.5-A, turning 5-A/5-C), or are hand arithmetic on them, never from the code's own output.
The five parts of 3.7-A, with the tool wear, are in test_tool_offset.py.
"""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from engine import alarms
from engine.strategy import (
    DECISIONS,
    Memories,
    Tolerance,
    average,
    decide_calibration,
    decide_tool_measurement,
    decide_tool_offset,
    decide_zero_offset,
    decode_evnum,
    mean_value,
    repeat_measurement,
)
from engine.types import MeasuringError

# the bore example of manual §5.4 (measuring-math 3.7-A), used for branch tests with k = 1
BAND = dict(upper=0.03, lower=-0.03, zero_range=0.01, mean_range=0.02, dim_difference=0.06, safe_area=1.0)


# --- §3.2 tolerance parameters ----------------------------------------------------------------

def test_defaults_are_the_spec_table():
    """measuring-math §3.2 table / manual appendix: _TZL 0.001, _TMV 0.7, _TUL 1, _TLL −1,
    _TDIF 1.2, _TSA 2, _TNVL 1.2, _K 1; _EVNUM 0 (§4.1), _CHBIT[4] 0."""
    t = Tolerance()
    assert (t.zero_range, t.mean_range, t.upper, t.lower) == (0.001, 0.7, 1.0, -1.0)
    assert (t.dim_difference, t.safe_area, t.distortion_limit, t.k) == (1.2, 2.0, 1.2, 1)
    assert (t.evnum, t.keep_mean) == (0, False)
    assert t.warnings() == []


def test_3_2_A_symmetrisation():
    """3.2-A (manual §2.3.11): _TUL=0.0, _TLL=−0.004, _SETVAL=10 → _OVR[0]=9.998, _OVR[8]=0.002,
    _OVR[12]=−0.002; the input parameters stay unchanged."""
    t = Tolerance(setpoint=10.0, upper=0.0, lower=-0.004)
    assert t.setpoint_eff == pytest.approx(9.998, abs=1e-12)
    assert t.upper_eff == pytest.approx(0.002, abs=1e-12)
    assert t.lower_eff == pytest.approx(-0.002, abs=1e-12)
    assert (round(t.setpoint_eff, 3), round(t.upper_eff, 3), round(t.lower_eff, 3)) == (9.998, 0.002, -0.002)
    assert (t.setpoint, t.upper, t.lower) == (10.0, 0.0, -0.004)


def test_symmetric_band_is_unchanged():
    t = Tolerance(setpoint=132.0, **BAND)
    assert (t.setpoint_eff, t.upper_eff, t.lower_eff) == (132.0, 0.03, -0.03)


def test_turning_5B_symmetrisation():
    """turning 5-B: _SETVAL=45, _TUL=0, _TLL=−0.01 → 44.995, +0.005, −0.005; the ID: 35,
    +0.015/0 → 35.0075, 0.0075."""
    od = Tolerance(setpoint=45.0, upper=0.0, lower=-0.01)
    assert (od.setpoint_eff, od.upper_eff, od.lower_eff) == pytest.approx((44.995, 0.005, -0.005), abs=1e-12)
    bore = Tolerance(setpoint=35.0, upper=0.015, lower=0.0)
    assert (bore.setpoint_eff, bore.upper_eff) == pytest.approx((35.0075, 0.0075), abs=1e-12)


@given(setpoint=st.floats(-1000, 1000), upper=st.floats(-1, 1), width=st.floats(0, 2))
def test_symmetrisation_keeps_the_band(setpoint, upper, width):
    """The band [SETVAL + TLL, SETVAL + TUL] is the same before and after (manual §2.3.11)."""
    t = Tolerance(setpoint=setpoint, upper=upper, lower=upper - width)
    assert t.setpoint_eff + t.upper_eff == pytest.approx(setpoint + upper, abs=1e-9)
    assert t.setpoint_eff + t.lower_eff == pytest.approx(setpoint + upper - width, abs=1e-9)
    assert t.upper_eff == pytest.approx(-t.lower_eff, abs=1e-12)


def test_magnitude_order_warnings():
    """manual §1.10: |_TZL| < |_TMV| < tolerance < |_TDIF| < |_TSA|; measuring-math §3.2 [I] warns."""
    assert Tolerance(setpoint=132.0, **BAND).warnings() == []
    # turning 5-C: _TMV left at its default 0.7 against TUL_eff 0.005 (turning §12 Q18)
    lathe = Tolerance(setpoint=45.0, upper=0.0, lower=-0.01, zero_range=0.002, dim_difference=0.4,
                      safe_area=1.0)
    messages = lathe.warnings()
    assert len(messages) == 1 and "mean_range" in messages[0] and "TUL_eff" in messages[0]
    # only magnitudes matter: a negative _TZL is read as its magnitude
    assert Tolerance(zero_range=-0.001).warnings() == []
    swapped = Tolerance(zero_range=0.01, mean_range=0.7, dim_difference=3.0, safe_area=2.0)
    assert any("dim_difference" in m and "safe_area" in m for m in swapped.warnings())
    # tool measuring only orders _TZL < _TDIF < _TSA (14.4-A: 0.04, 1.6, 2)
    tool = Tolerance(zero_range=0.04, dim_difference=1.6, safe_area=2.0)
    assert tool.warnings("tool") == []
    assert tool.warnings("calibration") == []
    assert Tolerance(zero_range=0.04, dim_difference=2.5, safe_area=2.0).warnings("tool") != []
    with pytest.raises(ValueError, match="scope"):
        tool.warnings("lathe")


@pytest.mark.parametrize("name", ["setpoint", "upper", "lower", "zero_range", "mean_range",
                                  "dim_difference", "safe_area", "distortion_limit"])
@pytest.mark.parametrize("bad", [math.nan, math.inf, True, "0.1", None])
def test_bad_numbers_name_the_field(name, bad):
    with pytest.raises(ValueError, match=name):
        Tolerance(**{name: bad})


def test_validation():
    with pytest.raises(ValueError, match="safe_area"):
        Tolerance(safe_area=0.0)
    with pytest.raises(ValueError, match="dim_difference"):
        Tolerance(dim_difference=0.0)
    with pytest.raises(ValueError, match="upper"):
        Tolerance(upper=-0.01, lower=0.0)           # turning 5-B's misprinted prose, swapped band
    with pytest.raises(ValueError, match="keep_mean"):
        Tolerance(keep_mean=1)
    for bad in (-1, 2.5, 100_000_000, True):
        with pytest.raises(ValueError, match="evnum"):
            Tolerance(evnum=bad)
    assert Tolerance(upper=0.01, lower=0.01).upper_eff == 0.0     # a zero-width band is legal


@pytest.mark.parametrize("k", [0, -1, -3])
def test_k_below_one_is_alarm_61318(k):
    """manual alarm list: 61318 "Check weighting factor _K" (parameter _K is 0); range _K ≥ 1."""
    with pytest.raises(MeasuringError) as err:
        Tolerance(k=k)
    assert err.value.definition is alarms.WEIGHTING_FACTOR
    assert "k" in err.value.message
    with pytest.raises(MeasuringError) as err:
        mean_value(0.0, 0.01, k)
    assert err.value.definition is alarms.WEIGHTING_FACTOR


def test_k_must_be_an_integer():
    """_K is INT (manual appendix); a non-integer cannot be held: ValueError naming k."""
    for bad in (2.5, True, "3", math.nan):
        with pytest.raises(ValueError, match="k"):
            Tolerance(k=bad)
    assert Tolerance(k=3.0).k == 3 and isinstance(Tolerance(k=3.0).k, int)


def test_from_params_uses_design_keys_and_defaults():
    """design.md §9.3 params.tolerance keys; missing keys come from the settings."""
    settings_tol = Tolerance(zero_range=0.01, safe_area=1.0)
    t = Tolerance.from_params({"setpoint": 132, "upper": 0.03, "lower": -0.03, "k": 3, "evnum": 10,
                               "keep_mean": True}, settings_tol)
    assert (t.setpoint, t.upper, t.lower, t.k, t.evnum, t.keep_mean) == (132.0, 0.03, -0.03, 3, 10, True)
    assert (t.zero_range, t.safe_area, t.mean_range) == (0.01, 1.0, 0.7)
    assert Tolerance.from_params(None) == Tolerance()
    with pytest.raises(ValueError, match="tolrance"):
        Tolerance.from_params({"tolrance": 1})
    with pytest.raises(ValueError, match="upper"):
        Tolerance.from_params({"upper": True})
    with pytest.raises(MeasuringError):
        Tolerance.from_params({"k": 0})


# --- §3.3 _EVNUM ------------------------------------------------------------------------------

def test_evnum_examples_of_the_manual():
    """manual §2.3.14: 11 → EV memory 11 = _EV[10], MV 11 = _MV[10]; 90012 → EV 12 = _EV[11],
    MV 9 = _MV[8] (_EVNUM = MV·10000 + EV)."""
    m = decode_evnum(11)
    assert (m.ev, m.mv, m.ev_index, m.mv_index) == (11, 11, 10, 10)
    m = decode_evnum(90012)
    assert (m.ev, m.mv, m.ev_index, m.mv_index) == (12, 9, 11, 8)


def test_evnum_other_cases():
    assert decode_evnum(0) == Memories(None, None)
    assert decode_evnum(0).ev_index is None
    assert decode_evnum(10) == Memories(10, 10) and decode_evnum(10).ev_index == 9   # design.md §9.3
    assert decode_evnum(20) == Memories(20, 20)
    assert decode_evnum(90000) == Memories(None, 9)              # lower four digits 0: no EV
    assert decode_evnum(120005, sizes=None) == Memories(5, 12)
    assert decode_evnum(9999, sizes=None) == Memories(9999, 9999)
    assert decode_evnum(99999999, sizes=None) == Memories(9999, 9999)
    with pytest.raises(ValueError, match="_EVMVNUM"):
        decode_evnum(21)                                          # default array size 20
    with pytest.raises(ValueError, match="_EVMVNUM"):
        decode_evnum(210001)
    assert decode_evnum(21, sizes=(30, 30)) == Memories(21, 21)
    for bad in (-1, 100_000_000, 1.5, True):
        with pytest.raises(ValueError, match="evnum"):
            decode_evnum(bad)
    assert Tolerance(evnum=90012).memories == Memories(12, 9)


# --- §3.4 mean value, worked example 3.4-A -----------------------------------------------------

D_34A = [30, 50, 60, 20, 40, 50, 50, 30, 70, 70]                         # µm
# measuring-math 3.4-A (µm, 3 decimals); the manual prints 32.6/38.4/42.3 in rows 5–7 of k=3
MV_34A = {
    3: ([10.000, 23.333, 35.556, 30.370, 33.580, 39.053, 42.702, 10.000, 30.000, 43.333], {7, 10}),
    2: ([15.000, 32.500, 46.250, 10.000, 25.000, 37.500, 43.750, 15.000, 42.500, 35.000], {3, 7, 9}),
}


@pytest.mark.parametrize("k", [3, 2])
def test_3_4_A_every_row_through_the_decision_flow(k):
    """3.4-A with _TZL = 40 µm: every mean to the table's rounding (1e-3 µm), compensation and
    clearing exactly in the marked rows (k=3: 7, 10; k=2: 3, 7, 9)."""
    expected, compensated = MV_34A[k]
    tol = Tolerance(upper=0.2, lower=-0.2, zero_range=0.040, mean_range=0.1, dim_difference=0.5,
                    safe_area=1.0, k=k, evnum=1, keep_mean=True)
    memory = 0.0
    for row, (d_um, mv_um) in enumerate(zip(D_34A, expected, strict=True), start=1):
        decision = decide_tool_offset(d_um / 1000.0, tol, mv_old=memory)
        assert decision.deviation == pytest.approx(d_um / 1000.0, abs=1e-12)
        assert decision.mean_value * 1000.0 == pytest.approx(mv_um, abs=1e-3), f"row {row}"
        if row in compensated:
            assert decision.decision == "mean", f"row {row}"
            assert decision.corrected == decision.mean_value
            assert decision.memory_cleared and decision.mv_memory == 0.0
        else:
            assert decision.decision == "none", f"row {row}"
            assert decision.corrected == 0.0 and not decision.memory_cleared
            assert decision.mv_memory == decision.mean_value
        assert decision.alarm is None and decision.violation is None
        memory = decision.mv_memory


def test_3_4_A_formula_rows_and_the_manual_slip():
    """Mv_new = Mv_old − (Mv_old − D)/k, row by row (µm). Row 5, k=3: 30.370 + 9.630/3 = 33.580,
    not the manual's 32.6 (measuring-math §3.4 remark)."""
    assert mean_value(0.0, 30.0, 3) == pytest.approx(10.0, abs=1e-12)
    assert mean_value(10.0, 50.0, 3) == pytest.approx(23.333, abs=1e-3)
    assert mean_value(30.370, 40.0, 3) == pytest.approx(33.580, abs=1e-3)
    assert abs(mean_value(30.370, 40.0, 3) - 32.6) > 0.9
    assert mean_value(32.5, 60.0, 2) == pytest.approx(46.25, abs=1e-12)
    assert mean_value(0.0, 70.0, 2) == pytest.approx(35.0, abs=1e-12)


@given(d=st.floats(-10, 10), mv=st.floats(-10, 10))
def test_mean_with_k_1_is_the_deviation(d, mv):
    """k = 1 → the mean is just D_i (measuring-math §3.4)."""
    assert mean_value(mv, d, 1) == pytest.approx(d, abs=1e-12)


@given(d=st.floats(-10, 10), mv=st.floats(-10, 10), k=st.integers(1, 50))
def test_mean_lies_between_old_mean_and_deviation(d, mv, k):
    new = mean_value(mv, d, k)
    assert min(mv, d) - 1e-12 <= new <= max(mv, d) + 1e-12


# --- §3.5 workpiece flow, branch by branch ---------------------------------------------------

@pytest.mark.parametrize("actual, slug, alarm, corrected", [
    (1.5, "safe_area", alarms.SAFE_AREA, 0.0),                      # also > _TDIF, > TUL, > _TMV
    (-1.5, "safe_area", alarms.SAFE_AREA, 0.0),
    (0.07, "dimension_difference", alarms.DIMENSION_DIFFERENCE, 0.0),   # also > TUL, > _TMV
    (-0.07, "dimension_difference", alarms.DIMENSION_DIFFERENCE, 0.0),
    (0.04, "oversize", alarms.OVERSIZE, 0.04),                      # also > _TMV
    (-0.04, "undersize", alarms.UNDERSIZE, -0.04),
    (0.025, "full", None, 0.025),
    (-0.025, "full", None, -0.025),
    (0.015, "mean", None, 0.015),                                   # k = 1: Mv = D > _TZL
    (-0.015, "mean", None, -0.015),
    (0.005, "none", None, 0.0),
    (0.0, "none", None, 0.0),
])
def test_each_branch_in_order(actual, slug, alarm, corrected):
    """measuring-math §3.5 rows 1–5b; a D that matches several rows takes the first."""
    tol = Tolerance(setpoint=0.0, k=1, evnum=3, keep_mean=True, **BAND)
    d = decide_tool_offset(actual, tol, mv_old=0.0)
    assert d.decision == slug and d.alarm is alarm
    assert d.corrected == pytest.approx(corrected, abs=1e-15)
    assert d.corrects == (slug in ("oversize", "undersize", "full", "mean"))
    assert d.repeatable == (slug in ("safe_area", "dimension_difference"))
    assert d.abort == (slug == "safe_area")
    assert d.decision in DECISIONS
    if slug in ("safe_area", "dimension_difference"):
        assert d.mv_memory is None and not d.memory_cleared and d.mean_value is None
    elif slug in ("oversize", "undersize", "full"):
        assert d.mv_memory == 0.0 and d.memory_cleared and d.mean_value is None
    elif slug == "mean":
        assert d.mv_memory == 0.0 and d.memory_cleared and d.mean_value == pytest.approx(actual)
    else:
        assert d.mv_memory == pytest.approx(actual) and not d.memory_cleared


def test_order_wins_when_the_limits_are_out_of_order():
    """The flow is checked in its order even when the magnitudes are not in the manual's order."""
    # _TDIF below the tolerance: a D inside the band but above _TDIF is a dimension difference
    t = Tolerance(upper=0.03, lower=-0.03, zero_range=0.01, mean_range=0.02, dim_difference=0.02,
                  safe_area=1.0)
    assert decide_tool_offset(0.025, t).decision == "dimension_difference"
    # _TSA below _TDIF: safe area first
    t = Tolerance(upper=0.03, lower=-0.03, dim_difference=0.06, safe_area=0.05)
    assert decide_tool_offset(0.055, t).decision == "safe_area"
    # _TMV above the tolerance: oversize before full
    t = Tolerance(upper=0.03, lower=-0.03, mean_range=0.05, dim_difference=0.06, safe_area=1.0)
    assert decide_tool_offset(0.04, t).decision == "oversize"
    # _TZL above _TMV: a D inside _TMV goes to the mean, whose |Mv| ≤ _TZL is not corrected
    t = Tolerance(upper=0.03, lower=-0.03, zero_range=0.025, mean_range=0.02, dim_difference=0.06,
                  safe_area=1.0)
    assert decide_tool_offset(0.02, t).decision == "none"


def test_equal_to_a_limit_is_not_exceeding_it():
    """Strict ">" of the flowchart (measuring-math §17 Q10), equality in decimal notation pinned:
    132.03 − 132 is not above TUL 0.03, 133 − 132 is not above _TSA 1."""
    t = Tolerance(setpoint=132.0, **BAND)
    assert decide_tool_offset(132.03, t).decision == "full"          # not oversize
    assert decide_tool_offset(131.97, t).decision == "full"          # not undersize
    assert decide_tool_offset(132.02, t).decision == "mean"          # not full (|D| = _TMV), k=1
    assert decide_tool_offset(132.01, t).decision == "none"          # |Mv| = _TZL: no correction
    assert decide_tool_offset(132.06, t).decision == "oversize"      # not dimension difference
    assert decide_tool_offset(133.0, t).decision == "dimension_difference"   # not safe area
    assert decide_tool_offset(132.0300001, t).decision == "oversize"


def test_deviation_uses_the_symmetrised_setpoint():
    """D against SETVAL_eff (3.2-A band, 9.998 ± 0.002): 9.999 → D = +0.001, inside; 10.0005 lies
    above _SETVAL + _TUL = 10.000 → oversize; 9.9955 below _SETVAL + _TLL = 9.996 → undersize."""
    t = Tolerance(setpoint=10.0, upper=0.0, lower=-0.004, zero_range=0.0001, mean_range=0.001,
                  dim_difference=0.01, safe_area=0.1)
    d = decide_tool_offset(9.999, t)
    assert d.deviation == pytest.approx(0.001, abs=1e-12) and d.setpoint == pytest.approx(9.998)
    assert (d.upper, d.lower) == pytest.approx((0.002, -0.002))
    assert decide_tool_offset(10.0005, t).decision == "oversize"
    assert decide_tool_offset(9.9955, t).decision == "undersize"     # below 10 − 0.004


def test_empirical_value_sign_both_ways():
    """_CHBIT[5]=0: EV subtracted from the actual value (default), 1: added (manual §2.3.14).
    3.7-A part 1: 132.020 − 0.004 − 132 = 0.016; added: 0.024."""
    t = Tolerance(setpoint=132.0, k=3, evnum=10, keep_mean=True, **BAND)
    sub = decide_tool_offset(132.020, t, ev=0.004)
    add = decide_tool_offset(132.020, t, ev=0.004, ev_add=True)
    assert sub.deviation == pytest.approx(0.016, abs=1e-9)
    assert add.deviation == pytest.approx(0.024, abs=1e-9)
    assert sub.empirical_value == add.empirical_value == 0.004
    assert sub.actual == add.actual == 132.020
    # the EV is applied before the safe area check ("before all other measures", manual §1.10)
    t = Tolerance(setpoint=0.0, safe_area=0.5, dim_difference=0.4, evnum=1)
    assert decide_tool_offset(0.6, t, ev=0.2).decision != "safe_area"
    assert decide_tool_offset(0.4, t, ev=0.2, ev_add=True).decision == "safe_area"


def test_keep_mean_false_takes_the_previous_mean_as_zero():
    """_CHBIT[4]=0: the mean runs with Mv_old = 0 and nothing is stored (measuring-math §3.3 [I],
    §17 Q9). 3.7-A part 1 without the memory: Mv = 0.016/3 = 0.005333 ≤ _TZL → none."""
    t = Tolerance(setpoint=132.0, k=3, evnum=10, keep_mean=False, **BAND)
    d = decide_tool_offset(132.020, t, ev=0.004, mv_old=0.006)
    assert d.mv_old == 0.0
    assert d.mean_value == pytest.approx(0.016 / 3, abs=1e-9)
    assert d.decision == "none" and d.mv_memory is None and not d.memory_cleared
    # a mean above _TZL is corrected, the (unused) memory is not written
    t1 = Tolerance(setpoint=0.0, k=1, evnum=10, keep_mean=False, **BAND)
    d = decide_tool_offset(0.018, t1, mv_old=0.5)
    assert d.decision == "mean" and d.corrected == pytest.approx(0.018)
    assert d.mv_memory is None and not d.memory_cleared
    d = decide_tool_offset(0.025, t1)
    assert d.decision == "full" and d.mv_memory is None and not d.memory_cleared


def test_no_memory_without_evnum():
    """_EVNUM = 0: no EV, no MV memory (§3.3); giving a memory value is a caller error."""
    t = Tolerance(setpoint=0.0, keep_mean=True, **BAND)
    d = decide_tool_offset(0.005, t)
    assert d.decision == "none" and d.mv_memory is None
    with pytest.raises(ValueError, match="EV memory"):
        decide_tool_offset(0.005, t, ev=0.001)
    with pytest.raises(ValueError, match="MV memory"):
        decide_tool_offset(0.005, t, mv_old=0.001)
    only_mv = Tolerance(setpoint=0.0, keep_mean=True, evnum=90000, **BAND)   # MV 9, no EV
    with pytest.raises(ValueError, match="EV memory"):
        decide_tool_offset(0.005, only_mv, ev=0.001)
    assert decide_tool_offset(0.005, only_mv, mv_old=0.001).mean_value == pytest.approx(0.005)


def test_measurements_at_the_same_point_are_averaged():
    """_NMSP (manual §2.3.15, measuring-math §1.4): D = (S1 + … + Sn)/n."""
    assert average([132.019, 132.021]) == pytest.approx(132.020, abs=1e-12)
    assert average(3.5) == 3.5
    t = Tolerance(setpoint=132.0, k=3, evnum=10, keep_mean=True, **BAND)
    d = decide_tool_offset([132.018, 132.020, 132.022], t, ev=0.004, mv_old=0.006)
    assert d.actual == pytest.approx(132.020, abs=1e-12)
    assert d.deviation == pytest.approx(0.016, abs=1e-9)
    with pytest.raises(ValueError, match="at least one"):
        average([])


def test_m0_on_tolerance_alarms():
    """_CBIT[2]=1: M0 on "oversize", "undersize", "permissible dimensional difference exceeded"."""
    t = Tolerance(setpoint=0.0, **BAND)
    assert decide_tool_offset(0.04, t, m0_on_alarm=True).stop
    assert decide_tool_offset(-0.04, t, m0_on_alarm=True).stop
    assert decide_tool_offset(0.07, t, m0_on_alarm=True).stop
    assert not decide_tool_offset(0.025, t, m0_on_alarm=True).stop
    assert not decide_tool_offset(0.04, t).stop


@settings(max_examples=200)
@given(d=st.floats(-50, 50), mv=st.floats(-50, 50), k=st.integers(1, 20), keep=st.booleans())
def test_huge_tolerances_leave_only_the_mean(d, mv, k, keep):
    """With every limit far beyond the deviations, the flow always reaches row 5: mean or none."""
    t = Tolerance(upper=1e6, lower=-1e6, zero_range=1e-3, mean_range=1e5, dim_difference=1e7,
                  safe_area=1e8, k=k, evnum=1, keep_mean=keep)
    decision = decide_tool_offset(d, t, mv_old=mv)
    assert decision.decision in ("mean", "none")
    assert decision.alarm is None and decision.mean_value is not None


@given(d=st.floats(-5, 5), tsa=st.floats(0.01, 2))
def test_beyond_the_safe_area_is_always_safe_area(d, tsa):
    t = Tolerance(upper=0.01, lower=-0.01, safe_area=tsa)
    decision = decide_tool_offset(d, t)
    if abs(d) > tsa + 1e-9:
        assert decision.decision == "safe_area" and decision.corrected == 0.0
    else:
        assert decision.decision != "safe_area"


# --- §3.6 repeat rule -------------------------------------------------------------------------

def test_repeat_without_cbit0():
    """_CBIT[0]=0: no repetition; the flow's alarm at once (61303 aborts, 62306 continues)."""
    a = repeat_measurement("safe_area", 0)
    assert (a.repeat, a.alarm, a.abort, a.final) == (False, alarms.SAFE_AREA, True, True)
    a = repeat_measurement("dimension_difference", 0)
    assert (a.repeat, a.alarm, a.abort, a.final) == (False, alarms.DIMENSION_DIFFERENCE, False, True)
    a = repeat_measurement(None, 0, repeat=True)
    assert (a.repeat, a.alarm, a.final) == (False, None, True)


@pytest.mark.parametrize("violation, warning", [("safe_area", alarms.SAFE_AREA_WARNING),
                                                ("dimension_difference", alarms.DIMENSION_DIFFERENCE)])
def test_repeat_at_most_four_times(violation, warning):
    """_CBIT[0]=1: repeated at most 4 times; _CBIT[1]=1: alarm (62303/62306) and M0 before each
    repetition; a 4th repetition that still violates ends with 61303 / 61306 (§3.6 [I])."""
    measurements, done, action = 1, 0, None
    while True:
        action = repeat_measurement(violation, done, repeat=True, alarm_and_m0=True)
        if not action.repeat:
            break
        assert action.alarm is warning and action.m0 and not action.abort
        done = action.repetitions
        measurements += 1
    assert measurements == 5 and done == 4
    final = alarms.SAFE_AREA if violation == "safe_area" else alarms.DIMENSION_DIFFERENCE_ABORT
    assert action.alarm is final and action.abort and action.final and not action.m0


def test_repeat_silently_and_the_final_dimension_alarm():
    for done in range(4):
        a = repeat_measurement("dimension_difference", done, repeat=True)
        assert a.repeat and a.alarm is None and not a.m0 and a.repetitions == done + 1
    # CYCLE994 is not in 61306's list of cycles: the last violation stays the warning 62306
    a = repeat_measurement("dimension_difference", 4, repeat=True, abort_after_repeats=False)
    assert a.alarm is alarms.DIMENSION_DIFFERENCE and not a.abort
    # a repetition that no longer violates goes on
    assert repeat_measurement(None, 2, repeat=True).alarm is None
    with pytest.raises(ValueError, match="violation"):
        repeat_measurement("oversize", 0)
    with pytest.raises(ValueError, match="repetitions_done"):
        repeat_measurement("safe_area", 5, repeat=True)


def test_decision_feeds_the_repeat_rule():
    t = Tolerance(setpoint=0.0, **BAND)
    d = decide_tool_offset(1.5, t)
    assert repeat_measurement(d.violation, 0, repeat=True).repeat
    assert not repeat_measurement(decide_tool_offset(0.04, t).violation, 0, repeat=True).repeat


# --- §3.5 tool measuring, worked example 14.4-A -----------------------------------------------

TOOL_14_4 = Tolerance(zero_range=0.04, dim_difference=1.6, safe_area=2.0)


def test_14_4_A_first_measurement():
    """14.4-A, _CHBIT[3]=0: L 70.300 against 70 → Δ 0.300 → L1 geometry 70.300; R 17.900
    against 18 → Δ −0.100 → R geometry 17.900 (wear 0)."""
    d = decide_tool_measurement(70.300, 70.0, 0.0, TOOL_14_4)
    assert d.delta == pytest.approx(0.300, abs=1e-9)
    assert (d.decision, d.write, d.alarm) == ("full", True, None)
    assert (d.geometry, d.wear) == (pytest.approx(70.300, abs=1e-12), 0.0)
    d = decide_tool_measurement(17.900, 18.0, 0.0, TOOL_14_4)
    assert d.delta == pytest.approx(-0.100, abs=1e-9)
    assert (d.geometry, d.wear) == (pytest.approx(17.900, abs=1e-12), 0.0)


def test_14_4_A_remeasurement():
    """14.4-A, _CHBIT[3]=1, R_geo 18.000, wear 0.024: R 17.990 → Δ −0.034, |Δ| < _TZL →
    unchanged; R 17.950 → Δ −0.074 → wear −0.050."""
    d = decide_tool_measurement(17.990, 18.0, 0.024, TOOL_14_4, remeasure=True)
    assert d.delta == pytest.approx(-0.034, abs=1e-9)
    assert (d.decision, d.write, d.geometry, d.wear) == ("none", False, 18.0, 0.024)
    d = decide_tool_measurement(17.950, 18.0, 0.024, TOOL_14_4, remeasure=True)
    assert d.delta == pytest.approx(-0.074, abs=1e-9)
    assert (d.decision, d.write, d.geometry) == ("full", True, 18.0)
    assert d.wear == pytest.approx(-0.050, abs=1e-9)


def test_tool_measuring_limits():
    """_TSA → 61303, |Δ| ≥ _TDIF → 62306 (the examples' "≥", measuring-math §17 Q10), |Δ| < _TZL →
    unchanged, |Δ| = _TZL → written; no mean value."""
    d = decide_tool_measurement(72.5, 70.0, 0.0, TOOL_14_4)
    assert (d.decision, d.alarm, d.write, d.abort, d.violation) == ("safe_area", alarms.SAFE_AREA, False, True,
                                                                   "safe_area")
    d = decide_tool_measurement(71.6, 70.0, 0.0, TOOL_14_4)       # Δ = _TDIF exactly
    assert (d.decision, d.alarm, d.write) == ("dimension_difference", alarms.DIMENSION_DIFFERENCE, False)
    assert d.violation == "dimension_difference" and not d.abort
    assert decide_tool_measurement(71.59, 70.0, 0.0, TOOL_14_4).write
    d = decide_tool_measurement(70.04, 70.0, 0.0, TOOL_14_4)       # Δ = _TZL exactly: not "<"
    assert d.write and d.geometry == pytest.approx(70.04)
    assert not decide_tool_measurement(70.0399, 70.0, 0.0, TOOL_14_4).write


def test_tool_measuring_empirical_value():
    """value_new = value_meas − EV (_CHBIT[5]=0), + EV with _CHBIT[5]=1 (measuring-math §14.4)."""
    t = Tolerance(zero_range=0.04, dim_difference=1.6, safe_area=2.0, evnum=5)
    d = decide_tool_measurement(70.35, 70.0, 0.0, t, ev=0.05)
    assert d.value == pytest.approx(70.30, abs=1e-12) and d.measured == 70.35
    assert d.geometry == pytest.approx(70.30, abs=1e-12)
    d = decide_tool_measurement(70.25, 70.0, 0.0, t, ev=0.05, ev_add=True)
    assert d.value == pytest.approx(70.30, abs=1e-12)
    with pytest.raises(ValueError, match="EV memory"):
        decide_tool_measurement(70.3, 70.0, 0.0, TOOL_14_4, ev=0.05)


# --- §3.5 calibration, worked example 14.5-A ---------------------------------------------------

CAL_14_5 = Tolerance(zero_range=0.005, safe_area=5.0)


def test_14_5_A_tool_probe_calibration():
    """14.5-A: rough _TP[0,0]=50, _TP[0,4]=80, _TZL 0.005, _TSA 5: 50.012 stored (Δ 0.012); a
    second run 50.004, Δ −0.008 → stored; −Z 80.006 stored."""
    d = decide_calibration({"X-": 50.012}, {"X-": 50.0, "Z-": 80.0}, CAL_14_5)
    assert d.delta["X-"] == pytest.approx(0.012, abs=1e-12)
    assert d.stored == ("X-",) and d.kept == () and d.alarm is None and d.decision == "full"
    assert d.values == {"X-": 50.012, "Z-": 80.0}
    d = decide_calibration({"X-": 50.004}, d.values, CAL_14_5)
    assert d.delta["X-"] == pytest.approx(-0.008, abs=1e-12) and d.values["X-"] == 50.004
    d = decide_calibration({"Z-": 80.006}, d.values, CAL_14_5)
    assert d.stored == ("Z-",) and d.values == {"X-": 50.004, "Z-": 80.006}


def test_calibration_within_zero_range_keeps_the_old_value():
    d = decide_calibration({"X-": 50.007, "X+": 30.02}, {"X-": 50.004, "X+": 30.0}, CAL_14_5)
    assert d.kept == ("X-",) and d.stored == ("X+",)
    assert d.values == {"X-": 50.004, "X+": 30.02}
    d = decide_calibration({"X-": 50.0045}, {"X-": 50.004}, CAL_14_5)
    assert d.decision == "none" and d.values == {"X-": 50.004}


def test_calibration_any_safe_area_violation_stores_nothing():
    """measuring-math §3.5 [I]: the test is per stored value; one violation stores nothing."""
    old = {"X-": 50.0, "Y-": 50.0}
    d = decide_calibration({"X-": 50.01, "Y-": 60.0}, old, CAL_14_5)
    assert d.alarm is alarms.SAFE_AREA and d.violation == "safe_area" and d.decision == "safe_area"
    assert d.values == old and d.stored == ()
    assert d.delta["Y-"] == pytest.approx(10.0)


def test_first_calibration_of_a_zeroed_record():
    """manual §5.3: the record _WP[] is preset to 0 for the first calibration, so _TSA must exceed
    the ball radius (Δ = t − 0 ≈ ±r), else 61303."""
    zeroed = {"X-": 0.0, "X+": 0.0}
    new = {"X-": 2.99, "X+": -2.994}
    d = decide_calibration(new, zeroed, Tolerance(zero_range=0.001, safe_area=2.0), ball_radius=3.0)
    assert d.alarm is alarms.SAFE_AREA and d.values == zeroed
    assert d.warnings and "ball radius" in d.warnings[0]
    d = decide_calibration(new, zeroed, Tolerance(zero_range=0.001, safe_area=4.0), ball_radius=3.0)
    assert d.alarm is None and d.values == new and d.warnings == ()
    d = decide_calibration(new, None, Tolerance(zero_range=0.001, safe_area=4.0))   # no record yet = zeroed
    assert d.values == new and d.delta == new


def test_incremental_calibration_ignores_the_limits():
    d = decide_calibration({"X-": 60.0, "X+": 30.0001}, {"X-": 50.0, "X+": 30.0}, CAL_14_5, incremental=True)
    assert d.alarm is None and d.values == {"X-": 60.0, "X+": 30.0001} and d.kept == ()


# --- §3.5 ZO correction --------------------------------------------------------------------

def test_zero_offset_only_safe_area():
    """Workpiece measuring with ZO correction: only _TSA (61303); else 100 %, no _TZL, no mean.
    turning 5-A: s = 60.150 against _SETVAL 60, _TSA 1 → d = +0.150 into G54 Z."""
    d = decide_zero_offset(60.150, 60.0, 1.0)
    assert d.decision == "full" and d.alarm is None
    assert d.deviation == pytest.approx(0.150, abs=1e-12) and d.corrected == d.deviation
    tiny = decide_zero_offset(60.00001, 60.0, 1.0)                 # below any _TZL: still corrected
    assert tiny.decision == "full" and tiny.corrected == pytest.approx(1e-5, abs=1e-12)
    d = decide_zero_offset(61.2, 60.0, 1.0)
    assert (d.decision, d.alarm, d.corrected, d.abort) == ("safe_area", alarms.SAFE_AREA, 0.0, True)
    assert decide_zero_offset(61.0, 60.0, 1.0).decision == "full"  # equal to _TSA: not exceeded


def test_zero_offset_per_axis_and_ev():
    """measuring-math 8.5-A centre (180.040, 129.970) against (180, 130) → (0.040, −0.030)."""
    d = decide_zero_offset((180.040, 129.970), (180.0, 130.0), 2.0)
    assert d.corrected == pytest.approx((0.040, -0.030), abs=1e-9) and d.decision == "full"
    d = decide_zero_offset((180.040, 132.5), (180.0, 130.0), 2.0)
    assert d.decision == "safe_area" and d.corrected == (0.0, 0.0)
    # EV applies to 1-point ZO measuring "with correct sign" (manual §5.5.3, turning §0.11)
    assert decide_zero_offset(100.025, 100.0, 1.0, ev=0.005).deviation == pytest.approx(0.020, abs=1e-12)
    assert decide_zero_offset(100.025, 100.0, 1.0, ev=0.005, ev_add=True).deviation == pytest.approx(0.030)
    with pytest.raises(ValueError, match="safe_area"):
        decide_zero_offset(1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="length"):
        decide_zero_offset((1.0, 2.0), (0.0,), 1.0)
