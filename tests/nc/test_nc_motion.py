"""Modal state and moves through a fake runtime that records the MCS targets.

Expected targets are computed by hand: p_mcs_axes = R·p_wcs + T + L·infeed (design.md §3), R from
scipy (intrinsic Z-Y-X = RPY as the SINUMERIK applies it), independent of engine.frames.
"""

from __future__ import annotations

import numpy as np
import pytest
from nc_runtimes import FakeRuntime
from scipy.spatial.transform import Rotation

from app.nc.interpreter import Interpreter
from app.nc.modal import ModalState
from engine import alarms
from engine.frames import Frame

L = 100.0                                # offset length of T9 D1
L2 = 87.5                                # T9 D2
T54 = np.array([250.0, 150.0, -120.0])
ROT54 = (2.0, -3.0, 30.0)                # about X, Y, Z (deg)


def rpy(rot):
    a, b, c = rot
    return Rotation.from_euler("ZYX", [c, b, a], degrees=True).as_matrix()


def runtime(**kw):
    kw.setdefault("offsets", {"G54": Frame(coarse=T54, rot=ROT54), "G55": Frame(coarse=[10.0, 20.0, 30.0])})
    kw.setdefault("tools", {9: {1: L, 2: L2}, 3: {1: 50.0}})
    kw.setdefault("tool", 9)
    kw.setdefault("edge", 1)
    kw.setdefault("position", {"X": 0.0, "Y": 0.0, "Z": 300.0})
    return FakeRuntime(**kw)


def run(text, rt=None, **kw):
    rt = rt or runtime(**kw)
    interp = Interpreter(rt)
    interp.load(text)
    result = interp.run()
    assert result.state == "done", result.alarm
    return interp, rt


def targets(rt):
    return [(np.array([e[1][a] for a in ("X", "Y", "Z")]), e[2]) for e in rt.moves]


def test_move_in_a_rotated_frame_with_tool_length():
    interp, rt = run("G54 G17 G90 G0 X10 Y20 Z5")
    (target, feed), = targets(rt)
    expected = rpy(ROT54) @ np.array([10.0, 20.0, 5.0]) + T54 + L * np.array([0.0, 0.0, 1.0])
    np.testing.assert_allclose(target, expected, atol=1e-9)
    assert feed is None
    assert ("activate", "G54") in rt.log and interp.modal.offset == "G54"


def test_incremental_moves_go_along_the_wcs_axes():
    interp, rt = run("G54 G0 X10 Y20 Z5\nG91 X5\nZ-2\nG90 Y0")
    t = [p for p, _ in targets(rt)]
    R = rpy(ROT54)
    np.testing.assert_allclose(t[1] - t[0], R @ [5.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(t[2] - t[1], R @ [0.0, 0.0, -2.0], atol=1e-9)
    np.testing.assert_allclose(t[3], R @ [15.0, 0.0, 3.0] + T54 + [0, 0, L], atol=1e-9)
    assert interp.modal.distance == "G90"


def test_unprogrammed_axes_keep_their_wcs_position():
    _, rt = run("G54 G0 X10 Y20 Z5\nX30")
    t = [p for p, _ in targets(rt)]
    np.testing.assert_allclose(t[1], rpy(ROT54) @ [30.0, 20.0, 5.0] + T54 + [0, 0, L], atol=1e-9)


@pytest.mark.parametrize("plane, unit", [("G17", (0, 0, 1)), ("G18", (0, 1, 0)), ("G19", (1, 0, 0))])
def test_tool_length_along_the_infeed_axis_of_the_plane(plane, unit):
    interp, rt = run(f"G500 {plane} G0 X10 Y20 Z5")
    (target, _), = targets(rt)
    np.testing.assert_allclose(target, np.array([10.0, 20.0, 5.0]) + L * np.array(unit, float), atol=1e-12)
    assert interp.modal.plane == plane


def test_g500_is_the_basic_chain_only():
    basic = Frame(coarse=[1.0, 2.0, 3.0], rot=[0.0, 0.0, 90.0])
    _, rt = run("G54 G0 X0 Y0 Z0\nG500 X10 Y0 Z0", basic=[basic])
    t = [p for p, _ in targets(rt)]
    Rb = rpy((0.0, 0.0, 90.0))
    np.testing.assert_allclose(t[0], Rb @ (rpy(ROT54) @ [0, 0, 0] + T54) + [1, 2, 3] + [0, 0, L], atol=1e-9)
    np.testing.assert_allclose(t[1], Rb @ [10.0, 0, 0] + [1, 2, 3] + [0, 0, L], atol=1e-9)


def test_g53_suppresses_the_frames_for_one_block():
    interp, rt = run("G54 G0 X0 Y0 Z0\nG53 X100 Y50 Z-10\nX1 Y2 Z3")
    t = [p for p, _ in targets(rt)]
    np.testing.assert_allclose(t[1], [100.0, 50.0, -10.0 + L], atol=1e-12)       # MCS, tool length kept
    np.testing.assert_allclose(t[2], rpy(ROT54) @ [1, 2, 3] + T54 + [0, 0, L], atol=1e-9)
    assert interp.modal.offset == "G54"


def test_g53_keeps_unprogrammed_axes_in_mcs():
    _, rt = run("G54 G0 X0 Y0 Z0\nG53 Z200")
    t = [p for p, _ in targets(rt)]
    np.testing.assert_allclose(t[1][:2], t[0][:2], atol=1e-9)
    assert t[1][2] == pytest.approx(200.0 + L)


def test_inch_g70_converts_geometry_but_not_the_feed():
    interp, rt = run("G500 G70 G1 X1 Y-2 Z0.5 F100\nG91 X0.1\nG71 G90 X10")
    t = targets(rt)
    np.testing.assert_allclose(t[0][0], [25.4, -50.8, 12.7 + L], atol=1e-12)
    assert t[0][1] == 100.0                   # G70: F stays mm/min (840D; G700 converts it)
    assert t[1][0][0] == pytest.approx(25.4 + 2.54)
    assert t[2][0][0] == pytest.approx(10.0)
    assert interp.modal.units == "G71"


def test_inch_g700_converts_the_feed_too():
    interp, rt = run("G500 G700 G1 X1 F10")
    (target, feed), = targets(rt)
    assert target[0] == pytest.approx(25.4) and feed == pytest.approx(254.0)
    assert interp.modal.feed == pytest.approx(254.0) and interp.modal.inch_feed


def test_feed_is_modal_and_g0_is_rapid():
    interp, rt = run("G500 G1 X1 F100\nX2\nG0 X3\nG1 X4\nF250 X5")
    assert [f for _, f in targets(rt)] == [100.0, 100.0, None, 100.0, 250.0]
    assert interp.modal.feed == 250.0 and interp.modal.motion == "G1"


def test_g1_without_feed_is_an_alarm_at_its_block():
    interp = Interpreter(runtime())
    interp.load("G500 G0 X1\nN20 G1 Y5")
    result = interp.run()
    assert result.state == "alarm" and result.alarm.alarm is alarms.NC_FEED_MISSING
    assert (result.alarm.line, result.alarm.column) == (2, 8)
    assert result.block.number == 20


def test_default_motion_is_g1_and_configurable():
    interp = Interpreter(runtime())
    interp.load("X1")
    assert interp.run().alarm.alarm is alarms.NC_FEED_MISSING
    rt = runtime()
    interp = Interpreter(rt, defaults=ModalState(motion="G0"))
    interp.load("X1")
    assert interp.run().state == "done" and targets(rt)[0][1] is None


def test_the_offset_change_alone_moves_nothing_and_axes_stay():
    interp, rt = run("G54 G0 X0 Y0 Z0\nG55\nZ50")
    t = [p for p, _ in targets(rt)]
    assert len(t) == 2
    # Z50 in G55: X, Y keep their position (expressed in G55), Z goes to 50 + 30 + L
    np.testing.assert_allclose(t[1][:2], t[0][:2], atol=1e-9)
    assert t[1][2] == pytest.approx(50.0 + 30.0 + L)
    assert [e for e in rt.log if e[0] == "activate"] == [("activate", "G54"), ("activate", "G55")]


def test_rotary_axis_with_the_frames_rotary_offset():
    rt = runtime(axes=("X", "Y", "Z", "A"), offsets={"G54": Frame(rotary=(("A", 10.0),))},
                 position={"X": 0.0, "Y": 0.0, "Z": 300.0, "A": 0.0})
    _, rt = run("G54 G0 A20\nG91 A-5\nG90 X1 A0", rt=rt)
    moves = [e[1] for e in rt.moves]
    assert moves[0] == {"A": 30.0}
    assert moves[1] == {"A": 25.0}
    assert moves[2]["A"] == 10.0 and moves[2]["X"] == pytest.approx(1.0)


def test_tool_change_and_d_select_the_offset_length():
    interp, rt = run("G500 T3 M6 G0 X0 Y0 Z0\nT9\nM6 D2 Z0\nD1 Z0\nD0 Z0")
    t = [p[2] for p, _ in targets(rt)]
    assert t == [pytest.approx(50.0), pytest.approx(L2), pytest.approx(L), pytest.approx(0.0)]
    assert ("tool", 3, 1) in rt.log and ("tool", 9, 2) in rt.log and ("edge", 1) in rt.log
    assert (interp.modal.tool, interp.modal.edge) == (9, 0)


def test_spindle_and_spos():
    interp, rt = run("S1000 M3\nS500\nM5\nSPOS=180\nM4 S200")
    spindle = [e for e in rt.log if e[0] in ("spindle", "spos")]
    assert spindle == [("spindle", 1, 1000.0), ("spindle", 1, 500.0), ("spindle", 0, 500.0), ("spos", 180.0),
                       ("spindle", -1, 200.0)]
    assert interp.modal.spindle_direction == -1 and interp.modal.spindle_speed == 200.0


def test_m3_needs_a_speed():
    interp = Interpreter(runtime())
    interp.load("M3")
    result = interp.run()
    assert result.alarm.alarm is alarms.NC_VALUE_RANGE and "program a spindle speed" in result.alarm.message


def test_modal_state_persists_to_the_next_program_and_reset_restores_the_defaults():
    rt = runtime()
    interp = Interpreter(rt)
    interp.load("G54 G91 G18 G70 F100")
    interp.run()
    interp.load("G0 X0")
    m = interp.modal
    assert (m.offset, m.distance, m.plane, m.units, m.feed) == ("G54", "G91", "G18", "G70", 100.0)
    interp.reset()
    m = interp.modal
    assert (m.offset, m.distance, m.plane, m.units, m.feed, m.motion) == ("G54", "G90", "G17", "G71", None, "G1")
    assert m.tool == 9 and m.edge == 1         # the physical state comes from the machine


def test_an_offset_the_control_does_not_have_is_an_alarm_before_motion():
    rt = runtime()
    interp = Interpreter(rt)
    interp.load("G0 X0\nG56 X10")
    result = interp.run()
    assert result.state == "alarm" and result.alarm.alarm is alarms.ZO_NUMBER
    assert (result.alarm.line, result.alarm.column) == (2, 1) and len(rt.moves) == 1
    assert interp.modal.offset == "G500"
    interp.load("T3 M6 G56")                      # found before the tool change is commanded
    assert interp.run().alarm.alarm is alarms.ZO_NUMBER and ("tool", 3, 1) not in rt.log
