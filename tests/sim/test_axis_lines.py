"""Rotary axes as lines (design.md §10.6): the simulator moves by the TRUE lines, the control
(status: tool axis, head shift) computes with its NOMINAL data; the scenario format only grows.

The expected values come from this file's own Rodrigues rotation (not the product's code).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from app.machine.scenario import load_scenario
from app.machine.sim import SimulatedMachine

PIVOT_A = np.array([0.0, 0.030, -0.020])          # mm: true A line misses the reference point
DIR_A = np.array([1.0, 25e-6, -40e-6])           # tens of µrad off X
PIVOT_B = np.array([0.015, 0.0, 0.040])
DIR_B = np.array([-30e-6, 1.0, 20e-6])


def rodrigues(d, deg) -> np.ndarray:
    d = np.asarray(d, float) / np.linalg.norm(d)
    t = math.radians(deg)
    k = np.array([[0, -d[2], d[1]], [d[2], 0, -d[0]], [-d[1], d[0], 0]])
    return np.eye(3) + math.sin(t) * k + (1 - math.cos(t)) * k @ k


def head_scenario(true: dict | None = None, nominal: dict | None = None) -> dict:
    head: dict = {"type": "swivel_head", "axes": ["A", "B"]}
    if true is not None:
        head["true"] = true
    if nominal is not None:
        head["nominal"] = nominal
    return {"machine": {"time_scale": 0, "limits": {"X": [-500, 500], "Y": [-500, 500], "Z": [-500, 500]},
                        "kinematics": head},
            "rotary_axes": {"A": {"limits": [-90, 90]}, "B": {"limits": [-90, 90]}},
            "probe": {"length": 100.0, "ball_diameter": 4.0}, "start": {"X": 0, "Y": 0, "Z": 200}}


TRUE = {"A": {"point": PIVOT_A.tolist(), "direction": DIR_A.tolist()},
        "B": {"point": PIVOT_B.tolist(), "direction": DIR_B.tolist()}}


def test_true_lines_move_the_ball_nominal_lines_drive_the_status():
    machine = SimulatedMachine(load_scenario(head_scenario(TRUE)))
    machine.goto({"A": 20.0, "B": -35.0})
    st = machine.status()
    axes = np.array([st.mcs["X"], st.mcs["Y"], st.mcs["Z"]])
    # truth: ball = A + T_B(θB)∘T_A(θA)(−L·ẑ), T(x) = p + R(d, θ)(x − p)
    v = np.array([0.0, 0.0, -100.0])
    inner = PIVOT_A + rodrigues(DIR_A, 20.0) @ (v - PIVOT_A)
    ball = axes + PIVOT_B + rodrigues(DIR_B, -35.0) @ (inner - PIVOT_B)
    got = machine._kinematics.ball_centre(machine._motion.position, 0.0)
    assert np.linalg.norm(got - ball) < 1e-9
    # the control holds the nominal (ideal) head: tool axis Ry(B)·Rx(A)·ẑ, no shift
    nominal_axis = rodrigues([0, 1, 0], -35.0) @ rodrigues([1, 0, 0], 20.0) @ np.array([0, 0, 1.0])
    assert np.linalg.norm(np.array(st.tool_axis) - nominal_axis) < 1e-12
    assert st.head_shift == (0.0, 0.0, 0.0)
    # the difference the kinematic error makes: tens of µm here
    assert 0.01 < np.linalg.norm(ball - (axes - 100.0 * nominal_axis)) < 0.2


def test_written_kinematic_data_drive_the_status():
    machine = SimulatedMachine(load_scenario(head_scenario(TRUE)))
    machine.write_kinematic_data(TRUE)
    machine.goto({"A": -15.0, "B": 40.0})
    st = machine.status()
    axes = np.array([st.mcs["X"], st.mcs["Y"], st.mcs["Z"]])
    nc_tip = axes + np.array(st.head_shift) - 100.0 * np.array(st.tool_axis)
    true_ball = machine._kinematics.ball_centre(machine._motion.position, 0.0)
    assert np.linalg.norm(nc_tip - true_ball) < 1e-9
    assert set(machine.kinematic_data()) == {"A", "B"}
    with pytest.raises(ValueError, match="C"):
        machine.write_kinematic_data({"C": {"point": [0, 0, 0], "direction": [0, 0, 1]}})


def test_ideal_lines_are_the_wave2_head_and_old_scenarios_load():
    plain = SimulatedMachine(load_scenario(head_scenario()))
    plain.goto({"A": 30.0, "B": 10.0})
    lines = plain.kinematic_data()
    assert lines["A"] == {"point": [0.0, 0.0, 0.0], "direction": [1.0, 0.0, 0.0], "unit": "head"}
    assert lines["B"]["direction"] == [0.0, 1.0, 0.0]
    st = plain.status()
    axes = np.array([st.mcs["X"], st.mcs["Y"], st.mcs["Z"]])
    expected = axes + rodrigues([0, 1, 0], 10.0) @ rodrigues([1, 0, 0], 30.0) @ np.array([0, 0, -100.0])
    assert np.linalg.norm(plain._kinematics.ball_centre(plain._motion.position, 0.0) - expected) < 1e-12


@pytest.mark.parametrize("bad, field", [
    ({"C": {"point": [0, 0, 0], "direction": [0, 0, 1]}}, "kinematics.true"),
    ({"A": {"point": [0, 0, 0], "direction": [0, 0, 0]}}, "direction"),
])
def test_bad_lines_are_refused_naming_the_field(bad, field):
    with pytest.raises(ValueError, match=field):
        load_scenario(head_scenario(bad))


def test_rotary_table_turns_the_part_about_its_true_line():
    from app.machine.scene import workpiece_pose
    true_point, true_dir = np.array([300.0, 200.0, 0.0]) + [0.02, -0.03, 0.0], np.array([30e-6, -10e-6, 1.0])
    sc = load_scenario({
        "machine": {"time_scale": 0, "rotary_table": {"axis": "C", "center": [300, 200],
                                                      "true": {"C": {"point": true_point.tolist(),
                                                                     "direction": true_dir.tolist()}}}},
        "rotary_axes": {"C": {"limits": [-360, 360]}},
        "workpiece": {"pose": {"trans": [250, 150, -100], "rot": [0, 0, 0]},
                      "features": [{"type": "sphere", "center": [80, 0, 20], "diameter": 25}]}})
    rot, trans = workpiece_pose(sc, 50.0)
    turn = rodrigues(true_dir, -50.0)                      # DIN 66217: the part turns by −angle
    assert np.linalg.norm(rot - turn) < 1e-12
    assert np.linalg.norm(trans - (true_point + turn @ (np.array([250, 150, -100.0]) - true_point))) < 1e-9
