"""The contract every controller behind the HMI keeps: tests against the ``Machine`` Protocol alone.

Each test drives a machine only through the Protocol's members (app/machine/protocol.py) and
checks it against the analytic geometry of ``CONTRACT_SCENARIO`` (the scenario format of
design.md §4, which every implementation takes: the simulator plays it, a real controller's
probe input is fed from it). Alarms are named from the catalogue (``engine.alarms``).

The suite runs once per entry of ``IMPLEMENTATIONS``; the machine is built by its registry
name (``app.machine.registry.build_machine``), as the HMI builds it. A new controller (the
LinuxCNC adapter) adds itself with one entry, e.g.::

    Implementation("linuxcnc", position_tol=1e-4, latch_tol=2e-3, marks=(needs_linuxcnc,)),

``position_tol``/``latch_tol`` say how close its moves end and its probe latches to the truth
(the simulator is exact), ``marks`` may skip it where the controller is not installed, and
``read_offset``/``read_tool`` say how to read back what ``write_offset``/``write_tool`` wrote
(the Protocol itself offers no read-back; None skips that check), ``held_offset``/``held_tool``
what of a written frame/tool the controller holds, in the shape the readers return (the
simulator: all of it; LinuxCNC: trans + fine and the rotation about Z, length + wear and the
diameter). The simulator runs at
``time_scale`` 0 (the scenario's), a real controller in real time: keep the moves short.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pytest

from app.machine.protocol import (
    ActiveFrame,
    Alarm,
    Machine,
    MachineAlarm,
    MachineStatus,
    MoveResult,
    ProbeResult,
)
from app.machine.registry import build_machine
from app.machine.scenario import load_scenario
from engine import alarms


@dataclass(frozen=True)
class Implementation:
    name: str                                     # its name in app.machine.registry
    position_tol: float = 1e-9                    # mm: a move ends this close to its target
    latch_tol: float = 1e-9                       # mm: a latch lies this close to the analytic value
    read_offset: Callable[[Machine, str], dict] | None = None
    read_tool: Callable[[Machine, int], dict] | None = None
    marks: tuple = ()
    held_offset: Callable[[dict], dict] = lambda frame: frame
    held_tool: Callable[[dict], dict] = lambda tool: tool
    readback_tol: float = 0.0                     # mm: how close the read-back is (0: exactly as written)


def _linuxcnc_g5x(frame: dict) -> dict:
    """What LinuxCNC's G5x holds of a frame: trans + fine per axis, the rotation about Z (R)."""
    return {"trans": {a: frame["trans"].get(a, 0.0) + frame.get("fine", {}).get(a, 0.0) for a in "XYZ"},
            "rot": {"Z": frame.get("rot", {}).get("Z", 0.0)}}


def _linuxcnc_tool(tool: dict) -> dict:
    """What LinuxCNC's tool table holds: Z = length + wear, D = 2·(radius + wear)."""
    wear = tool.get("wear", {})
    return {"length": tool["length"] + wear.get("length", 0.0),
            "diameter": 2.0 * (tool["radius"] + wear.get("radius", 0.0))}


def _linuxcnc_installed() -> bool:
    from app.machine.linuxcnc.modules import available

    return available()


needs_linuxcnc = pytest.mark.skipif(not _linuxcnc_installed(), reason="LinuxCNC is not installed "
                                    "(apt-get install linuxcnc-uspace linuxcnc-uspace-dev; scripts/test.sh does)")

IMPLEMENTATIONS = [
    Implementation("sim", read_offset=lambda m, name: m.nc_offsets[name], read_tool=lambda m, t: m.nc_tools[t]),
    # real time, its own latch (interpolated in the servo period): µm, not 1e-9; G5x read back
    # through LinuxCNC's parameters (6 decimals)
    Implementation("linuxcnc", position_tol=1e-6, latch_tol=1e-4, read_offset=lambda m, name: m.nc_offset(name),
                   read_tool=lambda m, t: m.nc_tool(t), held_offset=_linuxcnc_g5x, held_tool=_linuxcnc_tool,
                   readback_tol=1e-6, marks=(needs_linuxcnc, pytest.mark.linuxcnc)),
]

# --- the truth --------------------------------------------------------------------------------
L_PROBE = 100.0                   # true probe length (spindle nose to ball centre)
R_BALL = 2.0
ECCENTRICITY = np.array([0.010, -0.006, 0.0])         # at SPOS 0
PRETRAVEL = {"X+": 0.004, "X-": 0.005, "Y+": 0.003, "Y-": 0.006, "Z-": 0.002}
LATENCY_S = 0.004
BLOCK_ROT_Z = 10.0                # deg about Z
BLOCK_TRANS = np.array([200.0, 100.0, -150.0])       # top-front-left corner, MCS
BLOCK_SIZE = (200.0, 120.0, 60.0)
CUTTER = {"t": 1, "type": 120, "length": 85.0, "radius": 5.0}
START = {"X": 0.0, "Y": 0.0, "Z": 50.0}
LIMITS = {"X": [-50.0, 600.0], "Y": [-50.0, 400.0], "Z": [-300.0, 100.0]}
FEED = 300.0                      # mm/min, measuring feed

CONTRACT_SCENARIO = {
    "seed": 1,
    "machine": {"limits": LIMITS, "rapid": 10000.0, "jog_feed": 1000.0, "latency_s": LATENCY_S,
                "decel": 1.0, "kv": 1.0, "time_scale": 0.0},
    "probe": {"t": 9, "ball_diameter": 2 * R_BALL, "length": L_PROBE, "eccentricity": list(ECCENTRICITY[:2]),
              "pretravel": PRETRAVEL, "noise_sigma": 0.0, "max_deflection": 5.0},
    "workpiece": {"pose": {"trans": list(BLOCK_TRANS), "rot": [0.0, 0.0, BLOCK_ROT_Z]},
                  "features": [{"type": "block", "size": list(BLOCK_SIZE)}]},
    "tools": [CUTTER],
    "start": START,
}
XYZ = ("X", "Y", "Z")
Z_UP = np.array([0.0, 0.0, 1.0])


def _rot_z(deg: float) -> np.ndarray:
    c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _on_block(x: float, y: float, z: float) -> np.ndarray:
    """A point given in block coordinates (origin top-front-left, z up), in MCS."""
    return _rot_z(BLOCK_ROT_Z) @ np.array([x, y, z]) + BLOCK_TRANS


def _pretravel(d: np.ndarray) -> float:
    """p(d) = Σ d_i²·p(axis_i, sign d_i) (design.md §5)."""
    return sum(d[i] ** 2 * PRETRAVEL.get(f"{a}{'+' if d[i] > 0 else '-'}", 0.0) for i, a in enumerate(XYZ) if d[i])


def _axes_for_ball(centre: np.ndarray) -> dict[str, float]:
    """Axis positions that put the true ball centre at ``centre`` (SPOS 0, tool axis +Z)."""
    return dict(zip(XYZ, (centre - ECCENTRICITY + L_PROBE * Z_UP).tolist(), strict=True))


def _xyz(mcs: dict) -> np.ndarray:
    return np.array([mcs[a] for a in XYZ])


# --- fixtures ---------------------------------------------------------------------------------
@pytest.fixture(params=[pytest.param(i, id=i.name, marks=i.marks) for i in IMPLEMENTATIONS])
def implementation(request) -> Implementation:
    return request.param


@pytest.fixture
def machine(implementation):
    m = build_machine(implementation.name, load_scenario(CONTRACT_SCENARIO))
    m.change_tool(9, L_PROBE)                        # the probe in the spindle, its true length
    m.spindle_position(0.0)
    yield m
    m.close()


@pytest.fixture
def tol(implementation) -> Implementation:
    return implementation


def _goto(machine: Machine, target: dict[str, float], feed: float | None = None) -> MoveResult:
    """Positioning that must arrive; clear above the block first when going down to it."""
    result = machine.goto(target, feed)
    assert result.completed, result.alarm
    return result


def _above_block(machine: Machine, x: float, y: float, clearance: float) -> None:
    """The ball centre ``clearance`` above the top face at block point (x, y)."""
    _goto(machine, {"Z": START["Z"]})
    _goto(machine, _axes_for_ball(_on_block(x, y, R_BALL + clearance)))


def _in_front_of_block(machine: Machine, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """The ball ``gap`` in front of the block's front face (mid-length, 30 mm down): (face point, normal)."""
    p_face = _on_block(BLOCK_SIZE[0] / 2, 0.0, -30.0)
    n = _rot_z(BLOCK_ROT_Z) @ np.array([0.0, -1.0, 0.0])
    centre = p_face + (R_BALL + gap) * n
    _goto(machine, {"Z": START["Z"]})
    _goto(machine, {a: v for a, v in _axes_for_ball(centre).items() if a != "Z"})
    _goto(machine, _axes_for_ball(centre))
    return p_face, n


def _has(status: MachineStatus, definition) -> bool:
    return any(a.is_(definition) for a in status.alarms)


# --- status -----------------------------------------------------------------------------------
def test_implements_the_protocol(machine):
    assert isinstance(machine, Machine)
    assert machine.controller in ("sim", "linuxcnc") and isinstance(machine.controller, str)
    assert tuple(machine.axes[:3]) == XYZ and all(a in "ABC" for a in machine.axes[3:])


def test_status_shape_and_types(machine):
    st = machine.status()
    assert isinstance(st, MachineStatus)
    assert tuple(st.mcs) == tuple(machine.axes) and all(type(v) is float for v in st.mcs.values())
    assert set(XYZ) <= set(st.wcs) and all(type(v) is float for v in st.wcs.values())
    assert isinstance(st.active_offset, str) and st.active_offset
    assert st.tool == 9 and type(st.tool_length) is float and st.tool_length == pytest.approx(L_PROBE)
    for value in (st.feed_override, st.spindle_angle, st.spindle_speed):
        assert type(value) is float
    assert st.feed_override == 100.0 and st.spindle_speed == 0.0
    assert st.busy is False and st.alarms == ()
    assert isinstance(st.mode, str) and isinstance(st.plane, str)
    assert len(st.tool_axis) == 3 and np.linalg.norm(st.tool_axis) == pytest.approx(1.0)


# --- motion -----------------------------------------------------------------------------------
def test_goto_reaches_its_target_and_keeps_missing_axes(machine, tol):
    result = machine.goto({"X": 40.0, "Y": -20.0}, 2000.0)
    assert isinstance(result, MoveResult) and result.completed and result.alarm is None
    assert _xyz(result.mcs) == pytest.approx([40.0, -20.0, START["Z"]], abs=tol.position_tol)
    rapid = machine.goto({"Z": 20.0})
    assert rapid.completed and rapid.mcs["Z"] == pytest.approx(20.0, abs=tol.position_tol)
    assert _xyz(machine.status().mcs) == pytest.approx([40.0, -20.0, 20.0], abs=tol.position_tol)


def test_jog_moves_one_axis_by_its_distance(machine, tol):
    before = machine.status().mcs
    result = machine.jog("Y", -12.5)
    assert result.completed and result.alarm is None
    assert result.mcs["Y"] == pytest.approx(before["Y"] - 12.5, abs=tol.position_tol)
    assert result.mcs["X"] == pytest.approx(before["X"], abs=tol.position_tol)
    result = machine.jog("X", 3.0, feed=500.0)
    assert result.mcs["X"] == pytest.approx(before["X"] + 3.0, abs=tol.position_tol)


@pytest.mark.parametrize("move", ["goto", "jog"])
def test_a_target_beyond_the_limits_is_refused_with_the_limit_alarm(machine, move):
    before = machine.status().mcs
    with pytest.raises(MachineAlarm) as err:
        if move == "goto":
            machine.goto({"X": LIMITS["X"][1] + 10.0})
        else:
            machine.jog("Z", LIMITS["Z"][1] - before["Z"] + 5.0)
    assert err.value.alarm.is_(alarms.SOFTWARE_LIMIT)
    assert machine.status().mcs == before                      # refused before moving
    assert _has(machine.status(), alarms.SOFTWARE_LIMIT)


def test_continuous_jog_ends_with_stop(machine):
    before = machine.status().mcs
    machine.jog_continuous("X", -1, feed=2000.0)
    machine.stop()
    st = machine.status()
    assert not st.busy
    assert LIMITS["X"][0] - 1e-6 <= st.mcs["X"] <= before["X"]
    machine.stop()                                             # stop while idle is harmless


# --- probing ----------------------------------------------------------------------------------
def test_probe_down_latches_on_the_top_face(machine, tol):
    _above_block(machine, 100.0, 60.0, clearance=10.0)
    start = _xyz(machine.status().mcs)
    d = np.array([0.0, 0.0, -1.0])
    result = machine.probe(d, 20.0, FEED)
    assert isinstance(result, ProbeResult) and result.triggered
    assert result.feed == FEED and result.override == 100.0
    expected = start + (10.0 + _pretravel(d) + FEED / 60.0 * LATENCY_S) * d
    assert _xyz(result.latched_mcs) == pytest.approx(expected, abs=tol.latch_tol)
    assert (_xyz(result.end_mcs) - start) @ d >= (_xyz(result.latched_mcs) - start) @ d - tol.latch_tol


def test_probe_at_an_angle_to_the_axes_latches_on_the_rotated_face(machine, tol):
    """Contact of the eccentric ball with the rotated front face, then pre-travel p(d) and v·t."""
    _p_face, n = _in_front_of_block(machine, gap=10.0)
    start = _xyz(machine.status().mcs)
    d = -n
    result = machine.probe(d, 20.0, FEED)
    assert result.triggered
    expected = start + (10.0 + _pretravel(d) + FEED / 60.0 * LATENCY_S) * d
    assert _xyz(result.latched_mcs) == pytest.approx(expected, abs=tol.latch_tol)


def test_override_scales_the_feed_in_effect(machine, tol):
    """At 50 % a probing feed of 600 latches where 300 at 100 % does (latency path v·t)."""
    _above_block(machine, 60.0, 40.0, clearance=10.0)
    start = machine.status().mcs
    machine.set_override(50.0)
    assert machine.status().feed_override == 50.0
    half = machine.probe([0.0, 0.0, -1.0], 20.0, 2 * FEED)
    assert half.override == 50.0 and half.feed == 2 * FEED
    _goto(machine, start)
    machine.set_override(100.0)
    full = machine.probe([0.0, 0.0, -1.0], 20.0, FEED)
    assert _xyz(half.latched_mcs) == pytest.approx(_xyz(full.latched_mcs), abs=tol.latch_tol)
    with pytest.raises(ValueError):
        machine.set_override(130.0)


def test_a_probe_move_that_touches_nothing_is_not_triggered(machine, tol):
    start = _xyz(machine.status().mcs)
    result = machine.probe([1.0, 0.0, 0.0], 20.0, FEED)
    assert not result.triggered and result.latched_mcs is None
    assert _xyz(result.end_mcs) == pytest.approx(start + [20.0, 0.0, 0.0], abs=tol.position_tol)
    assert machine.status().alarms == ()                      # no alarm: the measuring task raises it


# --- faults, Reset ----------------------------------------------------------------------------
def test_a_positioning_into_the_part_stops_with_the_collision_alarm(machine, tol):
    _above_block(machine, 100.0, 60.0, clearance=10.0)
    above = machine.status().mcs
    contact_z = above["Z"] - 10.0                              # axes Z where the ball touches the top
    result = machine.goto({"Z": above["Z"] - 40.0}, 1000.0)
    assert not result.completed and result.alarm is not None and result.alarm.is_(alarms.PROBE_COLLISION)
    assert above["Z"] - 40.0 < result.mcs["Z"] <= contact_z + tol.latch_tol   # past the contact, short of the target
    assert _has(machine.status(), alarms.PROBE_COLLISION)
    machine.reset()
    assert machine.status().alarms == ()
    assert machine.goto(above).completed                       # the probe moves clear again


def test_reset_clears_resettable_alarms_and_stops_the_spindle(machine):
    machine.post_alarm(Alarm.of(alarms.PROBE_NOT_SWITCHED, "Probe not switched (contract)"))
    st = machine.status()
    assert [a.text for a in st.alarms] == ["Probe not switched (contract)"]
    assert st.alarms[0].is_(alarms.PROBE_NOT_SWITCHED)
    machine.spindle_rotate(500.0)
    with pytest.raises(MachineAlarm):
        machine.goto({"Y": LIMITS["Y"][0] - 1.0})
    assert len(machine.status().alarms) == 2
    machine.reset()
    st = machine.status()
    assert st.alarms == () and st.spindle_speed == 0.0 and not st.busy


# --- tool, spindle ----------------------------------------------------------------------------
def test_tool_change_and_offset_length_act_on_the_wcs_display(machine, tol):
    z = machine.status().mcs["Z"]
    machine.change_tool(CUTTER["t"], CUTTER["length"])
    st = machine.status()
    assert st.tool == CUTTER["t"] and st.tool_length == pytest.approx(CUTTER["length"])
    assert st.wcs["Z"] == pytest.approx(z - CUTTER["length"], abs=tol.position_tol)   # G500: WCS = tool tip
    machine.set_tool_offset(85.25)
    st = machine.status()
    assert st.tool_length == pytest.approx(85.25) and st.wcs["Z"] == pytest.approx(z - 85.25, abs=tol.position_tol)
    machine.change_tool(9, L_PROBE)
    assert machine.status().tool == 9 and machine.status().tool_length == pytest.approx(L_PROBE)


def test_spindle_orientation_and_rotation(machine):
    machine.spindle_position(90.0)
    assert machine.status().spindle_angle == pytest.approx(90.0)
    machine.spindle_position(270.0)
    assert machine.status().spindle_angle == pytest.approx(270.0)
    machine.spindle_rotate(800.0)
    assert machine.status().spindle_speed == pytest.approx(800.0)
    machine.spindle_rotate(0.0)
    assert machine.status().spindle_speed == 0.0


# --- frames and the NC's data -----------------------------------------------------------------
def test_activate_frame_changes_the_wcs_display(machine, tol):
    wcs2bcs = np.eye(4)
    wcs2bcs[:3, :3] = _rot_z(30.0)
    wcs2bcs[:3, 3] = [10.0, 20.0, -30.0]
    machine.activate_frame(ActiveFrame(name="G54", wcs2bcs=wcs2bcs))
    st = machine.status()
    tip = _xyz(st.mcs) - st.tool_length * np.asarray(st.tool_axis)
    assert st.active_offset == "G54"
    assert _rot_z(30.0) @ _xyz(st.wcs) + wcs2bcs[:3, 3] == pytest.approx(tip, abs=tol.position_tol)
    machine.activate_frame(ActiveFrame())
    assert machine.status().active_offset == "G500"
    assert _xyz(machine.status().wcs) == pytest.approx(tip, abs=tol.position_tol)


def test_write_offset_and_tool_data(machine, implementation):
    before = machine.status()
    frame = {"trans": {"X": 12.5, "Y": -3.0, "Z": 0.25}, "fine": {"X": 0.001, "Y": 0.0, "Z": 0.0},
             "rot": {"X": 0.0, "Y": 0.0, "Z": 1.5}}
    machine.write_offset("G55", frame)
    tool = {"type": 120, "length": 60.0, "radius": 4.0, "wear": {"length": -0.02, "radius": 0.01}}
    machine.write_tool(2, tool)
    after = machine.status()                        # neither is active: the display stays
    assert after.wcs == before.wcs and after.tool_length == before.tool_length
    if implementation.read_offset is not None:
        assert _flat(implementation.read_offset(machine, "G55")) == pytest.approx(
            _flat(implementation.held_offset(frame)), abs=implementation.readback_tol, rel=0)
    if implementation.read_tool is not None:
        assert _flat(implementation.read_tool(machine, 2)) == pytest.approx(
            _flat(implementation.held_tool(tool)), abs=implementation.readback_tol, rel=0)


def _flat(data: dict, prefix: str = "") -> dict:
    """A nested dict of numbers as one level ("trans.X": 12.5), for pytest.approx."""
    out = {}
    for key, value in data.items():
        if isinstance(value, dict):
            out.update(_flat(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


@pytest.mark.parametrize("frame, field", [
    ({"trans": {"X": "12"}}, "trans.X"),
    ({"trans": {"Q": 1.0}}, "Q"),
    ({"rot": {"X": math.nan}}, "rot.X"),
    ({"shift": {}}, "shift"),
])
def test_a_malformed_offset_is_a_value_error_naming_the_field(machine, frame, field):
    with pytest.raises(ValueError, match=field.replace(".", r"\.")):
        machine.write_offset("G56", frame)


@pytest.mark.parametrize("data, field", [
    ({"type": 120, "length": "x", "radius": 1.0}, "length"),
    ({"type": 120, "length": 10.0}, "radius"),
    ({"type": 120, "length": 10.0, "radius": 1.0, "wear": {"length": math.inf}}, "wear.length"),
    ({"type": 120, "length": 10.0, "radius": 1.0, "colour": "red"}, "colour"),
])
def test_malformed_tool_data_is_a_value_error_naming_the_field(machine, data, field):
    with pytest.raises(ValueError, match=field.replace(".", r"\.")):
        machine.write_tool(3, data)


def test_close_stops_and_may_be_called_again(machine):
    machine.jog_continuous("Y", +1, feed=1000.0)
    machine.close()
    assert not machine.status().busy
    machine.close()
