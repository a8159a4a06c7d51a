"""SimulatedMachine behaviour against analytic truth (measuring-math §1, design.md §5)."""

import threading

import numpy as np
import pytest
from sim_helpers import plane_contact, rotation, scenario
from waiting import wait_until

from app.machine.protocol import (
    ActiveFrame,
    Machine,
    MachineAlarm,
    MachineBusy,
)
from app.machine.sim import SimulatedMachine
from engine import alarms

L = 100.0
R_BALL = 2.0
XYZ = ("X", "Y", "Z")


def _xyz(d):
    return np.array([d[a] for a in XYZ])


def _front_face(sc):
    """Point on the block's front face (part y = 0) and its outward normal, MCS."""
    rot = rotation(sc.workpiece.pose.rot)
    trans = np.asarray(sc.workpiece.pose.trans, float)
    return rot @ np.array([100.0, 0.0, -30.0]) + trans, rot @ np.array([0.0, -1.0, 0.0])


def _machine_in_front(sc, gap=10.0):
    """Machine with the ball centre ``gap`` mm in front of the face, probing direction -n."""
    m = SimulatedMachine(sc)
    p_face, n = _front_face(sc)
    centre = p_face + (R_BALL + gap) * n
    m.goto(dict(zip(XYZ, centre + np.array([0, 0, L]), strict=True)))
    return m, p_face, n


def test_implements_protocol():
    assert isinstance(SimulatedMachine(scenario()), Machine)


def test_pretravel_and_eccentricity_shift_the_latched_position():
    """The wave-1 model (``pretravel_frame`` "machine"): the lobing stays with the machine axes
    while the eccentricity turns with SPOS (the probe-frame default: tests/sim/test_probe_frame.py)."""
    pre = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006, "Z-": 0.002}
    ecc = np.array([0.01, -0.006])
    sc = scenario(probe={"t": 9, "ball_diameter": 4.0, "length": L, "max_deflection": 5.0,
                         "pretravel": pre, "eccentricity": list(ecc), "pretravel_frame": "machine"})
    p_face, n = _front_face(sc)
    d = -n
    for spos in (0.0, 90.0, 180.0):
        m = SimulatedMachine(sc)
        m.spindle_position(spos)
        phi = np.radians(spos)
        e = np.array([ecc[0] * np.cos(phi) - ecc[1] * np.sin(phi), ecc[0] * np.sin(phi) + ecc[1] * np.cos(phi), 0])
        axes0 = p_face + 10.0 * n + np.array([0, 0, L]) - e
        m.goto(dict(zip(XYZ, axes0, strict=True)))
        centre0 = axes0 + e - np.array([0, 0, L])
        s_contact = plane_contact(centre0, d, p_face, n, R_BALL)
        # pre-travel of direction d: d_x<0 uses X-, d_y>0 uses Y+ (rotated front face normal)
        pretravel = d[0] ** 2 * (pre["X-"] if d[0] < 0 else pre["X+"]) + d[1] ** 2 * (
            pre["Y-"] if d[1] < 0 else pre["Y+"])
        r = m.probe(d, 20.0, 300.0)
        assert r.triggered
        expected = axes0 + (s_contact + pretravel) * d
        assert _xyz(r.latched_mcs) == pytest.approx(expected, abs=1e-9)


def test_latency_difference_between_feeds_is_dv_times_t():
    sc = scenario(machine={"limits": {"X": [-100, 1000], "Y": [-100, 800], "Z": [-500, 100]},
                           "latency_s": 0.004, "time_scale": 0.0})
    latched = {}
    for feed in (100.0, 500.0):
        m, _, n = _machine_in_front(sc)
        latched[feed] = _xyz(m.probe(-n, 20.0, feed).latched_mcs)
    diff = (latched[500.0] - latched[100.0]) @ (-n)
    assert diff == pytest.approx((500.0 - 100.0) / 60.0 * 0.004, abs=1e-9)


def test_override_50_percent_acts_as_half_the_feed():
    sc = scenario(machine={"limits": {"X": [-100, 1000], "Y": [-100, 800], "Z": [-500, 100]},
                           "latency_s": 0.004, "time_scale": 0.0})
    m1, _, n = _machine_in_front(sc)
    m1.set_override(50.0)
    r1 = m1.probe(-n, 20.0, 600.0)
    m2, _, _ = _machine_in_front(sc)
    r2 = m2.probe(-n, 20.0, 300.0)
    assert r1.override == 50.0 and r1.feed == 600.0
    assert _xyz(r1.latched_mcs) == pytest.approx(_xyz(r2.latched_mcs), abs=1e-9)
    assert _xyz(r1.end_mcs) == pytest.approx(_xyz(r2.end_mcs), abs=1e-9)


def test_braking_end_position():
    sc = scenario(machine={"limits": {"X": [-100, 1000], "Y": [-100, 800], "Z": [-500, 100]},
                           "latency_s": 0.004, "decel": 2.0, "kv": 2.0, "time_scale": 0.0})
    m, p_face, n = _machine_in_front(sc)
    start = _xyz(m.status().mcs)
    r = m.probe(-n, 20.0, 300.0)
    # worked example 1.3-B numbers: 300 mm/min, 4 ms, 2 m/s², Kv 2 -> 0.17625 mm behind the switch
    assert (_xyz(r.end_mcs) - start) @ (-n) == pytest.approx(10.0 + 0.17625, abs=1e-9)
    assert (_xyz(r.latched_mcs) - start) @ (-n) == pytest.approx(10.0 + 300 / 60 * 0.004, abs=1e-9)


def test_seeded_noise_is_reproducible_with_the_right_spread():
    sigma = 0.001
    sc = scenario(probe={"t": 9, "ball_diameter": 4.0, "length": L, "noise_sigma": sigma, "max_deflection": 5.0})

    def run():
        m, _, n = _machine_in_front(sc)
        start = m.status().mcs
        values = []
        for _ in range(400):
            r = m.probe(-n, 20.0, 300.0)
            values.append((_xyz(r.latched_mcs) - _xyz(start)) @ (-n) - 10.0)
            m.goto(start)
        return np.array(values)

    first, second = run(), run()
    assert np.array_equal(first, second)
    assert np.std(first) == pytest.approx(sigma, rel=0.10)
    assert abs(np.mean(first)) < 4 * sigma / np.sqrt(400)


def test_no_trigger_in_free_air():
    m = SimulatedMachine(scenario())
    r = m.probe([1, 0, 0], 50.0, 300.0)
    assert not r.triggered and r.latched_mcs is None
    assert _xyz(r.end_mcs) == pytest.approx([50.0, 0.0, 50.0])
    assert m.status().alarms == ()


def test_collision_during_goto_stops_short_with_61302():
    sc = scenario()
    m, p_face, n = _machine_in_front(sc, gap=30.0)
    start = _xyz(m.status().mcs)
    target = start - 60.0 * n
    result = m.goto(dict(zip(XYZ, target, strict=True)), feed=1000.0)
    assert not result.completed and result.alarm.code == alarms.PROBE_COLLISION.number
    # braking behind the switch (measuring-math §1.3): v = 1000 mm/min, t = 0, a = 1 m/s², Kv = 1
    v = 1000.0 / 60000.0                                      # m/s
    s_b = 1000.0 * v**2 / (2 * 1.0) + 1.0 / 1.0               # 0.1389 mm + following error 1 mm
    expected = start + (30.0 + s_b) * (-n)
    assert _xyz(result.mcs) == pytest.approx(expected, abs=1e-9)
    assert [a.code for a in m.status().alarms] == [alarms.PROBE_COLLISION.number]
    m.reset()
    assert m.status().alarms == ()
    # the deflected probe can be moved away again
    assert m.goto(dict(zip(XYZ, start, strict=True))).completed


def test_rapid_into_the_part_breaks_the_probe_until_tool_change():
    m, _, n = _machine_in_front(scenario(), gap=30.0)
    start = _xyz(m.status().mcs)
    result = m.goto(dict(zip(XYZ, start - 60.0 * n, strict=True)))     # rapid
    assert result.alarm.code == alarms.PROBE_COLLISION.number
    pending = m.status().alarms
    assert [(a.code, a.resettable) for a in pending] == [(alarms.PROBE_COLLISION.number, True),   # collision,
                                                        (alarms.PROBE_BROKEN.number, False)]     # broken stylus
    m.reset()
    remaining = m.status().alarms
    assert len(remaining) == 1 and remaining[0].code == alarms.PROBE_BROKEN.number and not remaining[0].resettable
    with pytest.raises(MachineAlarm) as err:
        m.jog("Z", 10.0)
    assert err.value.alarm.code == alarms.PROBE_BROKEN.number and not err.value.alarm.resettable
    m.change_tool(9, 100.0)
    assert m.status().alarms == ()
    assert m.goto(dict(zip(XYZ, start, strict=True))).completed


def test_probe_overtravel_beyond_max_deflection_breaks():
    m, _, n = _machine_in_front(scenario())      # max_deflection 5 mm; 6000 mm/min brakes > 6 mm
    with pytest.raises(MachineAlarm) as err:
        m.probe(-n, 20.0, 6000.0)
    assert err.value.alarm.code == alarms.PROBE_BROKEN.number and not err.value.alarm.resettable   # 61302 is also
    m.reset()                                                                          # the collision
    with pytest.raises(MachineAlarm) as err:
        m.probe(n, 20.0, 300.0)
    assert not err.value.alarm.resettable


@pytest.mark.parametrize("max_deflection, breaks", [(12.7, False), (12.5, True)])
def test_manual_braking_example_1_3_a_on_the_machine(max_deflection, breaks):
    # measuring-math §1.3-A: v = 6 m/min, t = 0.016 s, a = 1 m/s², Kv = 1 -> s_b = 12.6 mm behind the
    # switch; the latch lies v·t = 1.6 mm behind it; no pre-travel, so the deflection is s_b
    sc = scenario(machine={"latency_s": 0.016, "decel": 1.0, "kv": 1.0},
                  probe={"max_deflection": max_deflection})
    m, _, n = _machine_in_front(sc)                  # contact after 10 mm along -n
    start = _xyz(m.status().mcs)
    if breaks:
        with pytest.raises(MachineAlarm) as err:
            m.probe(-n, 30.0, 6000.0)
        assert err.value.alarm.code == alarms.PROBE_BROKEN.number and not err.value.alarm.resettable
        end = _xyz(m.status().mcs)
    else:
        r = m.probe(-n, 30.0, 6000.0)
        assert (_xyz(r.latched_mcs) - start) @ (-n) == pytest.approx(10.0 + 1.6, abs=1e-9)
        end = _xyz(r.end_mcs)
    assert end == pytest.approx(start + (10.0 + 12.6) * (-n), abs=1e-9)


def test_limits_refuse_before_moving():
    m = SimulatedMachine(scenario())
    before = m.status().mcs
    with pytest.raises(MachineAlarm) as err:
        m.goto({"X": 5000.0})
    assert err.value.alarm.code == alarms.SOFTWARE_LIMIT.number
    with pytest.raises(MachineAlarm):
        m.probe([0, 0, 1], 100.0, 300.0)           # Z 50 -> 150 > 100
    with pytest.raises(MachineAlarm):
        m.jog("Y", -1000.0)
    assert m.status().mcs == before
    assert alarms.SOFTWARE_LIMIT.number in {a.code for a in m.status().alarms}


def test_time_scale_zero_is_instant(monkeypatch):
    def no_waiting(*_args):
        raise AssertionError("time scale 0 must not wait")

    monkeypatch.setattr("app.machine.motion.time.sleep", no_waiting)
    m = SimulatedMachine(scenario())
    assert m.goto({"X": 900.0, "Y": 700.0}, feed=10.0).completed     # 90 min at real speed
    assert m.status().mcs["X"] == pytest.approx(900.0) and m.status().mcs["Y"] == pytest.approx(700.0)


def test_reset_aborts_a_timed_move_and_status_interpolates():
    sc = scenario(machine={"limits": {"X": [-100, 1000], "Y": [-100, 800], "Z": [-500, 100]},
                           "latency_s": 0.0, "time_scale": 1.0})
    m = SimulatedMachine(sc)
    results = {}
    worker = threading.Thread(target=lambda: results.setdefault("r", m.jog("X", 100.0, feed=600.0)))
    worker.start()
    wait_until(lambda: m.status().mcs["X"] > 0.5, "the jog is under way")
    st = m.status()
    assert st.busy and 0.5 < st.mcs["X"] < 100.0                    # interpolated: on its way
    with pytest.raises(MachineBusy):
        m.goto({"Y": 10.0})
    m.reset()
    worker.join(2.0)
    r = results["r"]
    assert not r.completed and r.alarm.code == alarms.RESET_ABORT.number
    assert 0.5 < r.mcs["X"] < 20.0 and not m.status().busy
    assert m.status().mcs["X"] == pytest.approx(r.mcs["X"])


def test_continuous_jog_stop_and_limit():
    sc = scenario(machine={"limits": {"X": [-100, 1000], "Y": [-100, 800], "Z": [-500, 100]},
                           "time_scale": 1.0})
    m = SimulatedMachine(sc)
    m.jog_continuous("Y", -1, feed=3000.0)
    wait_until(lambda: m.status().mcs["Y"] < -0.5, "the continuous jog is under way")
    assert m.status().busy
    m.stop()
    st = m.status()
    assert not st.busy and -100.0 < st.mcs["Y"] < 0.0 and st.alarms == ()
    m2 = SimulatedMachine(scenario())
    m2.jog_continuous("Y", -1)
    m2.stop()
    assert m2.status().mcs["Y"] == pytest.approx(-100.0)
    assert alarms.SOFTWARE_LIMIT.number in {a.code for a in m2.status().alarms}


def test_wcs_display_uses_frame_and_offset_length():
    m = SimulatedMachine(scenario())
    m.change_tool(9, 100.2)
    rot = rotation((0.0, 0.0, 30.0))
    wcs2bcs = np.eye(4)
    wcs2bcs[:3, :3] = rot
    wcs2bcs[:3, 3] = [10.0, 20.0, -30.0]
    m.activate_frame(ActiveFrame(name="G54", wcs2bcs=wcs2bcs))
    st = m.status()
    tip = _xyz(st.mcs) - np.array([0, 0, 100.2])
    assert rot @ _xyz(st.wcs) + wcs2bcs[:3, 3] == pytest.approx(tip, abs=1e-12)
    assert st.active_offset == "G54" and st.tool_length == 100.2


def test_cutter_length_and_radius_on_the_tool_probe():
    sc = scenario()
    m = SimulatedMachine(sc)
    m.change_tool(1, 85.0)
    top = np.array([800.0, 600.0, -200.0])
    m.goto({"X": top[0], "Y": top[1], "Z": top[2] + 85.0 + 10.0})
    r = m.probe([0, 0, -1], 20.0, 100.0)
    assert r.triggered and r.latched_mcs["Z"] == pytest.approx(top[2] + 85.0, abs=1e-9)   # tip on the top face
    m.goto({"Z": top[2] + 85.0 + 10.0})
    m.goto({"X": top[0] + 10.0 + 5.0 + 8.0})
    m.goto({"Z": top[2] + 85.0 - 2.0})                                  # tip 2 mm below the top, beside
    r = m.probe([-1, 0, 0], 20.0, 100.0)
    assert r.latched_mcs["X"] == pytest.approx(top[0] + 10.0 + 5.0, abs=1e-9)          # Rp + R


def test_cutter_touching_the_workpiece_is_a_collision():
    sc = scenario()
    m = SimulatedMachine(sc)
    m.change_tool(1, 85.0)
    rot = rotation(sc.workpiece.pose.rot)
    above = rot @ np.array([100.0, 90.0, 10.0]) + np.asarray(sc.workpiece.pose.trans)
    m.goto({"X": above[0], "Y": above[1], "Z": above[2] + 85.0})
    result = m.goto({"Z": above[2] + 85.0 - 30.0}, feed=500.0)
    assert not result.completed and result.alarm.code == alarms.PROBE_COLLISION.number
    assert result.mcs["Z"] == pytest.approx(above[2] + 85.0 - 10.0, abs=1e-9)   # tip on the top face


def test_load_resets_machine_and_noise_sequence():
    sc = scenario(probe={"t": 9, "ball_diameter": 4.0, "length": L, "noise_sigma": 0.001})
    m, _, n = _machine_in_front(sc)
    in_front = m.status().mcs
    first = m.probe(-n, 20.0, 300.0).latched_mcs
    m.set_override(30.0)
    m.change_tool(1, 85.0)
    m.load(sc)
    st = m.status()
    assert st.mcs == {"X": 0.0, "Y": 0.0, "Z": 50.0} and st.feed_override == 100.0 and st.tool == 9
    m.goto(in_front)
    assert m.probe(-n, 20.0, 300.0).latched_mcs == first        # the seeded noise starts again


def test_scene_geometry_is_json_ready():
    import json

    geo = SimulatedMachine(scenario()).scene_geometry()
    json.dumps(geo)
    assert len(geo["block"]["corners"]) == 8
    kinds = sorted(c["kind"] for c in geo["circles"])
    assert kinds == ["hole", "ring_bore", "ring_outer", "spigot", "tool_probe"]
    assert geo["probe"]["is_probe"] and geo["probe"]["tip"] == pytest.approx([0.0, 0.0, -50.0])


def test_bad_input_is_a_value_error():
    m = SimulatedMachine(scenario())
    for call in (lambda: m.probe([0, 0, 0], 10, 300), lambda: m.probe([1, 0, 0], -1, 300),
                 lambda: m.goto({"Q": 1.0}), lambda: m.set_override(130),
                 lambda: m.jog("X", float("nan"))):
        with pytest.raises(ValueError):
            call()


def test_unknown_tool_is_alarm_61343():
    m = SimulatedMachine(scenario())
    with pytest.raises(MachineAlarm) as err:
        m.change_tool(77, 10.0)
    assert err.value.alarm.code == 61343 and m.status().tool == 9


def test_reset_stops_the_spindle():
    m = SimulatedMachine(scenario())
    m.spindle_rotate(800.0)
    assert m.status().spindle_speed == 800.0
    m.reset()
    assert m.status().spindle_speed == 0.0
