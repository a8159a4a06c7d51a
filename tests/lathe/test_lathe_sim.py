"""The simulated lathe against analytic geometry (turning.md §11), through the Machine Protocol.

No engine here: every expected value is the closed-form contact of a ball (the probe, or a
tool's nose) with the scenario's solids: an eccentric cylinder turning with SPOS, a bore, a
tilted face, the tool probe cube, the groove rings, the chuck.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from lathe_kit import LATHE_SCENARIO, lathe_scenario

from app.machine.lathe import LatheMachine
from app.machine.lathe_kinematics import SL_DIRECTION
from app.machine.protocol import Machine, MachineAlarm, SimulatorControl
from app.machine.registry import build_machine
from app.machine.scenario import load_scenario
from engine import alarms

PROBE = LATHE_SCENARIO["probe"]
R_BALL = PROBE["ball_diameter"] / 2
R_OD, R_BORE = 45.006 / 2, 35.004 / 2
FEED = 150.0


def machine(**changes) -> LatheMachine:
    m = build_machine("sim", load_scenario(lathe_scenario(**changes)))
    assert isinstance(m, LatheMachine)
    return m


def ball_at(m: LatheMachine, x: float, z: float) -> None:
    """True ball centre to (x, z): F = centre + true (l1, l2); Z first, then X (clear paths)."""
    m.goto({"Z": z + PROBE["l2"]})
    m.goto({"X": x + PROBE["l1"]})


def latched_centre(m: LatheMachine, direction, distance: float = 10.0) -> np.ndarray:
    result = m.probe(direction, distance, FEED)
    assert result.triggered
    f = result.latched_mcs
    return np.array([f["X"] - PROBE["l1"], f["Y"], f["Z"] - PROBE["l2"]])


def test_the_registry_builds_the_lathe_for_a_lathe_scenario():
    m = machine()
    assert isinstance(m, Machine) and isinstance(m, SimulatorControl)
    assert m.controller == "sim" and m.kind == "lathe" and m.axes == ("X", "Z")
    assert build_machine("sim", load_scenario({})).__class__.__name__ == "SimulatedMachine"
    status = m.status()
    assert status.plane == "G18" and status.tool == PROBE["t"] and status.mcs == {"X": 600.0, "Y": 0.0, "Z": 800.0}


@pytest.mark.parametrize("angle", [0.0, 90.0, 180.0, 270.0, 33.0])
@pytest.mark.parametrize("ecc", [(0.030, 0.0), (0.0, 0.030), (0.021, -0.013)])
def test_eccentric_od_turning_with_the_spindle(angle, ecc):
    """x = e_x(φ) + sqrt((R + r)² − e_y(φ)²) for the ball travelling −X at Y 0 (turning.md §11)."""
    m = machine(workpiece__eccentricity=list(ecc))
    m.spindle_position(angle)
    ball_at(m, 30.0, 30.0)
    phi = math.radians(angle)
    ex = ecc[0] * math.cos(phi) - ecc[1] * math.sin(phi)
    ey = ecc[0] * math.sin(phi) + ecc[1] * math.cos(phi)
    c = latched_centre(m, [-1, 0, 0])
    assert c[0] == pytest.approx(ex + math.sqrt((R_OD + R_BALL) ** 2 - ey ** 2), abs=1e-9)


def test_bore_from_inside_and_the_opposite_wall():
    """Inside the bore (z 20..60) the ball travelling +X meets x = e_x + sqrt((R_b − r)² − e_y²)."""
    m = machine()
    m.goto({"Z": 100.0 + PROBE["l2"]})
    m.goto({"X": 0.0 + PROBE["l1"]})
    m.goto({"Z": 40.0 + PROBE["l2"]})                         # into the bore on the axis
    assert latched_centre(m, [1, 0, 0], 20.0)[0] == pytest.approx(0.030 + (R_BORE - R_BALL), abs=1e-9)
    m.goto({"X": 0.0 + PROBE["l1"]})
    assert latched_centre(m, [-1, 0, 0], 20.0)[0] == pytest.approx(0.030 - (R_BORE - R_BALL), abs=1e-9)


@pytest.mark.parametrize("tau, angle", [(0.0, 0.0), (0.2, 0.0), (0.2, 90.0), (-0.3, 200.0)])
def test_face_with_run_out(tau, angle):
    """The face z = 60 of the part tilted by τ towards (cos φ, sin φ) about the chuck face centre:
    the ball travelling −Z at radius 20 touches the plane n·(c − p0) = r exactly."""
    m = machine(workpiece__face_runout_deg=tau)
    m.spindle_position(angle)
    ball_at(m, 20.0, 80.0)
    c = latched_centre(m, [0, 0, -1], 30.0)
    phi, t = math.radians(angle), math.radians(tau)
    n = np.array([-math.cos(phi) * math.sin(t), -math.sin(phi) * math.sin(t), math.cos(t)])
    base = np.array([0.030 * math.cos(phi), 0.030 * math.sin(phi), 0.0])
    p0 = base + 60.0 * n
    # c(s) = (20, 0, 80 − s): n·(c − p0) = r -> s
    c0 = np.array([20.0, 0.0, 80.0])
    s = (n @ (c0 - p0) - R_BALL) / n[2]
    assert c[2] == pytest.approx(80.0 - s, abs=1e-9)


@pytest.mark.parametrize("sl", range(1, 10))
@pytest.mark.parametrize("face", ["X-", "Z-"])
def test_tool_nose_on_the_tool_probe(sl, face):
    """The nose circle (centre S = P − R·s) touches the face with its leading point S + d·R:
    P = face − (d − s)·R on the travel axis (turning.md §0.5); F = P + (L1, L2)."""
    faces = LATHE_SCENARIO["tool_probe"]["faces"]
    tool = {"t": 5, "type": 500, "sl": sl, "l1": 50.0, "l2": 20.0, "radius": 1.2}
    m = machine(tools=[tool])
    m.change_tool(5, 0.0)
    sx, sz = SL_DIRECTION[sl]
    axis, d = face[0], -1
    centre = {"X": (faces["X-"] + faces["X+"]) / 2, "Z": (faces["Z-"] + faces["Z+"]) / 2}
    if axis == "X":                   # above the probe, nose centre over its Z centre
        m.goto({"X": 420.0 + tool["l1"]})
        m.goto({"Z": centre["Z"] + sz * tool["radius"] + tool["l2"]})
    else:                             # right of the probe, nose centre at its X centre
        m.goto({"X": 420.0 + tool["l1"]})
        m.goto({"Z": 240.0 + tool["l2"]})
        m.goto({"X": centre["X"] + sx * tool["radius"] + tool["l1"]})
    result = m.probe([-1, 0, 0] if axis == "X" else [0, 0, -1], 30.0, FEED)
    assert result.triggered
    s = sx if axis == "X" else sz
    tip = faces[face] - (d - s) * tool["radius"]
    length = tool["l1"] if axis == "X" else tool["l2"]
    assert result.latched_mcs[axis] - length == pytest.approx(tip, abs=1e-9)


def test_pre_travel_by_travel_direction_and_latency():
    """The probe switches p(d) after contact; with latency the latch lies v·t further."""
    m = machine(probe__pretravel={"X-": 0.004, "X+": 0.002, "Z-": 0.003}, machine__latency_s=0.004)
    ball_at(m, 30.0, 30.0)
    c = latched_centre(m, [-1, 0, 0])
    assert c[0] == pytest.approx(0.030 + R_OD + R_BALL - 0.004 - FEED / 60.0 * 0.004, abs=1e-9)


def test_collisions_while_positioning():
    """A switch during positioning is 61302 (part, chuck, groove, tool probe); a tool hitting the
    part stops at the contact."""
    m = machine()
    ball_at(m, 30.0, 30.0)
    slow = 50.0                                           # braking inside the permissible deflection
    result = m.goto({"X": 20.0 + PROBE["l1"]}, slow)
    assert not result.completed and result.alarm.is_(alarms.PROBE_COLLISION)
    assert "workpiece" in result.alarm.text
    m.reset()
    m.goto({"X": 30.0 + PROBE["l1"]})
    m.goto({"Z": 80.0 + PROBE["l2"]})
    m.goto({"X": 40.0 + PROBE["l1"]})                     # radius 40: between the part and the grooves
    result = m.goto({"Z": -10.0 + PROBE["l2"]}, slow)     # down past the part onto the chuck face
    assert not result.completed and "chuck" in result.alarm.text
    assert result.mcs["Z"] - PROBE["l2"] == pytest.approx(R_BALL, abs=0.1)
    m.reset()
    m.goto({"Z": 80.0 + PROBE["l2"]})
    m.goto({"X": 48.0 + PROBE["l1"]})                     # over the SL 7 inner wall ring (45.054..50.054)
    result = m.goto({"Z": 10.0 + PROBE["l2"]}, slow)
    assert not result.completed and "groove" in result.alarm.text
    m.reset()
    m.goto({"Z": 80.0 + PROBE["l2"]})
    m.goto({"X": 20.0 + PROBE["l1"]})                     # over the face ring between the bore and the OD
    result = m.goto({"Z": 30.0 + PROBE["l2"]})            # rapid onto the part's face: the stylus breaks
    assert not result.completed
    with pytest.raises(MachineAlarm) as err:
        m.goto({"Z": 100.0 + PROBE["l2"]})
    assert err.value.alarm.is_(alarms.PROBE_BROKEN)
    m.change_tool(PROBE["t"], 0.0)                        # a new stylus
    m.reset()
    m.goto({"Z": 800.0})
    m.change_tool(3, 0.0)
    tool = LATHE_SCENARIO["tools"][1]
    m.goto({"X": 30.0 + tool["l1"]})
    m.goto({"Z": 30.0 + tool["l2"]})
    result = m.goto({"X": 20.0 + tool["l1"]})             # the tip into the shaft: a crash at the contact
    assert not result.completed and "T3 hit the workpiece" in result.alarm.text
    nose_bottom = result.mcs["X"] - tool["l1"] + tool["radius"] - tool["radius"]   # SL 3: P is the lowest point
    assert nose_bottom == pytest.approx(0.030 + R_OD, abs=1e-9)


def test_spos_turns_the_part_and_is_refused_into_the_probe():
    m = machine(workpiece__eccentricity=[0.5, 0.0])
    ball_at(m, R_OD + 0.5 + R_BALL + 0.2, 30.0)            # 0.2 above the part at 0°
    m.spindle_position(90.0)                                # the part swings sideways: free
    with pytest.raises(MachineAlarm) as err:
        m.goto({"X": R_OD + R_BALL + 0.3 + PROBE["l1"]})    # fine at 90°: e_x = 0 -> 0.3 clearance
        m.spindle_position(0.0)                             # back to 0°: the part would hit the ball
    assert err.value.alarm.is_(alarms.PROBE_COLLISION)
    assert m.status().spindle_angle == 90.0
    no_spos = machine(machine__spos=False)
    with pytest.raises(MachineAlarm) as err:
        no_spos.spindle_position(180.0)
    assert err.value.alarm.code == alarms.NEEDS_SPOS.number


def test_axes_limits_and_the_missing_y():
    m = machine()
    with pytest.raises(ValueError):
        m.jog("Y", 1.0)
    with pytest.raises(ValueError):
        m.goto({"Y": 5.0})
    with pytest.raises(MachineAlarm) as err:
        m.goto({"X": 700.0})
    assert err.value.alarm.is_(alarms.SOFTWARE_LIMIT)
    y = machine(machine__limits={"X": [-50, 600], "Y": [-20, 20], "Z": [-50, 800]})
    assert y.axes == ("X", "Y", "Z")
    y.jog("Y", 5.0)
    assert y.status().mcs["Y"] == 5.0


def test_status_shows_the_nc_reference_with_diamon():
    """P = F − (L1, L2) of the NC's tool data; WCS X a diameter with diameter programming."""
    m = machine()
    m.write_tool(8, {"type": 580, "sl": 7, "length": 0.0, "radius": 3.0, "l1": 40.123, "l2": 100.456,
                     "wear": {"l1": 0.001}})
    st = m.status()
    assert st.tool_lengths == pytest.approx((40.124, 100.456))
    assert st.wcs["X"] == pytest.approx(2 * (600.0 - 40.124)) and st.wcs["Z"] == pytest.approx(800.0 - 100.456)
    with pytest.raises(ValueError, match="sl"):
        m.write_tool(8, {"type": 580, "sl": 12, "radius": 3.0})
    radius = machine(machine__diameter_programming=False)
    radius.write_tool(8, {"type": 580, "sl": 7, "radius": 3.0, "l1": 40.0, "l2": 100.0})
    assert radius.status().wcs["X"] == pytest.approx(560.0)


def test_machined_part_follows_the_nc_length():
    """turning.md §11: r_cut = r_programmed + (L1_NC − L1_true); the tool wears per part."""
    profile = [{"type": "cylinder", "z": [0, 60], "diameter": 45.0, "machined_by": {"t": 1}}]
    tools = [{"t": 1, "type": 500, "sl": 3, "l1": 60.0, "l2": 30.0, "radius": 0.8, "wear_per_part": {"l1": 0.002}}]
    m = machine(workpiece__profile=profile, tools=tools)
    m.write_tool(1, {"type": 500, "sl": 3, "radius": 0.8, "l1": 60.010, "l2": 30.0})
    assert m.machine_part() == 1
    assert m.part_diameters[0] == pytest.approx(45.020, abs=1e-12)
    assert m.machine_part() == 2
    assert m.part_diameters[0] == pytest.approx(45.024, abs=1e-12)      # 2 µm shorter: Ø +4 µm more
    ball_at(m, 30.0, 30.0)
    assert latched_centre(m, [-1, 0, 0])[0] == pytest.approx(0.030 + 45.024 / 2 + R_BALL, abs=1e-9)


@pytest.mark.parametrize("changes, message", [
    ({"grooves": [{"sl7": {"x_minus": 10.0, "x_plus": 20.0, "bottom_z": 15.0}}]}, "overlaps the workpiece"),
    ({"grooves": [{"sl8": {"z_minus": 2.0, "z_plus": 8.0, "top_x": 120.0, "bottom_x": 110.0}}]}, "into the chuck"),
    ({"tool_probe": {"faces": {"Z-": 50, "Z+": 40, "X-": 20, "X+": 10}}}, "overlaps the workpiece"),
    ({"workpiece": {"pose": {}}}, "workpiece.pose"),
    ({"probe": {"t": 8, "l1": 40, "l2": 100, "sl": 3}}, "probe.sl"),
    ({"tool_probe": {"faces": {"Z-": 220.35, "Z+": 199.65, "X-": 400.25}}}, "tool_probe.faces"),
])
def test_a_scenario_the_lathe_cannot_play_is_refused(changes, message):
    data = {**lathe_scenario(), **changes}
    with pytest.raises(ValueError, match=message):
        load_scenario(data)


def test_the_lathe_fields_need_machine_kind_lathe():
    with pytest.raises(ValueError, match="machine.diameter_programming"):
        load_scenario({"machine": {"diameter_programming": True}})
    with pytest.raises(ValueError, match="grooves"):
        load_scenario({"grooves": []})
    with pytest.raises(ValueError, match="machine.kind"):
        load_scenario({"machine": {"kind": "grinder"}})
    assert load_scenario({"machine": {"kind": "mill"}}).kind == "mill"
