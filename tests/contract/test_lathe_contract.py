"""The simulated lathe in the machine contract suite (issue 27 item 1).

The lathe is built as the HMI builds it (``registry.build_machine("sim", <lathe scenario>)``)
and driven through the ``Machine`` Protocol alone, checked against the analytic truth of
``LATHE`` (turning.md §10.2's example, time_scale 0, no latency, no pre-travel, no noise).

The contracts of test_machine_contract.py it keeps here: the Protocol and the status' shape,
goto/jog, limits refused before moving, continuous jog ended by stop, Reset, spindle, the
NC's data (and malformed data named), close, a probe move that touches nothing, a positioning
into the part. What it meets differently, with the reason:
- the probe's latch: the lathe's part is a turned profile, not the block; the latch is checked
  here on the cylinder (radius + clamping eccentricity + ball radius, measured along -X);
- the tool change's offset length and the WCS display: a lathe's NC takes L1/L2 from its own
  tool data (turning.md §10.2, lathe.py), not from the offset length: checked as
  ``P = F − (L1·x̂ + L2·ẑ)`` with the L1/L2 written by ``write_tool``;
- the axes: X (radius), Z and an optional Y, not X/Y/Z of a milling machine; without a Y axis
  the status still shows Y at 0 (``tuple(status().mcs) == axes`` does not hold there).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from app.machine.protocol import ActiveFrame, Alarm, Lathe, Machine, MachineAlarm, MachineStatus
from app.machine.registry import build_machine
from app.machine.scenario import load_scenario
from engine import alarms

LIMITS = {"X": [-50.0, 600.0], "Z": [-50.0, 800.0]}
PROBE_T, L1, L2, BALL_R = 8, 40.119, 100.456, 2.995          # the probe's true lengths and ball radius
CYLINDER_R, ECCENTRICITY_X = 45.006 / 2.0, 0.030              # the turned diameter, clamping eccentricity
LATHE = {
    "seed": 3,
    "machine": {"kind": "lathe", "diameter_programming": True, "spos": True, "limits": LIMITS, "time_scale": 0},
    "spindle": {"angle": 0.0},
    "tools": [{"t": 3, "type": 500, "sl": 3, "l1": 100.70, "l2": 60.30, "radius": 2.0}],
    "probe": {"t": PROBE_T, "type": 580, "sl": 7, "l1": L1, "l2": L2, "ball_diameter": 2 * BALL_R,
              "pretravel": {"X+": 0.0, "X-": 0.0, "Z-": 0.0}, "noise_sigma": 0.0},
    "workpiece": {"chuck_face_z": 0.0, "eccentricity": [ECCENTRICITY_X, 0.0], "face_runout_deg": 0.0,
                  "profile": [{"type": "cylinder", "z": [0, 60], "diameter": 2 * CYLINDER_R}]},
}
Z_MID = 30.0                                                  # halfway along the cylinder


@pytest.fixture
def lathe():
    machine = build_machine("sim", load_scenario(LATHE))
    yield machine
    machine.close()


def _f_for_ball(x: float, z: float) -> dict[str, float]:
    """Axis positions (F, MCS) that put the true ball centre at radius ``x``, ``z``."""
    return {"X": x + L1, "Z": z + L2}


def _over_the_cylinder(machine: Machine, ball_x: float) -> None:
    """Z first (turret out in X), then X down to the ball at ``ball_x`` over the middle of the cylinder."""
    assert machine.goto({"Z": _f_for_ball(0.0, Z_MID)["Z"]}).completed
    assert machine.goto({"X": _f_for_ball(ball_x, Z_MID)["X"]}).completed


def test_is_a_machine_and_a_lathe(lathe):
    assert isinstance(lathe, Machine) and isinstance(lathe, Lathe)
    assert lathe.controller == "sim" and tuple(lathe.axes) == ("X", "Z")
    assert lathe.diameter_programming is True and lathe.spos_capable is True


def test_status_shape_and_types(lathe):
    st = lathe.status()
    assert isinstance(st, MachineStatus)
    # differently from the milling contract: the status also shows Y, held at 0, on a lathe
    # without a Y axis (lathe_kinematics); a goto may name it with 0 only
    assert set(st.mcs) == set(lathe.axes) | {"Y"} and all(type(v) is float for v in st.mcs.values())
    assert st.mcs == {"X": LIMITS["X"][1], "Y": 0.0, "Z": LIMITS["Z"][1]}    # started retracted (lathe_scenario)
    assert st.tool == PROBE_T and st.busy is False and st.alarms == ()
    assert st.feed_override == 100.0 and st.spindle_speed == 0.0 and st.plane == "G18"


def test_goto_and_jog_reach_their_targets(lathe):
    result = lathe.goto({"X": 300.0}, 2000.0)
    assert result.completed and result.alarm is None
    assert result.mcs == pytest.approx({"X": 300.0, "Y": 0.0, "Z": LIMITS["Z"][1]}, abs=1e-9)
    assert lathe.jog("Z", -12.5).mcs["Z"] == pytest.approx(LIMITS["Z"][1] - 12.5, abs=1e-9)
    assert lathe.jog("X", 3.0, feed=500.0).mcs["X"] == pytest.approx(303.0, abs=1e-9)


@pytest.mark.parametrize("move", ["goto", "jog"])
def test_a_target_beyond_the_limits_is_refused_before_moving(lathe, move):
    before = lathe.status().mcs
    with pytest.raises(MachineAlarm) as err:
        if move == "goto":
            lathe.goto({"X": LIMITS["X"][1] + 10.0})
        else:
            lathe.jog("Z", 5.0)
    assert err.value.alarm.is_(alarms.SOFTWARE_LIMIT)
    assert lathe.status().mcs == before
    assert any(a.is_(alarms.SOFTWARE_LIMIT) for a in lathe.status().alarms)


def test_continuous_jog_ends_at_the_limit_or_stop_and_reset_clears_the_alarms(lathe):
    lathe.jog_continuous("X", -1, feed=2000.0)       # time_scale 0: at once onto the limit (Z clear of the part)
    lathe.stop()
    st = lathe.status()
    assert not st.busy and st.mcs["X"] == pytest.approx(LIMITS["X"][0], abs=1e-9)
    assert [a.code for a in st.alarms] == [alarms.SOFTWARE_LIMIT.number]
    lathe.post_alarm(Alarm.of(alarms.PROBE_NOT_SWITCHED, "Probe not switched (contract)"))
    lathe.spindle_rotate(500.0)
    assert [a.text for a in lathe.status().alarms][-1] == "Probe not switched (contract)"
    lathe.reset()
    st = lathe.status()
    assert st.alarms == () and st.spindle_speed == 0.0 and not st.busy


def test_spos_turns_the_part(lathe):
    lathe.spindle_position(90.0)
    assert lathe.status().spindle_angle == pytest.approx(90.0)
    lathe.spindle_position(450.0)
    assert lathe.status().spindle_angle == pytest.approx(90.0)


def test_the_reference_is_the_tool_data_written_to_the_nc(lathe):
    lathe.write_tool(PROBE_T, {"type": 580, "sl": 7, "length": 0.0, "radius": BALL_R, "l1": L1, "l2": L2})
    lathe.activate_frame(ActiveFrame())
    st = lathe.status()
    assert st.tool_length == pytest.approx(L1)
    assert st.wcs["X"] == pytest.approx(2.0 * (st.mcs["X"] - L1), abs=1e-9)      # DIAMON: a diameter
    assert st.wcs["Z"] == pytest.approx(st.mcs["Z"] - L2, abs=1e-9)
    frame = {"trans": {"X": 0.0, "Z": 250.0}}
    lathe.write_offset("G54", frame)
    assert lathe.nc_offsets["G54"]["trans"]["Z"] == 250.0
    assert lathe.nc_tools[PROBE_T]["l2"] == L2


@pytest.mark.parametrize("data, field", [
    ({"type": 500, "radius": 0.8, "l1": "x"}, "l1"),
    ({"type": 500, "sl": 12, "radius": 0.8}, "sl"),
    ({"type": 500}, "radius"),
])
def test_malformed_tool_data_is_a_value_error_naming_the_field(lathe, data, field):
    with pytest.raises(ValueError, match=field):
        lathe.write_tool(4, data)


def test_a_probe_move_latches_on_the_cylinder(lathe):
    """From the ball 40 mm off the axis, -X: the ball touches the turned surface at
    x = eccentricity (SPOS 0) + R_cylinder + r_ball (no latency, no pre-travel, no noise)."""
    _over_the_cylinder(lathe, 40.0)
    result = lathe.probe([-1.0, 0.0, 0.0], 30.0, 300.0)
    assert result.triggered
    assert result.latched_mcs["X"] - L1 == pytest.approx(ECCENTRICITY_X + CYLINDER_R + BALL_R, abs=1e-9)
    assert result.latched_mcs["Z"] == pytest.approx(Z_MID + L2, abs=1e-9)


def test_a_probe_move_that_touches_nothing_is_not_triggered(lathe):
    _over_the_cylinder(lathe, 40.0)
    result = lathe.probe([1.0, 0.0, 0.0], 5.0, 300.0)
    assert not result.triggered and result.latched_mcs is None
    assert result.end_mcs["X"] == pytest.approx(40.0 + L1 + 5.0, abs=1e-9)


def test_a_positioning_into_the_part_stops_with_the_collision_alarm(lathe):
    _over_the_cylinder(lathe, 40.0)
    result = lathe.goto({"X": _f_for_ball(10.0, Z_MID)["X"]}, 300.0)
    assert not result.completed and result.alarm.is_(alarms.PROBE_COLLISION)
    contact = ECCENTRICITY_X + CYLINDER_R + BALL_R + L1
    assert contact - 2.0 <= result.mcs["X"] <= contact + 1e-9          # stopped behind the contact, braking
    assert any(a.is_(alarms.PROBE_COLLISION) for a in lathe.status().alarms)
    assert math.isfinite(lathe.status().mcs["X"]) and not lathe.status().busy


def test_close_stops_and_may_be_called_again(lathe):
    lathe.jog_continuous("Z", -1, feed=1000.0)
    lathe.close()
    assert not lathe.status().busy
    lathe.close()
    assert np.isfinite(list(lathe.status().mcs.values())).all()
