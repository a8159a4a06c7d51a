"""G100 / G101 / G102 (measuring-math §16, seed 003): worked example 16-A end to end as an MDA
program on the simulator, its variants and error cases; the offset bookkeeping on its own."""

from __future__ import annotations

import pytest
from nc_runtimes import FakeRuntime, plane_switch
from nc_scenes import BACK_FACE, BALL_R, G54, LEFT_FACE, PRE, PROBE_LENGTH, scene

from app.nc.interpreter import Interpreter
from app.nc.offsets import MeasuringOffsets, NoMeasuredValue, NothingIncluded
from engine import alarms

# --- the truth of the scene, by hand -------------------------------------------------------------------
# G100 X50 probes +X against the block's left face: the ball centre switches at
# LEFT_FACE - r + pre-travel(X+) in MCS; minus G54 in the WCS. G100 Y30 probes -Y against the back face.
SWITCH_X = LEFT_FACE - BALL_R + PRE["X+"] - G54[0]
SWITCH_Y = BACK_FACE + BALL_R - PRE["Y-"] - G54[1]
DX, DY = 0.12, -0.05           # the manual's Δx, Δy (16a); the scene is built to switch there
Z20_AXIS = 20.0 + G54[2] + PROBE_LENGTH      # MCS Z of the spindle with the ball centre at WCS Z20

MDA_16A = """\
N10 G54 G17 G90 G0 Z20
N20 X45 Y0
N30 Z-10
N40 F100 G100 X50          ; measuring move towards X50 and on through _FA
N50 G0 X45
N60 Z20
N70 X100 Y35
N80 Z-10
N90 G100 Y30
N100 G0 Y35
N110 Z20
N120 G101 X1 Y7            ; include: X with factor 1, Y with factor 7
N130 G1 X10 Y10
N140 M0
N150 G102 X1               ; extract the offset of X only
N160 G1 X10 Y10
N170 M0
N180 G102                  ; extract all
N190 G1 X10 Y10
N200 M30
"""


@pytest.fixture
def sim():
    machine, runtime = scene()
    return machine, runtime, Interpreter(runtime)


def axes(machine):
    mcs = machine.status().mcs
    return mcs["X"], mcs["Y"], mcs["Z"]


def test_worked_example_16a_as_an_mda_program(sim):
    machine, runtime, interp = sim
    interp.load(MDA_16A)

    result = interp.run()
    assert (result.state, result.reason, result.block.number) == ("stopped", "M0", 140), result.alarm
    offsets = interp.measuring_offsets
    assert offsets.measured["X"] == pytest.approx(DX, abs=1e-9)          # Δx = +0.12
    assert offsets.measured["Y"] == pytest.approx(DY, abs=1e-9)          # Δy = -0.05
    assert offsets.included == pytest.approx({"X": DX, "Y": 7 * DY}, abs=1e-9)   # +0.12, -0.35
    # G1 X10 Y10 goes to the absolute position (10.12, 9.65)
    assert axes(machine) == pytest.approx((G54[0] + 10.0 + DX, G54[1] + 10.0 + 7 * DY, Z20_AXIS), abs=1e-9)
    assert machine.status().wcs["X"] == pytest.approx(10.12, abs=1e-9)
    assert machine.status().wcs["Y"] == pytest.approx(9.65, abs=1e-9)

    result = interp.run()                                               # NC Start after M0
    assert (result.state, result.block.number) == ("stopped", 170)
    assert interp.measuring_offsets.included == pytest.approx({"Y": 7 * DY}, abs=1e-9)
    assert axes(machine) == pytest.approx((G54[0] + 10.0, G54[1] + 10.0 + 7 * DY, Z20_AXIS), abs=1e-9)

    result = interp.run()
    assert (result.state, result.reason) == ("done", "M30")
    assert dict(interp.measuring_offsets.included) == {}
    assert axes(machine) == pytest.approx((G54[0] + 10.0, G54[1] + 10.0, Z20_AXIS), abs=1e-9)
    # the measured values stay for a later G101
    assert interp.measuring_offsets.measured["X"] == pytest.approx(DX, abs=1e-9)
    # the G100 moves also latched like MEAS: the last one measured Y
    assert interp.variables.get("$AA_MW", ("Y",)) == pytest.approx(SWITCH_Y, abs=1e-9)
    assert interp.variables.get("$AC_MEA", (1,)) is True


def measured_16a(sim):
    machine, runtime, interp = sim
    interp.load(MDA_16A.split("N120")[0])
    assert interp.run().state == "done"
    return machine, interp


def alarm_of(interp, text):
    interp.load(text)
    result = interp.run()
    assert result.state == "alarm", result
    return result.alarm


def test_g102_for_an_axis_without_included_offset_is_an_error(sim):
    machine, interp = measured_16a(sim)
    interp.load("G101 X1 Y7")
    interp.run()
    err = alarm_of(interp, "N10 G1 X10 Y10\nN20 G102 Z1")
    assert err.alarm is alarms.NO_MEASURING_OFFSET and (err.line, err.column) == (2, 10)
    assert "no measuring offset is included for axis Z" in str(err) and str(err).endswith("line 2, column 10")
    assert interp.measuring_offsets.included == pytest.approx({"X": DX, "Y": 7 * DY}, abs=1e-9)
    # a listed axis with nothing included: nothing at all is extracted
    err = alarm_of(interp, "G102 X1 Z1")
    assert err.alarm is alarms.NO_MEASURING_OFFSET and err.column == 9
    assert set(interp.measuring_offsets.included) == {"X", "Y"}


def test_g101_without_a_measurement_of_the_axis_is_an_error(sim):
    machine, interp = measured_16a(sim)
    before = axes(machine)
    err = alarm_of(interp, "N10 G101 Z1")
    assert err.alarm is alarms.NO_MEASURED_VALUE and (err.line, err.column) == (1, 10)
    assert "no measured value for axis Z" in err.message
    # all or nothing: X is not included either
    err = alarm_of(interp, "G101 X1 Z1")
    assert err.alarm is alarms.NO_MEASURED_VALUE and err.column == 9
    assert dict(interp.measuring_offsets.included) == {}
    assert axes(machine) == before


def test_a_second_g101_replaces_and_a_later_g100_does_not_change_what_is_included(sim):
    machine, interp = measured_16a(sim)
    interp.load("G101 X1\nG101 X2\nG1 X10 Y10")
    assert interp.run().state == "done"
    assert interp.measuring_offsets.included["X"] == pytest.approx(2 * DX, abs=1e-9)   # 0.24, not 0.36
    # measure X again against another target: Δ changes, the included offset does not
    interp.load("G0 Y0\nZ-10\nX45\nG100 X49\nG0 X45\nZ20\nG1 X10 Y10")
    assert interp.run().state == "done"
    assert interp.measuring_offsets.measured["X"] == pytest.approx(SWITCH_X - 49.0, abs=1e-9)
    assert interp.measuring_offsets.included["X"] == pytest.approx(2 * DX, abs=1e-9)
    assert axes(machine)[0] == pytest.approx(G54[0] + 10.0 + 2 * DX, abs=1e-9)
    interp.load("G102 X0\nG1 X10")                      # the number after the axis is meaningless
    assert interp.run().state == "done"
    assert axes(machine)[0] == pytest.approx(G54[0] + 10.0, abs=1e-9)
    interp.load("G101 X1\nG1 X10")                      # the newest Δ is included now
    interp.run()
    assert axes(machine)[0] == pytest.approx(G54[0] + 10.0 + SWITCH_X - 49.0, abs=1e-9)


def test_g102_without_axes_and_nothing_included_is_a_noop(sim):
    machine, runtime, interp = sim
    interp.load("G102\nG102")
    assert interp.run().state == "done"


def test_g100_that_does_not_switch_is_an_alarm_at_its_block(sim):
    machine, runtime, interp = sim
    err = alarm_of(interp, "N10 G54 G0 Z20\nN20 X45 Y0\nN30 Z-10\nN40 F100 G100 X46")
    # from X45 towards X46 and on through _FA = 2 mm: ends at X48, the face is at 50.12
    assert err.alarm is alarms.PROBE_NOT_SWITCHED and (err.line, err.column) == (4, 15)
    assert "between X45 and X48" in err.message
    assert machine.status().wcs["X"] == pytest.approx(48.0, abs=1e-9)
    assert "X" not in interp.measuring_offsets.measured


def test_g100_measuring_path_is_fa(sim):
    machine, runtime, interp = sim
    interp.load("_FA=5\nG54 G0 Z20\nX40 Y0\nZ-10\nF100 G100 X44")    # 44 + 5 = 49: short of 50.12
    assert interp.run().alarm.alarm is alarms.PROBE_NOT_SWITCHED
    assert machine.status().wcs["X"] == pytest.approx(49.0, abs=1e-9)
    interp.reset()
    interp.load("G54 G0 X40 Y0\n_FA=7 F100 G100 X44")               # now on through to 51
    assert interp.run().state == "done"
    assert interp.measuring_offsets.measured["X"] == pytest.approx(SWITCH_X - 44.0, abs=1e-9)


@pytest.mark.parametrize("text, definition, line, column", [
    ("_FA=0\nG54 G0 Z20\nX45 Y0\nZ-10\nF100 G100 X50", alarms.MEASURING_PATH, 5, 11),
    ("G54 G0 Z20\nX45 Y0\nZ-10\nF100 G100 X45", alarms.NO_MEASURING_PATH, 4, 11),
    ("G54 G0 Z20\nX45 Y0\nZ-10\nG100 X50", alarms.NC_FEED_MISSING, 4, 6),
])
def test_g100_error_cases(sim, text, definition, line, column):
    machine, runtime, interp = sim
    interp.load(text)
    result = interp.run()
    assert result.alarm.alarm is definition and (result.alarm.line, result.alarm.column) == (line, column)
    # nothing moved in the failing block: the probe is where the block before left it (X45 Y0 Z-10)
    assert axes(machine) == pytest.approx((G54[0] + 45.0, G54[1], G54[2] - 10.0 + PROBE_LENGTH), abs=1e-9)


def test_g100_incremental_target():
    rt = FakeRuntime(position={"X": 0.0, "Y": 0.0, "Z": 0.0}, switch=plane_switch("X", 13.0))
    interp = Interpreter(rt)
    interp.load("G500 G0 X10\nG91 F100 G100 X2")        # target 12, through to 14, switches at 13
    assert interp.run().state == "done"
    assert interp.measuring_offsets.measured["X"] == pytest.approx(1.0)
    assert rt.log[-1] == ("measure", {"X": 14.0, "Y": 0.0, "Z": 0.0}, 100.0, True)


def test_g100_in_inch_and_g101_in_a_rotated_frame():
    from engine.frames import Frame
    rt = FakeRuntime(offsets={"G54": Frame(coarse=[10.0, 0, 0], rot=[0, 0, 90])},
                     position={"X": 10.0, "Y": 0.0, "Z": 0.0}, switch=plane_switch("Y", 25.6))
    interp = Interpreter(rt)
    # WCS X is MCS +Y here; G70: target X1 inch = 25.4 mm; the probe switches at WCS X 25.6
    interp.load("G54 G70 F100 G100 X1\nG71\nG101 X1\nG0 X10 Y0")
    assert interp.run().state == "done"
    assert interp.measuring_offsets.measured["X"] == pytest.approx(0.2)
    assert rt.pos["X"] == pytest.approx(10.0) and rt.pos["Y"] == pytest.approx(10.2)


def test_g53_and_measuring_offsets():
    rt = FakeRuntime(position={"X": 0.0, "Y": 0.0, "Z": 0.0}, switch=plane_switch("X", 5.5))
    interp = Interpreter(rt)
    interp.load("G500 F100 G100 X5\nG101 X1\nG0 X0\nG53 X0")
    assert interp.run().state == "done"
    assert [e[1]["X"] for e in rt.moves[1:]] == [pytest.approx(0.5), pytest.approx(0.0)]   # G53: suppressed too


# --- the bookkeeping alone -----------------------------------------------------------------------------

def test_offsets_value_semantics():
    m = MeasuringOffsets().record("X", 0.12).record("Y", -0.05)
    inc = m.include({"X": 1, "Y": 7})
    assert dict(inc.included) == pytest.approx({"X": 0.12, "Y": -0.35})
    assert inc.offset("X") == pytest.approx(0.12) and inc.offset("Z") == 0.0
    assert dict(inc.extract(["X"]).included) == pytest.approx({"Y": -0.35})
    assert dict(inc.extract().included) == {}
    assert dict(inc.record("X", 5.0).included) == dict(inc.included)
    with pytest.raises(NoMeasuredValue):
        m.include({"Z": 1})
    with pytest.raises(NothingIncluded):
        inc.extract(["Z"])
    assert dict(m.included) == {}                        # immutable
    assert MeasuringOffsets().extract() == MeasuringOffsets()
