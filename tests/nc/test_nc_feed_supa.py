"""Words of the manual's listings (issue 28 item 1): G94/G95 (feed per minute / per revolution,
840D group 15) and SUPA (frame suppression, manual §6 tool-probe calibration listing
``%_N_KALIBRIEREN_MTWZ_MPF``: ``N05 G0 G17 G94 G90``, ``N30 SUPA G0 Z100``)."""

from __future__ import annotations

import pytest
from nc_runtimes import FakeRuntime

from app.nc.interpreter import Interpreter
from app.nc.variables import Variables
from engine import alarms
from engine.frames import Frame

T54 = (200.0, 100.0, -150.0)


def run(text: str):
    rt = FakeRuntime(offsets={"G54": Frame(coarse=T54)}, tools={7: {1: 50.0}})
    interp = Interpreter(rt, Variables(axes=("X", "Y", "Z")))
    interp.load(text)
    return interp, rt, interp.run()


def test_the_listings_first_block_runs_as_printed():
    interp, _rt, result = run("N05 G0 G17 G94 G90\nN10 M2")
    assert result.state == "done" and interp.modal.feed_type == "G94"


def test_g95_feeds_per_revolution_of_the_spindle():
    # 0.1 mm per revolution at 1000 rev/min = 100 mm/min
    _interp, rt, result = run("G95 S1000 M3\nG1 F0.1 X10")
    assert result.state == "done"
    assert rt.moves[-1][2] == pytest.approx(100.0)


def test_g95_with_the_spindle_standing_is_an_alarm_before_any_motion():
    interp, rt, result = run("G95 F0.1\nG1 X10")
    assert result.state == "alarm" and result.alarm.alarm == alarms.NC_FEED_MISSING
    assert "G95" in result.alarm.message and result.block.line == 2
    assert rt.moves == []


def test_g94_goes_back_to_feed_per_minute():
    _interp, rt, _result = run("G95 S500 M3 F0.2\nG1 X5\nG94 F300 X8")
    assert [m[2] for m in rt.moves] == [pytest.approx(100.0), pytest.approx(300.0)]


def test_supa_positions_in_machine_coordinates_like_g53():
    _i, supa, _r = run("G54 G0 X0 Y0 Z0\nN30 SUPA G0 Z100\nN35 SUPA X70 Y90")
    _i, g53, _r = run("G54 G0 X0 Y0 Z0\nG53 G0 Z100\nG53 X70 Y90")
    assert supa.moves == g53.moves
    assert supa.moves[1][1]["Z"] == pytest.approx(100.0)           # not G54's Z -150 + 100
    assert (supa.moves[2][1]["X"], supa.moves[2][1]["Y"]) == (pytest.approx(70.0), pytest.approx(90.0))
