"""MEAS / MEAW with $AA_MM / $AA_MW / $AC_MEA against the analytic latch on the simulator
(measuring-math §1: flying measurement; MEAS deletes the distance to go, MEAW goes on)."""

from __future__ import annotations

import numpy as np
import pytest
from nc_runtimes import FakeRuntime, plane_switch
from nc_scenes import BALL_R, G54, LEFT_FACE, PRE, PROBE_LENGTH, braking, scene

from app.nc.interpreter import Interpreter
from engine import alarms

LATENCY = 0.004
FEED = 300.0
E_LAT = FEED / 60.0 * LATENCY                        # 0.02 mm further along the move at the latch
SWITCH_AXIS_X = LEFT_FACE - BALL_R + PRE["X+"]       # MCS X of the spindle (no eccentricity) at the switch
LATCH_AXIS_X = SWITCH_AXIS_X + E_LAT
Y_AXIS = G54[1] + 0.0
Z_AXIS = G54[2] - 10.0 + PROBE_LENGTH                # ball centre at WCS Z-10

APPROACH = "N10 G54 G17 G90 G0 Z20\nN20 X40 Y0\nN30 Z-10\n"


@pytest.fixture
def sim():
    machine, runtime = scene(latency_s=LATENCY)
    return machine, Interpreter(runtime)


def test_meas_latches_on_the_fly_and_deletes_the_distance_to_go(sim):
    machine, interp = sim
    interp.load(APPROACH + f"N40 MEAS=1 G1 X60 F{FEED:g}\n"
                "N50 R1=$AA_MM[X] R2=$AA_MW[X] R3=$AC_MEA[1] R4=$AA_MM[Y] R5=$AA_MM[Z] R6=$AA_MW[Z] R7=$AA_MW[Y]")
    result = interp.run()
    assert result.state == "done", result.alarm
    r = [interp.variables.get("R", (i,)) for i in range(8)]
    assert r[1] == pytest.approx(LATCH_AXIS_X, abs=1e-9)                    # MCS
    assert r[2] == pytest.approx(LATCH_AXIS_X - G54[0], abs=1e-9)           # WCS, the ball centre
    assert r[3] == 1.0
    assert r[4] == pytest.approx(Y_AXIS, abs=1e-9) and r[5] == pytest.approx(Z_AXIS, abs=1e-9)
    assert r[6] == pytest.approx(-10.0, abs=1e-9) and r[7] == pytest.approx(0.0, abs=1e-9)
    # the axes braked behind the switch; the rest of the path to X60 was not travelled
    x_end = machine.status().mcs["X"]
    assert x_end == pytest.approx(SWITCH_AXIS_X + braking(FEED, LATENCY), abs=1e-9)
    assert x_end < G54[0] + 60.0 - 5.0


def test_meaw_goes_on_to_the_end_point(sim):
    machine, interp = sim
    # end point 0.2 mm behind the switching point: within the braking distance the simulator models
    end_wcs = SWITCH_AXIS_X - G54[0] + 0.2
    assert 0.2 < braking(FEED, LATENCY)
    interp.load(APPROACH + f"N40 MEAW=1 G1 X={end_wcs!r} F{FEED:g}\nN50 R1=$AA_MM[X] R2=$AC_MEA[1]")
    assert interp.run().state == "done"
    assert interp.variables.get("R", (1,)) == pytest.approx(LATCH_AXIS_X, abs=1e-9)
    assert interp.variables.get("R", (2,)) == 1.0
    assert machine.status().mcs["X"] == pytest.approx(G54[0] + end_wcs, abs=1e-9)


def test_meaw_into_the_part_beyond_the_stylus_is_a_collision(sim):
    machine, interp = sim
    interp.load(APPROACH + f"N40 MEAW=1 G1 X60 F{FEED:g}")
    result = interp.run()
    assert result.state == "alarm" and result.alarm.alarm is alarms.PROBE_COLLISION
    assert (result.alarm.line, result.alarm.column) == (4, 15)
    assert interp.variables.get("$AC_MEA", (1,)) is False     # the block did not complete: nothing stored


def test_meas_without_switching_is_no_alarm_the_program_asks_ac_mea(sim):
    machine, interp = sim
    interp.load(APPROACH + "N35 MEAS=1 G1 X45 F300\n"          # first a switching move, then none
                "N40 G0 X40\nN45 MEAS=1 G1 X60\nN50 R1=$AA_MM[X]\nN55 G0 X40\nN60 MEAS=2 G1 X45\n"
                "N70 IF $AC_MEA[2]==0 GOTOF NOSWITCH\nN80 R2=1\nN90 NOSWITCH: R3=$AA_MM[X] R4=$AC_MEA[1]")
    result = interp.run()
    assert result.state == "done"
    v = interp.variables
    assert v.get("R", (2,)) == 0.0                              # jumped over N80
    assert v.get("R", (3,)) == pytest.approx(LATCH_AXIS_X, abs=1e-9)   # $AA_MM keeps the last latch
    assert v.get("$AC_MEA", (2,)) is False and v.get("R", (4,)) == 1.0
    assert machine.status().wcs["X"] == pytest.approx(45.0, abs=1e-9)


def test_manual_function_check_program(sim):
    """The manual's probe function check (§8.3), with the probe as T9."""
    machine, interp = sim
    program = """\
%_N_PRUEF_MESSTASTER_MPF
;$PATH=/_N_MPF_DIR
N05 DEF INT MTSIGNAL ; flag for the switching state
N10 DEF INT ME_NR=1 ; measuring input
N20 G54
N30 G17 T9 D1 ; tool offset of the probe
N35 G0 Z20
N36 X40 Y0
N37 Z-10
N40 G0 G90 X40 F150 ; start position and measuring feed
N50 MEAS=ME_NR G1 X100 ; measure on measuring input 1 in X
N60 STOPRE
N70 MTSIGNAL=$AC_MEA[ME_NR] ; read the switching signal
N80 IF MTSIGNAL == 0 GOTOF _FEHL1
N90 R1=$AA_MW[X] ; measured value in workpiece coordinates
N95 M0 ; show R1
N100 M2
N110 _FEHL1:MSG ("测量头未接通")
N120 M0
N130 M2
"""
    interp.load(program, name="PRUEF_MESSTASTER")
    result = interp.run()
    assert (result.state, result.reason, result.block.number) == ("stopped", "M0", 95)
    assert interp.variables.get("R", (1,)) == pytest.approx(SWITCH_AXIS_X + 150 / 60 * LATENCY - G54[0], abs=1e-9)
    assert interp.message is None
    assert interp.run().reason == "M2"
    # without a surface in reach: the program shows the message and stops
    interp.load(program.replace("X100", "X45"))
    result = interp.run()
    assert (result.state, result.block.number) == ("stopped", 120)
    assert interp.message == "测量头未接通"


def test_manual_repeatability_program_with_noise():
    """The manual's repeatability test (§10.4): 10 measurements at one position into an array."""
    sigma = 0.0005
    machine, runtime = scene(latency_s=LATENCY, noise_sigma=sigma, seed=11)
    interp = Interpreter(runtime)
    interp.load("""\
%_N_PRUEF_GENAU_MPF
N05 DEF INT SIGNAL, KK
N10 DEF REAL MESSWERT_IN_X[10]
N15 G54 G17 T9 D1
N16 G0 Z20
N17 X40 Y0
N18 Z-10
N20 ANF: G0 X40 F150
N25 MEAS=+1 G1 X55
N30 STOPRE
N35 SIGNAL= $AC_MEA[1]
N37 IF SIGNAL == 0 GOTOF _FEHL1
N40 MESSWERT_IN_X[kk]=$AA_MW[X]
N50 KK=KK+1
N60 IF KK<10 GOTOB ANF
N65 M0
N70 M2
N80 _FEHL1:MSG ("probe not switched")
N90 M0
N95 M2
""")
    result = interp.run()
    assert (result.state, result.block.number) == ("stopped", 65)
    values = np.array(interp.variables.snapshot("MESSWERT_IN_X"))
    expected = SWITCH_AXIS_X + 150 / 60 * LATENCY - G54[0]
    assert interp.variables.get("KK") == 10
    assert np.all(np.abs(values - expected) < 6 * sigma)
    assert values.std() > 0.0                                    # ten different touches


def test_meas_feeds_the_stop_flag_and_the_end_point_to_the_runtime():
    rt = FakeRuntime(position={"X": 0.0, "Y": 0.0, "Z": 0.0}, switch=plane_switch("X", 4.0))
    interp = Interpreter(rt)
    interp.load("G500 F200\nMEAS=1 G1 X10 Y1\nG0 X0 Y0\nMEAW=1 G1 X10\nR1=$AA_MM[X] R2=$AA_MM[Y]")
    assert interp.run().state == "done"
    measures = [e for e in rt.log if e[0] == "measure"]
    assert measures[0] == ("measure", {"X": 10.0, "Y": 1.0, "Z": 0.0}, 200.0, True)
    assert measures[1] == ("measure", {"X": 10.0, "Y": 0.0, "Z": 0.0}, 200.0, False)
    assert interp.variables.get("R", (1,)) == pytest.approx(4.0)
    assert interp.variables.get("R", (2,)) == pytest.approx(0.0)


@pytest.mark.parametrize("text, definition, column", [
    ("MEAS=-1 G1 X10 F100", alarms.NC_VALUE_RANGE, 1),
    ("MEAS=3 G1 X10 F100", alarms.NC_VALUE_RANGE, 1),
    ("G0\nMEAS=1 X10 F100", alarms.NC_SYNTAX, 1),
    ("MEAS=1 G1 X0 F100", alarms.NO_MEASURING_PATH, 1),
    ("MEAS=1 G1 X10", alarms.NC_FEED_MISSING, 11),
])
def test_meas_errors(text, definition, column):
    interp = Interpreter(FakeRuntime())
    interp.load(text)
    result = interp.run()
    assert result.alarm.alarm is definition and result.alarm.column == column, result.alarm
