"""The simulator's parts on their own: kinematics, contact, motion, the NC's data copy."""

import threading

import numpy as np
import pytest
from sim_helpers import rotation, scenario
from waiting import wait_until

from app.machine.contact import Contact
from app.machine.kinematics import Kinematics
from app.machine.motion import Motion
from app.machine.nc_data import NcData
from app.machine.protocol import MachineBusy, SimulatorControl, SwivelHead
from app.machine.sim import SimulatedMachine
from engine import alarms

SWIVEL = {"machine": {"kinematics": {"type": "swivel_head", "axes": ["A", "B"]}},
          "rotary_axes": {"A": {"limits": [-90, 90]}, "B": {"limits": [-90, 90]}}}


def test_the_simulator_offers_the_optional_interfaces():
    m = SimulatedMachine(scenario())
    assert isinstance(m, SwivelHead) and isinstance(m, SimulatorControl) and m.controller == "sim"


def test_load_gives_a_fresh_nc_copy():
    m = SimulatedMachine(scenario())
    m.write_offset("G54", {"trans": {"X": 1.0}})
    m.write_tool(1, {"type": 120, "length": 85.0, "radius": 5.0})
    assert m.nc_offsets["G54"] == {"trans": {"X": 1.0}, "fine": {}, "rot": {}}
    assert m.nc_tools[1]["wear"] == {"length": 0.0, "radius": 0.0}
    m.load(scenario())
    assert m.nc_offsets == {} and m.nc_tools == {}


def test_nc_data_holds_only_the_machine_axes():
    nc = NcData(("X", "Y", "Z", "C"))
    nc.write_offset("G54", {"trans": {"C": 12.0}})
    with pytest.raises(ValueError, match=r"trans\.B"):
        nc.write_offset("G54", {"trans": {"B": 1.0}})
    with pytest.raises(ValueError, match=r"fine\.C"):
        nc.write_offset("G54", {"fine": {"C": 1.0}})
    with pytest.raises(ValueError, match="t:"):
        nc.write_tool(True, {"type": 120, "length": 1.0, "radius": 1.0})
    assert nc.offsets == {"G54": {"trans": {"C": 12.0}, "fine": {}, "rot": {}}}


def test_kinematics_of_the_swivel_head():
    sc = scenario(probe={"t": 9, "ball_diameter": 4.0, "length": 100.0, "eccentricity": [0.01, 0.0]}, **SWIVEL)
    kin = Kinematics(sc)
    position = np.array([10.0, 20.0, 30.0, 0.0, -30.0])            # X Y Z A B
    r_head = rotation((0.0, -30.0, 0.0))
    assert kin.tool_axis(position) == pytest.approx(r_head @ [0, 0, 1], abs=1e-12)
    assert kin.ball_centre(position, 0.0) == pytest.approx(position[:3] + r_head @ [0.01, 0.0, -100.0], abs=1e-12)
    assert kin.head_angles_for(r_head @ [0, 0, 1], np.zeros(5)) == pytest.approx({"A": 0.0, "B": -30.0}, abs=1e-9)
    alarm = kin.limit_alarm(np.array([0.0, 0.0, 0.0, 95.0, 0.0]))
    assert alarm.is_(alarms.SOFTWARE_LIMIT) and "A" in alarm.text
    assert kin.limit_alarm(position) is None


def test_contact_of_the_probe_and_of_an_empty_spindle():
    sc = scenario(probe={"t": 9, "ball_diameter": 4.0, "length": 100.0, "pretravel": {"Z-": 0.002}})
    kin = Kinematics(sc)
    contact = Contact(sc, kin)
    top = np.asarray(sc.workpiece.pose.trans)                      # the part's origin: top-front-left corner
    inside = rotation(sc.workpiece.pose.rot) @ np.array([100.0, 60.0, 0.0]) + top
    start = np.array([inside[0], inside[1], inside[2] + 2.0 + 10.0 + 100.0])
    down = np.array([0.0, 0.0, -1.0])
    event = contact.first_event(start, down, 20.0, 9, 0.0)
    assert event.kind == "switch" and event.s_contact == pytest.approx(10.0, abs=1e-9)
    assert event.s_switch == pytest.approx(10.002, abs=1e-9)
    assert contact.first_event(start, down, 20.0, None, 0.0) is None
    assert contact.first_event(start, down, 5.0, 9, 0.0) is None   # the surface lies beyond the path


def test_motion_claims_the_axes_and_stops_a_timed_travel():
    lock = threading.RLock()
    motion = Motion(lock, np.zeros(3))
    reached, outcome = motion.travel(np.zeros(3), np.array([5.0, 0.0, 0.0]), lambda: 100.0, time_scale=0.0)
    assert outcome == "done" and list(motion.position) == [5.0, 0.0, 0.0]
    result = {}

    def timed_move():
        motion.begin()
        try:
            result["r"] = motion.travel(motion.position.copy(), np.array([105.0, 0.0, 0.0]), lambda: 600.0,
                                        time_scale=1.0)
        finally:
            motion.finish()

    worker = threading.Thread(target=timed_move)
    worker.start()
    wait_until(lambda: motion.position[0] > 5.0, "the timed move is under way")
    assert motion.busy
    with pytest.raises(MachineBusy):
        motion.begin()
    motion.stop()                            # waits until the travel has ended
    assert not motion.busy
    worker.join(2.0)
    position, outcome = result["r"]
    assert outcome == "stop" and 5.0 < position[0] < 10.0          # 10 mm/s for about 0.1 s
