"""The lathe tasks of turning.md §10.2: validation, mapping to the cycle calls, end to end."""

from __future__ import annotations

import numpy as np
import pytest
from test_turning_model import ProbeWorld, Solid, ToolWorld, TurningToolTruth, drive
from test_turning_probe import sl7_groove

from engine import alarms
from engine.checks import ParamError
from engine.turning import LatheContext, LatheProbe, LatheTool
from engine.turning_plan import (
    LATHE_TASKS,
    evaluate_lathe,
    finish_lathe,
    lathe_planned_path,
    lathe_program,
    prepare,
    validate_lathe_params,
)
from engine.types import MeasuringError

TRUE_1B = {"Z-": 220.35, "Z+": 199.65, "X-": 400.25, "X+": 379.80}


def xz(x, z):
    return np.array([x, 0.0, z])


@pytest.mark.parametrize("task, params, field", [
    ("lathe.toolprobe.calibrate", {}, "axis"),
    ("lathe.toolprobe.calibrate", {"axis": "Y"}, "axis"),
    ("lathe.toolprobe.calibrate", {"axis": "X", "incremental": True}, "direction"),
    ("lathe.toolprobe.calibrate", {"axis": "X", "measuring_path": 0}, "measuring_path"),
    ("lathe.toolprobe.calibrate", {"axis": "X", "reference": "tool"}, "reference"),
    ("lathe.toolprobe.calibrate", {"axis": "X", "tolerance": {"upper": 0.1}}, "tolerance.upper"),
    ("lathe.toolprobe.calibrate", {"axis": "X", "probe": 0}, "probe"),
    ("lathe.tool.measure", {"axis": "Z", "compensation": "both"}, "compensation"),
    ("lathe.tool.measure", {"axis": "Z", "tolerance": {"safe_area": "x"}}, "tolerance.safe_area"),
    ("lathe.tool.measure", {"axis": "Z", "tolerance": {"evnum": -1}}, "tolerance.evnum"),
    ("lathe.tool.measure", {"axis": "Z", "incremental": True, "direction": "-", "quantity": "length_radius"},
     "quantity"),
    ("lathe.tool.auto", {"quantity": "radius"}, "quantity"),
    ("lathe.probe.groove", {"axis": "X", "direction": "both"}, "groove"),
    ("lathe.probe.groove", {"groove": {"number": 1}, "axis": "X", "direction": "+", "skew": True}, "skew"),
    ("lathe.probe.groove", {"groove": {"number": 1}, "axis": "X", "direction": "-", "ball_diameter": True},
     "ball_diameter"),
    ("lathe.probe.groove", {"groove": {"x_minus": 50, "width": 3}, "axis": "X", "direction": "+"}, "groove.width"),
    ("lathe.probe.surface", {"axis": "Z", "direction": "-"}, "setpoint"),
    ("lathe.point", {"axis": "X"}, "setpoint"),
    ("lathe.point", {"axis": "X", "setpoint": 45, "tolerance": {"setpoint": 44}}, "tolerance.setpoint"),
    ("lathe.point", {"axis": "X", "setpoint": 45, "tolerance": {"k": 0}}, "tolerance.k"),
    ("lathe.point", {"axis": "X", "setpoint": 45, "target": "G99"}, "target"),
    ("lathe.point", {"axis": "X", "setpoint": 45, "target": "G54", "reversal": True}, "reversal"),
    ("lathe.point", {"axis": "X", "setpoint": 45, "target": {"tool": 7, "correct": "diameter"}}, "target.correct"),
    ("lathe.point", {"axis": "X", "setpoint": 45, "start_angle": 400}, "start_angle"),
    ("lathe.two_point", {"axis": "X", "setpoint": 45}, "zone"),
    ("lathe.two_point", {"axis": "X", "setpoint": -45, "zone": {"Z": 5, "X": 55}}, "setpoint"),
    ("lathe.two_point", {"axis": "X", "setpoint": 45, "zone": {"Z": 5, "Y": 1}}, "zone.Y"),
    ("lathe.two_point", {"axis": "X", "setpoint": 35, "inside": True, "zone": {"X": 1}}, "zone.Z"),
    ("lathe.nothing", {}, "task"),
])
def test_validation_names_the_field(task, params, field):
    with pytest.raises(ParamError) as err:
        validate_lathe_params(task, params)
    assert err.value.field == field
    assert isinstance(err.value, ValueError)


def _call(task, params, ctx=None):
    return prepare(task, validate_lathe_params(task, params), ctx or LatheContext())


def test_mapping_to_cycle_calls():
    """§10.2: the task params give the manual's _MVAR and parameters."""
    assert _call("lathe.toolprobe.calibrate", {"axis": "X"}).call.mvar == 0
    prep = _call("lathe.toolprobe.calibrate", {"axis": "Z", "reference": "workpiece", "incremental": True,
                                               "direction": "-"})
    assert (prep.call.mvar, prep.call.ma, prep.call.md, prep.coords) == (100010, 1, 1, "WCS")
    prep = _call("lathe.tool.measure", {"axis": "X", "compensation": "wear", "tolerance": {"evnum": 11}})
    assert (prep.call.mvar, prep.call.ma, prep.call.evnum, prep.ctx.bit(3), prep.coords) == (1, 2, 11, True, "MCS")
    assert _call("lathe.tool.auto", {"reference": "workpiece"}).call.mvar == 12
    prep = _call("lathe.tool.measure", {"axis": "Z", "quantity": "length_radius", "position": "radial",
                                        "start_angle": 15})
    assert prep.call.mvar == 12001 and prep.call.sta1 == 15.0 and not prep.ctx.bit(3)
    prep = _call("lathe.probe.groove", {"groove": {"number": 2}, "axis": "X", "direction": "both", "skew": True,
                                        "ball_diameter": True})
    assert (prep.call.mvar, prep.call.calnum, prep.coords) == (12113, 2, "MCS")
    prep = _call("lathe.probe.groove", {"groove": {"x_minus": 50.054, "x_plus": 60.123, "bottom_z": 15.021},
                                        "axis": "Z", "direction": "-"})
    assert (prep.call.mvar, prep.call.md, prep.call.calnum) == (1013, 1, 1)
    assert prep.ctx.kb == ((60.123, 50.054, 15.021, 0.0, 0.0, 0.0, 0.0),)
    prep = _call("lathe.probe.surface", {"axis": "Z", "direction": "-", "setpoint": -18})
    assert (prep.call.mvar, prep.call.md, prep.call.setval, prep.coords) == (0, 1, -18.0, "WCS")
    prep = _call("lathe.point", {"axis": "Z", "setpoint": 60, "target": "G54"})
    assert (prep.call.mvar, prep.call.knum, prep.zero_offset) == (100, 1, "G54")
    prep = _call("lathe.point", {"axis": "X", "setpoint": 45, "reversal": True, "start_angle": 0,
                                 "target": {"tool": 7, "edge": 1}, "tolerance": {"upper": 0, "lower": -0.01}})
    assert prep.call.mvar == 1000 and prep.target.t == 7 and prep.call.tul == 0.0 and prep.call.tll == -0.01
    prep = _call("lathe.two_point", {"axis": "X", "setpoint": 35, "inside": True, "zone": {"Z": 55}})
    assert prep.call.mvar == 1 and prep.call.sza == 55.0
    prep = _call("lathe.two_point", {"axis": "X", "setpoint": 45, "zone": {"Z": 55, "X": 55},
                                     "use_ball_diameter": True, "tolerance": {"keep_mean": True}})
    assert prep.call.mvar == 2 and prep.call.szo == 55.0 and prep.ctx.bit(7) and prep.ctx.bit(4)
    assert _call("lathe.two_point", {"axis": "X", "setpoint": 35, "inside": True}).call.mvar == 2
    assert set(LATHE_TASKS) == {"lathe.toolprobe.calibrate", "lathe.tool.measure", "lathe.tool.auto",
                                "lathe.probe.groove", "lathe.probe.surface", "lathe.point", "lathe.two_point"}


def test_toolprobe_and_tool_tasks_end_to_end():
    """1-B's first call and 2-B through the task layer: the §10.2 result keys."""
    rough = {"Z-": 220.0, "Z+": 200.0, "X-": 400.0, "X+": 380.0}
    t7 = LatheTool(t=7, d=1, type=500, sl=3, l1=10.0, l2=40.0, radius=5.0)
    prep = _call("lathe.toolprobe.calibrate", {"axis": "X", "measuring_path": 1,
                                               "tolerance": {"safe_area": 1, "zero_range": 0.001}},
                 LatheContext(tool=t7, tp=(rough,)))
    world = ToolWorld(faces=TRUE_1B, tool=TurningToolTruth(3, 10.0, 40.0, 5.0), stored_l1=10.0, stored_l2=40.0,
                      start=xz(420, 240))
    ev = evaluate_lathe(prep, drive(lathe_program(prep, xz(420, 240)), world))
    assert ev.values["trigger"] == {"X-": pytest.approx(400.25)}
    assert ev.values["difference"] == {"X-": pytest.approx(0.25)}
    assert ev.values["tool_probe"]["faces"]["X-"] == pytest.approx(400.25)
    t3 = LatheTool(t=3, d=1, type=500, sl=3, l1=100.65, l2=60.32, radius=2.0)
    prep = _call("lathe.tool.auto", {"compensation": "geometry", "measuring_path": 1,
                                     "tolerance": {"safe_area": 1, "dim_difference": 0.8}},
                 LatheContext(tool=t3, tp=(TRUE_1B,)))
    world = ToolWorld(faces=TRUE_1B, tool=TurningToolTruth(3, 100.7, 60.3, 2.0), stored_l1=100.65, stored_l2=60.32,
                      start=xz(420, 240))
    ev = evaluate_lathe(prep, drive(lathe_program(prep, xz(420, 240)), world))
    assert ev.values["length"]["L1"]["actual"] == pytest.approx(100.7, abs=1e-9)
    assert ev.values["length"]["L2"]["difference"] == pytest.approx(-0.02, abs=1e-9)
    assert ev.values["tool"]["l1"] == pytest.approx(100.7, abs=1e-9) and ev.values["tool"]["sl"] == 3
    assert not ev.needs_decision


def test_probe_tasks_end_to_end():
    """4-A call 2 (skew) and 4-B through the task layer: the ``probe`` key holds _WP[k]."""
    probe = LatheTool(t=8, d=1, type=580, sl=7, l1=40.123, l2=100.456, radius=3.0)
    old = LatheProbe.from_wp([0.0, 2.990, 0.0, 2.992, -2.997, 0, 0, 0, 0, 0, 0])
    prep = _call("lathe.probe.groove", {"groove": {"x_minus": 50.054, "x_plus": 60.123, "bottom_z": 15.021},
                                        "axis": "X", "direction": "both", "skew": True, "measuring_path": 3,
                                        "tolerance": {"zero_range": 0, "safe_area": 1}},
                 LatheContext(tool=probe, wp=(old,)))
    start = xz(55.0885, 21.021)
    world = ProbeWorld(solids=sl7_groove(), radius={"X+": 2.995, "X-": 2.995}, true_r=3.0, skew=(0.0, 0.004),
                       start=start)
    ev = evaluate_lathe(prep, drive(lathe_program(prep, start), world))
    assert ev.values["probe"]["wp"][8] == pytest.approx(0.004, abs=1e-9)
    assert ev.values["probe"]["trigger"]["X+"] == pytest.approx(-2.995, abs=1e-9)
    prep = _call("lathe.probe.surface", {"axis": "Z", "direction": "-", "setpoint": -18, "measuring_path": 3,
                                         "tolerance": {"zero_range": 0, "safe_area": 1}},
                 LatheContext(tool=probe, wp=(old,), diamon=True))
    start = xz(33.0, 90.0)
    world = ProbeWorld(solids=[Solid(0.0, 40.0, -60.0, -18.0)], radius={"Z-": 2.996}, true_r=3.0, start=start)
    ev = evaluate_lathe(prep, drive(lathe_program(prep, start), world))
    assert ev.values["probe"]["wp"][1] == pytest.approx(2.996, abs=1e-9)


def test_point_tasks_end_to_end():
    """5-A (ZO) and 5-C (reversal) and 6-A (two points) through the task layer."""
    probe = LatheTool(t=9, d=1, type=580, sl=7, l1=40.123, l2=100.456, radius=3.0)
    rec = LatheProbe(trigger={"Z-": 2.995, "X-": 2.995, "X+": -2.993})
    ctx = LatheContext(tool=probe, wp=(rec,), diamon=True)
    prep = _call("lathe.point", {"axis": "Z", "setpoint": 60, "target": "G54", "measuring_path": 1,
                                 "tolerance": {"safe_area": 1}}, ctx)
    start = xz(18.0, 100.0)
    world = ProbeWorld(solids=[Solid(0.0, 30.0, 0.0, 60.15)], radius={"Z-": 2.995}, true_r=3.0, start=start)
    ev = evaluate_lathe(prep, drive(lathe_program(prep, start), world),
                        frame={"coarse": [0, 0, 200.0], "fine": [0, 0, 0]})
    assert not ev.needs_decision
    assert ev.values["actual"] == pytest.approx(60.15) and ev.values["decision"] == "full"
    assert ev.values["compensation"] == pytest.approx(0.15)
    assert ev.values["frame"]["after"]["coarse"][2] == pytest.approx(200.15)
    prep = _call("lathe.point", {"axis": "X", "setpoint": 45, "reversal": True, "start_angle": 0,
                                 "target": {"tool": 7, "edge": 1, "correct": "length", "mode": "wear"},
                                 "measuring_path": 2, "tolerance": {"upper": 0, "lower": -0.01, "zero_range": 0.002,
                                                                    "dim_difference": 0.4, "safe_area": 1}}, ctx)
    start = xz(45.0, 30.0)
    world = ProbeWorld(solids=[Solid(0.0, 22.503, -40.0, 60.0, ecc=(0.03, 0.0))], radius={"X-": 2.995}, true_r=3.0,
                       start=start)
    ev = evaluate_lathe(prep, drive(lathe_program(prep, start), world))
    assert ev.needs_decision and ev.values["actual"] == pytest.approx(45.006, abs=1e-9)
    assert ev.values["deviation"] == pytest.approx(0.011, abs=1e-9)
    t7 = LatheTool(t=7, d=1, type=500, sl=3, l1=60.0, l2=30.0, radius=0.8)
    r = finish_lathe(prep, ev, decision="oversize", amount=ev.measurement.deviation, warning=alarms.OVERSIZE, tool=t7)
    assert r.values["compensation"] == pytest.approx(-0.0055, abs=1e-9) and r.values["decision"] == "oversize"
    assert r.tool_after["wear"]["l1"] == pytest.approx(-0.0055, abs=1e-9) and r.ovr[20] == pytest.approx(-0.0055)
    prep = _call("lathe.two_point", {"axis": "X", "setpoint": 45, "zone": {"Z": 55, "X": 55}, "measuring_path": 1,
                                     "target": {"tool": 8},
                                     "tolerance": {"upper": 0, "lower": -0.01, "evnum": 3, "safe_area": 0.5}}, ctx)
    start = xz(30.0, 30.0)
    world = ProbeWorld(solids=[Solid(0.0, 22.4995, -40.0, 50.0, ecc=(0.02, 0.0))],
                       radius={"X-": 2.995, "X+": 2.993}, true_r=3.0, start=start)
    ev = evaluate_lathe(prep, drive(lathe_program(prep, start), world), ev=0.001)
    assert ev.values["diameter"] == pytest.approx(44.999, abs=1e-9)
    assert ev.values["deviation"] == pytest.approx(0.003, abs=1e-9)
    r = finish_lathe(prep, ev, decision="none", mean_value=0.0016)
    assert r.values["diameter"] == pytest.approx(44.999) and r.values["compensation"] == 0.0
    assert r.values["mean_value"] == 0.0016
    prep = _call("lathe.two_point", {"axis": "X", "setpoint": 45, "inside": True, "measuring_path": 1}, ctx)
    with pytest.raises(MeasuringError) as err:
        drive(lathe_program(prep, start), ProbeWorld(solids=[], radius={}, true_r=3.0, start=start))
    assert err.value.definition is alarms.WRONG_VARIANT


def test_frames_refused():
    """turning.md §0.2: a scale factor -> 61310 in every cycle; a rotation in the plane -> 61330
    in CYCLE972/973/974/994 [L27895–L27899] (not listed for CYCLE982)."""
    from engine.turning_point import point_program
    from engine.turning_probe import Cycle973, probe_calibration_program
    from engine.turning_tools import Cycle982, toolprobe_program
    from engine.turning_twopoint import two_point_program
    from engine.turning_workpiece import WorkpieceCall
    t7 = LatheTool(t=7, d=1, type=500, sl=3, l1=10.0, l2=40.0, radius=5.0)
    probe = LatheTool(t=8, d=1, type=580, sl=7, radius=3.0)
    rec = LatheProbe(trigger={"X-": 3.0, "X+": -3.0, "Z-": 3.0})
    programs = [
        (lambda c: toolprobe_program(Cycle982(mvar=0, ma=2, cycle=972), xz(420, 240), c), t7, True),
        (lambda c: toolprobe_program(Cycle982(mvar=0, ma=2), xz(420, 240), c), t7, False),
        (lambda c: probe_calibration_program(Cycle973(mvar=0, ma=1, md=1, setval=0.0), xz(20, 30), c), probe, True),
        (lambda c: point_program(WorkpieceCall(cycle=974, mvar=0, setval=20.0), xz(20, 30), c), probe, True),
        (lambda c: two_point_program(WorkpieceCall(cycle=994, mvar=2, setval=20.0, szo=60, sza=50), xz(20, 30), c), probe, True),
    ]
    for make, tool, rotation in programs:
        for flags, alarm in (({"scale_active": True}, alarms.SCALE_FACTOR),
                             ({"rotation_active": True}, alarms.ROTATION_ACTIVE)):
            ctx = LatheContext(tool=tool, tp=(TRUE_1B,), wp=(rec,), **flags)
            if alarm is alarms.ROTATION_ACTIVE and not rotation:
                next(make(ctx))                       # CYCLE982 runs
                continue
            with pytest.raises(MeasuringError) as err:
                next(make(ctx))
            assert err.value.definition is alarm
    with pytest.raises(MeasuringError) as err:
        next(toolprobe_program(Cycle982(mvar=1, ma=2, cycle=972), xz(420, 240),
                               LatheContext(tool=LatheTool(type=120, radius=5.0), tp=(TRUE_1B,))))
    assert err.value.definition is alarms.TOOL_TYPE


def test_planned_path_preview():
    """The preview of 2-B's automatic measurement; a start in the forbidden band ends the list."""
    t3 = LatheTool(t=3, d=1, type=500, sl=3, l1=100.65, l2=60.32, radius=2.0)
    prep = _call("lathe.tool.auto", {"measuring_path": 1}, LatheContext(tool=t3, tp=(TRUE_1B,)))
    steps = lathe_planned_path(prep, xz(420, 240))
    assert len([s for s in steps if s.__class__.__name__ == "ProbeStep"]) == 2
    assert steps[-1].target == pytest.approx(xz(420, 240))
    assert lathe_planned_path(prep, xz(400.5, 240)) == []
